/* function/sin.cl: f(z) = sin z, f'(z) = cos z (POV-Ray 3.6 documentation, the
 * julia_fractal function "sin"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_sin(z); }
inline cplx cfun_d(cplx z) { return c_cos(z); }

#ifdef ENCLOSE   /* march/proven.cl: |sin'| <= |cos m| + r sup|sin| and |sin z| <= cosh(Im z) (enclose/disc.cl d_taylor) */
/* enclose/split.cl's Taylor bound: |f''| = |sin z| <= cosh(Im z) */
#define FUNC_M2(m, rho) cosh(fabs((m).im) + (rho))
/* enclose/split.cl's second order: f'' = FUNC_D2_SIGN f (sin'' = -sin, and |sin'''| = |cos z| <= cosh(Im z): FUNC_M2's bound holds f''' too) */
#define FUNC_D2_SIGN (-1)
/* its disc enclosure: second order with that bound (enclose/disc.cl D_TAYLOR_OF) */
inline cdisc cfun_disc(cdisc z) { return D_TAYLOR_OF(z); }
#endif
