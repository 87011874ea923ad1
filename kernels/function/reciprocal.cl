/* function/reciprocal.cl: f(z) = 1/z, f'(z) = -1/z^2 (POV-Ray 3.6 documentation, the
 * julia_fractal function "reciprocal"), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
inline cplx cfun(cplx z) { return c_recip(z); }
inline cplx cfun_d(cplx z) { return c_neg(c_sqr(c_recip(z))); }

#ifdef ENCLOSE   /* march/proven.cl: the Moebius image of the disc (enclose/disc.cl) */
/* enclose/split.cl's Taylor bound: |f''| = 2 / |z|^3 <= 2 / (|m| - rho)^3; none where 0 is in the disc */
inline lreal func_m2(cplx m, lreal rho)
{
    lreal g = c_abs(m) - rho;
    return L_SEL((lreal)INFINITY, (real)2 / (g * g * g), g > (real)0);
}
#define FUNC_M2(m, rho) func_m2((m), (rho))
/* its disc enclosure */
inline cdisc cfun_disc(cdisc z) { return d_recip(z); }
#endif
