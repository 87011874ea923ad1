/* function/exp.cl: f(z) = e^z, f'(z) = e^z (POV-Ray 3.6 documentation, the
 * julia_fractal function "exp"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_exp(z); }
inline cplx cfun_d(cplx z) { return c_exp(z); }

#ifdef ENCLOSE   /* march/proven.cl: |exp'| <= e^(Re m + r) (enclose/disc.cl) */
/* enclose/split.cl's Taylor bound: |f''| = e^Re z <= e^(Re m + rho) */
#define FUNC_M2(m, rho) exp((m).re + (rho))
/* enclose/split.cl's second order: f'' = FUNC_D2_SIGN f (exp'' = exp, and |exp'''| = e^(Re z): FUNC_M2's bound holds f''' too) */
#define FUNC_D2_SIGN (1)
/* its disc enclosure */
inline cdisc cfun_disc(cdisc z) { return d_exp(z); }
#endif
