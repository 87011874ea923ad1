/* function/atanh.cl: f(z) = atanh z, f'(z) = 1/(1 - z^2) (POV-Ray 3.6 documentation, the
 * julia_fractal function "atanh"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_atanh(z); }
inline cplx cfun_d(cplx z) { return c_recip(c_sub(C((lreal)1, (lreal)0), c_sqr(z))); }

#ifdef ENCLOSE   /* march/proven.cl: (log(1 + z) - log(1 - z)) / 2 (enclose/disc.cl) */
inline cdisc cfun_disc(cdisc z) { return d_atanh(z); }
#endif
