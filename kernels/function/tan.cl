/* function/tan.cl: f(z) = tan z, f'(z) = 1 + tan^2 z (POV-Ray 3.6 documentation, the
 * julia_fractal function "tan"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_tan(z); }
inline cplx cfun_d(cplx z) { return c_add(C((lreal)1, (lreal)0), c_sqr(c_tan(z))); }

#ifdef ENCLOSE   /* march/proven.cl: 1 / |cos z|^2 bounded away from the poles (enclose/disc.cl) */
inline cdisc cfun_disc(cdisc z) { return d_tan(z); }
#endif
