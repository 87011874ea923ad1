/* function/asinh.cl: f(z) = asinh z, f'(z) = 1/sqrt(z^2 + 1) (POV-Ray 3.6 documentation, the
 * julia_fractal function "asinh"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_asinh(z); }
inline cplx cfun_d(cplx z) { return c_recip(c_sqrt(c_add(c_sqr(z), C((lreal)1, (lreal)0)))); }

#ifdef ENCLOSE   /* march/proven.cl: log(z + sqrt(z^2 + 1)) (enclose/disc.cl) */
inline cdisc cfun_disc(cdisc z) { return d_asinh(z); }
#endif
