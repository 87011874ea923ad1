/* function/sqr.cl: f(z) = z^2, f'(z) = 2 z (POV-Ray 3.6 documentation, the
 * julia_fractal function "sqr"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 * FUNC_POWER tells the algebra the map is the polynomial z^2: quaternions use their own
 * product for it (algebra/quaternion.cl), and it sets the escape bound.
 */
#define FUNC_POWER 2
inline cplx cfun(cplx z) { return c_sqr(z); }
inline cplx cfun_d(cplx z) { return c_scale((lreal)2, z); }

#ifdef ENCLOSE   /* march/proven.cl: (m + e)^2 = m^2 + 2 m e + e^2 (enclose/disc.cl) */
/* enclose/split.cl's Taylor bound: f'' = 2 */
#define FUNC_M2(m, rho) ((lreal)2)
/* its disc enclosure */
inline cdisc cfun_disc(cdisc z) { return d_sqr(z); }
#endif
