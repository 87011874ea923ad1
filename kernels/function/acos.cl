/* function/acos.cl: f(z) = acos z, f'(z) = -1/sqrt(1 - z^2) (POV-Ray 3.6 documentation, the
 * julia_fractal function "acos"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_acos(z); }
inline cplx cfun_d(cplx z) { return c_neg(c_recip(c_sqrt(c_sub(C((lreal)1, (lreal)0), c_sqr(z))))); }

#ifdef ENCLOSE   /* march/proven.cl: pi/2 - asin z */
inline cdisc cfun_disc(cdisc z) { return d_add_const(d_neg(d_times_minus_i(d_asinh(d_times_i(z)))), C((lreal)1.57079632679489661923, (lreal)0)); }
#endif
