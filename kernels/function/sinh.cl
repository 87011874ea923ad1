/* function/sinh.cl: f(z) = sinh z, f'(z) = cosh z (POV-Ray 3.6 documentation, the
 * julia_fractal function "sinh"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_sinh(z); }
inline cplx cfun_d(cplx z) { return c_cosh(z); }

#ifdef ENCLOSE   /* march/proven.cl: |sinh'| <= |cosh m| + r sup|sinh| and |sinh z| <= cosh(Re z) (enclose/disc.cl d_taylor) */
/* enclose/split.cl's Taylor bound: |f''| = |sinh z| <= cosh(Re z) */
#define FUNC_M2(m, rho) cosh(fabs((m).re) + (rho))
/* enclose/split.cl's second order: f'' = FUNC_D2_SIGN f (sinh'' = sinh, and |sinh'''| = |cosh z| <= cosh(Re z): FUNC_M2's bound holds f''' too) */
#define FUNC_D2_SIGN (1)
/* its disc enclosure: second order with that bound (enclose/disc.cl D_TAYLOR_OF) */
inline cdisc cfun_disc(cdisc z) { return D_TAYLOR_OF(z); }
#endif
