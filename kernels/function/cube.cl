/* function/cube.cl: f(z) = z^3, f'(z) = 3 z^2 (POV-Ray 3.6 documentation, the
 * julia_fractal function "cube"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 * FUNC_POWER tells the algebra the map is the polynomial z^3: quaternions use their own
 * product for it (algebra/quaternion.cl), and it sets the escape bound.
 */
#define FUNC_POWER 3
inline cplx cfun(cplx z) { return c_mul(c_sqr(z), z); }
inline cplx cfun_d(cplx z) { return c_scale((lreal)3, c_sqr(z)); }

#ifdef ENCLOSE   /* march/proven.cl: (m + e)^3 by two products (enclose/disc.cl) */
/* enclose/split.cl's Taylor bound: |f''| = 6 |z| <= 6 (|m| + rho) */
#define FUNC_M2(m, rho) ((real)6 * (c_abs(m) + (rho)))
/* its disc enclosure */
inline cdisc cfun_disc(cdisc z) { return d_mul(d_sqr(z), z); }
#endif
