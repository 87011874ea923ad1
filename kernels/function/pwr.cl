/* function/pwr.cl: f(z) = z^p = exp(p log z), f'(z) = p z^(p-1) (seed 003_8ca5f9108f52d3d6.txt,
 * the julia_fractal function "pwr(x, y)"; p = x + iy is fractal.exponent, compiled in as
 * -D FUNC_EXPONENT_RE/IM), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
#ifndef FUNC_EXPONENT_RE
#error "pwr needs -D FUNC_EXPONENT_RE and FUNC_EXPONENT_IM (build.fractal_defines)"
#endif
#define FUNC_EXPONENT C((lreal)(real)(FUNC_EXPONENT_RE), (lreal)(real)(FUNC_EXPONENT_IM))
inline cplx cfun(cplx z) { return c_pow(z, FUNC_EXPONENT); }
inline cplx cfun_d(cplx z) { return c_mul(FUNC_EXPONENT, c_pow(z, C((lreal)((real)(FUNC_EXPONENT_RE) - (real)1), (lreal)(real)(FUNC_EXPONENT_IM)))); }

#ifdef ENCLOSE   /* march/proven.cl: exp(p log z), both sides of log's cut (enclose/disc.cl) */
/* enclose/split.cl's Taylor bound: |f''| = |p (p - 1) z^(p - 2)| <= |p (p - 1)| e^(max(Re q ln|z|) + |Im q| pi), q = p - 2, over the disc; none where it meets log's cut or 0 */
inline lreal func_m2(cplx m, lreal rho)
{
    real qr = (real)(FUNC_EXPONENT_RE) - (real)2, qi = (real)(FUNC_EXPONENT_IM);
    real pp = hypot((real)(FUNC_EXPONENT_RE), qi) * hypot((real)(FUNC_EXPONENT_RE) - (real)1, qi);
    lreal lo = log(c_abs(m) - rho), hi = log(c_abs(m) + rho);
    lreal e = fmax(qr * lo, qr * hi) + fabs(qi) * ENC_PI;
#ifdef PWR_INTEGER   /* an integer exponent: z^p is analytic across log's cut, z^(p-2) too for p >= 2 */
    e = L_SEL(e, (lreal)0, (lmask)(qr == (real)0));
    lmask bad = (qr < (real)0) & !(c_abs(m) > rho);
#else
    lmask bad = d_meets_cut(D(m, rho)) | !(c_abs(m) > rho);
#endif
    return L_SEL(pp * exp(e) * ENC_UP, (lreal)INFINITY, bad);
}
#define FUNC_M2(m, rho) func_m2((m), (rho))
/* exp(p log z) loses |p log z| ulps of its value to the rounding of p log z */
#define FUNC_ROUND_GAIN(m) ((real)1 + hypot((real)(FUNC_EXPONENT_RE), (real)(FUNC_EXPONENT_IM)) * (fabs(log(c_abs(m))) + ENC_PI))
/* its disc enclosure */
inline cdisc cfun_disc(cdisc z) { return d_pwr(z, FUNC_EXPONENT); }
#endif
