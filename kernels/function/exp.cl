/* function/exp.cl: f(z) = e^z, f'(z) = e^z (POV-Ray 3.6 documentation, the
 * julia_fractal function "exp"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_exp(z); }
inline cplx cfun_d(cplx z) { return c_exp(z); }

#ifdef ENCLOSE   /* march/proven.cl: |exp'| <= e^(Re m + r) (enclose/disc.cl) */
/* enclose/split.cl's Taylor bound: |f''| = e^Re z <= e^(Re m + rho) */
#define FUNC_M2(m, rho) exp((m).re + (rho))
/* its disc enclosure */
inline cdisc cfun_disc(cdisc z) { return d_exp(z); }
#endif
