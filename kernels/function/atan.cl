/* function/atan.cl: f(z) = atan z, f'(z) = 1/(1 + z^2) (POV-Ray 3.6 documentation, the
 * julia_fractal function "atan"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_atan(z); }
inline cplx cfun_d(cplx z) { return c_recip(c_add(C((lreal)1, (lreal)0), c_sqr(z))); }

#ifdef ENCLOSE   /* march/proven.cl: -i atanh(i z) */
inline cdisc cfun_disc(cdisc z) { return d_times_minus_i(d_atanh(d_times_i(z))); }
#endif
