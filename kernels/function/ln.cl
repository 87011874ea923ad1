/* function/ln.cl: f(z) = ln z (principal), f'(z) = 1/z (POV-Ray 3.6 documentation, the
 * julia_fractal function "ln"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_log(z); }
inline cplx cfun_d(cplx z) { return c_recip(z); }

#ifdef ENCLOSE   /* march/proven.cl: the principal log, its cut included (enclose/disc.cl) */
inline cdisc cfun_disc(cdisc z) { return d_log(z); }
#endif
