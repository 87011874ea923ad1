/* function/sinh.cl: f(z) = sinh z, f'(z) = cosh z (seed 003_8ca5f9108f52d3d6.txt, the
 * julia_fractal function "sinh"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_sinh(z); }
inline cplx cfun_d(cplx z) { return c_cosh(z); }
