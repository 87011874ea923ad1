/* function/pwr.cl: f(z) = z^p = exp(p log z), f'(z) = p z^(p-1) (POV-Ray 3.6 documentation,
 * the julia_fractal function "pwr(x, y)"; p = x + iy is fractal.exponent, compiled in as
 * -D FUNC_EXPONENT_RE/IM), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
#ifndef FUNC_EXPONENT_RE
#error "pwr needs -D FUNC_EXPONENT_RE and FUNC_EXPONENT_IM (build.fractal_defines)"
#endif
#define FUNC_EXPONENT C((lreal)(real)(FUNC_EXPONENT_RE), (lreal)(real)(FUNC_EXPONENT_IM))
/* |x + iy| of constants: sqrt folds at compile time where the runtime's hypot stayed a call
 * at every use (perf: 1-1.5 % of hypercomplex pwr's proven march); within an ulp of hypot,
 * which the bounds' ENC_UP covers */
#define PWR_ABS(x, y) sqrt((real)(x) * (real)(x) + (real)(y) * (real)(y))
inline cplx cfun(cplx z) { return c_pow(z, FUNC_EXPONENT); }
/* f'(z) = p z^(p-1) = p z^p / z: the compiler shares z^p's log and exp with cfun(z) wherever
 * both are taken at one point (enclose/split.cl, the Jacobian), half the transcendental
 * calls of exp((p - 1) log z); 0 at z = 0, as c_pow */
inline cplx cfun_d(cplx z)
{
    cplx r = c_mul(FUNC_EXPONENT, c_div(cfun(z), z));
    lmask zero = (z.re == (real)0) & (z.im == (real)0);
    return C(L_SEL(r.re, (lreal)0, zero), L_SEL(r.im, (lreal)0, zero));
}

#ifdef ENCLOSE   /* march/proven.cl: exp(p log z), both sides of log's cut (enclose/disc.cl) */
/* enclose/split.cl's Taylor bound: |f''| = |p (p - 1) z^(p - 2)| <= |p (p - 1)| e^(max(Re q ln|z|) + |Im q| pi), q = p - 2, over the disc; none where it meets log's cut or 0 */
inline lreal func_m2(cplx m, lreal rho)
{
    real qr = (real)(FUNC_EXPONENT_RE) - (real)2, qi = (real)(FUNC_EXPONENT_IM);
    real pp = PWR_ABS(FUNC_EXPONENT_RE, qi) * PWR_ABS((real)(FUNC_EXPONENT_RE) - (real)1, qi);
    /* max(q_r ln s) over s in [|m| - rho, |m| + rho]: one end by q_r's sign, a constant */
    lreal e = (qr > (real)0 ? qr * log(c_abs(m) + rho) : qr < (real)0 ? qr * log(c_abs(m) - rho) : (lreal)0)
              + fabs(qi) * ENC_PI;
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
#define FUNC_ROUND_GAIN(m) ((real)1 + PWR_ABS(FUNC_EXPONENT_RE, FUNC_EXPONENT_IM) * (fabs(log(c_abs(m))) + ENC_PI))
/* its disc enclosure */
inline cdisc cfun_disc(cdisc z) { return d_pwr(z, FUNC_EXPONENT); }
#endif
