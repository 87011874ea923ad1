/* function/cos.cl: f(z) = cos z, f'(z) = -sin z (POV-Ray 3.6 documentation, the
 * julia_fractal function "cos"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_cos(z); }
inline cplx cfun_d(cplx z) { return c_neg(c_sin(z)); }

#ifdef ENCLOSE   /* march/proven.cl: |cos'| <= |sin m| + r sup|cos| and |cos z| <= cosh(Im z) (enclose/disc.cl d_taylor) */
/* enclose/split.cl's Taylor bound: |f''| = |cos z| <= cosh(Im z) */
#define FUNC_M2(m, rho) cosh(fabs((m).im) + (rho))
/* enclose/split.cl's second order: f'' = FUNC_D2_SIGN f (cos'' = -cos, and |cos'''| = |sin z| <= cosh(Im z): FUNC_M2's bound holds f''' too) */
#define FUNC_D2_SIGN (-1)
/* its disc enclosure: second order with that bound (enclose/disc.cl D_TAYLOR_OF) */
inline cdisc cfun_disc(cdisc z) { return D_TAYLOR_OF(z); }
#endif
