/* function/acosh.cl: f(z) = acosh z, f'(z) = 1/(sqrt(z - 1) sqrt(z + 1)) (POV-Ray 3.6 documentation, the
 * julia_fractal function "acosh"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_acosh(z); }
inline cplx cfun_d(cplx z) { return c_recip(c_mul(c_sqrt(C(z.re - (real)1, z.im)), c_sqrt(C(z.re + (real)1, z.im)))); }

#ifdef ENCLOSE   /* march/proven.cl: log(z + sqrt(z + 1) sqrt(z - 1)), C99's cut (enclose/disc.cl) */
inline cdisc cfun_disc(cdisc z) { return d_log(d_add(z, d_mul(d_sqrt(d_add_const(z, C((lreal)1, (lreal)0))), d_sqrt(d_add_const(z, C((lreal)-1, (lreal)0)))))); }
#endif
