/* function/cosh.cl: f(z) = cosh z, f'(z) = sinh z (POV-Ray 3.6 documentation, the
 * julia_fractal function "cosh"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_cosh(z); }
inline cplx cfun_d(cplx z) { return c_sinh(z); }

#ifdef ENCLOSE   /* march/proven.cl: |cosh'| <= |sinh m| + r sup|cosh| and |cosh z| <= cosh(Re z) (enclose/disc.cl d_taylor) */
/* enclose/split.cl's Taylor bound: |f''| = |cosh z| <= cosh(Re z) */
#define FUNC_M2(m, rho) cosh(fabs((m).re) + (rho))
/* enclose/split.cl's second order: f'' = FUNC_D2_SIGN f (cosh'' = cosh, and |cosh'''| = |sinh z| <= cosh(Re z): FUNC_M2's bound holds f''' too) */
#define FUNC_D2_SIGN (1)
/* its disc enclosure: second order with that bound (enclose/disc.cl D_TAYLOR_OF) */
inline cdisc cfun_disc(cdisc z) { return D_TAYLOR_OF(z); }
#endif
