/* function/tanh.cl: f(z) = tanh z, f'(z) = 1 - tanh^2 z (POV-Ray 3.6 documentation, the
 * julia_fractal function "tanh"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_tanh(z); }
inline cplx cfun_d(cplx z) { return c_sub(C((lreal)1, (lreal)0), c_sqr(c_tanh(z))); }

#ifdef ENCLOSE   /* march/proven.cl: 1 / |cosh z|^2 bounded away from the poles (enclose/disc.cl) */
inline cdisc cfun_disc(cdisc z) { return d_tanh(z); }
#endif
