/* kind/julia_stack.cl (-D KIND_JULIA_STACK, STACK_CM_RE/IM, STACK_CH_RE/IM; built only for
 * fractal.kind = "julia_stack"): a stack of complex Julia sets, the 3D slice of C x C of
 * Hart, Sandin & Kauffman 1989 §5.1 - "looking at the z-planes and varying some
 * single-dimension function of c to define the third dimension".  The point p = (x, y, u, w):
 *     z_0 = x + i y,   c(u) = c_mid + u c_half,   |u| <= 1,   w ignored,
 * c_mid = (c_from + c_to) / 2 and c_half = (c_to - c_from) / 2 (fractal.c_from at u = -1,
 * fractal.c_to at u = +1: c(s) = c_from + s (c_to - c_from), s = (u + 1) / 2), compiled in.
 * p is inside when |u| <= 1 and |z_n| <= bailout for n = 0 .. max_iter, z_{n+1} = z_n^2 + c(u):
 * each u = const section is the filled Julia set of c(u), truncated like iterate.cl's.
 * The ends u = +-1 are flat caps showing the Julia sets of the end points.
 *
 * Compiled after iterate.cl (the pattern of kind/mandelbrot.cl): the set test, level function
 * and normal below take over julia_inside, julia_level and the Jacobian normal (KIND_NORMAL,
 * defined at the end: normals/jacobian.cl projects its 4D gradient).
 * No distance estimate is proven for a stack (Hart, Sandin & Kauffman 1989 §5.1), so by default the estimate of
 * iterate.cl is switched off (ALG_HAS_DE undefined: shadows and ambient occlusion test inside
 * points); -D STACK_DE (march.method = "de") builds the seed's "empirical formula based on
 * the Mandelbrot set distance estimate" instead (stack_distance_formula). */
#ifndef FUNC_POWER
#error "a Julia set stack is the complex square (scene._check_fractal: quaternion sqr)"
#endif

/* z^2 + c on (re, im) lane pairs; lanes outside live keep their values */
#define STACK_STEP(zr, zi, cr, ci, live) do { \
        lreal nr_ = zr * zr - zi * zi + (cr), ni_ = (real)2 * zr * zi + (ci); \
        zr = L_SEL(zr, nr_, live); \
        zi = L_SEL(zi, ni_, live); \
    } while (0)

inline lmask stack_inside(quat p, julia_params jp)
{
    lreal zr = p.x, zi = p.y;
    lreal cr = (real)(STACK_CM_RE) + p.z * (real)(STACK_CH_RE);
    lreal ci = (real)(STACK_CM_IM) + p.z * (real)(STACK_CH_IM);
    lmask slab = fabs(p.z) <= (real)1;
    lmask live = slab & (zr * zr + zi * zi <= jp.bailout2);
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        STACK_STEP(zr, zi, cr, ci, live);
        live = slab & (zr * zr + zi * zi <= jp.bailout2);
    }
    COUNT_ITER(jp, n);
    return live;
}

/* F = max(F_z, |u| - 1): F_z = |z_N|^2 / bailout^2 - 1, extrapolated past an escape as in
 * iterate.cl julia_level (growth 2), and the slab's own level |u| - 1; F <= 0 exactly where
 * stack_inside, continuous across the caps (march/refine.cl interpolates it) */
inline lreal stack_level(quat p, julia_params jp, lmask *inside)
{
    lreal zr = p.x, zi = p.y;
    lreal cr = (real)(STACK_CM_RE) + p.z * (real)(STACK_CH_RE);
    lreal ci = (real)(STACK_CM_IM) + p.z * (real)(STACK_CH_IM);
    lreal m2 = zr * zr + zi * zi;
    lmask live = m2 <= jp.bailout2;
    lmask steps = 0;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        STACK_STEP(zr, zi, cr, ci, live);
        m2 = zr * zr + zi * zi;
        steps = L_SEL(steps, steps + 1, live);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    lmask zin = m2 <= jp.bailout2;
    lreal out = kind_level(m2, jp.bailout2, jp.max_iter - steps, 2);
    lreal fz = L_SEL(out, m2 / jp.bailout2 - (real)1, zin);
    lreal fu = fabs(p.z) - (real)1;
    *inside = zin & (fu <= (real)0);
    return fmax(fz, fu);
}

/* The analytic normal grad |z_N|^2 = 2 (Re(conj z_N A), Re(conj z_N i A), Re(conj z_N B), 0)
 * with A = dz_N/dz_0 and B = dz_N/du:  A_0 = 1, B_0 = 0,  A_{n+1} = 2 z_n A_n,
 * B_{n+1} = 2 z_n B_n + c_half; rescaled both ways as in normals/jacobian.cl (the added
 * c_half kept at the scale, as kind/mandelbrot.cl's identity), the same stop before z
 * underflows (GUARD_JACOBIAN_TINY).  A point whose z-orbit stays bounded but lies past a cap
 * (|u| > 1: the march's outside end of a hit on a cap) gets the cap's normal (0, 0, sign u, 0). */
inline quat stack_normal(quat p, julia_params jp, lmask *guard)
{
    lreal zr = p.x, zi = p.y;
    lreal cr = (real)(STACK_CM_RE) + p.z * (real)(STACK_CH_RE);
    lreal ci = (real)(STACK_CM_IM) + p.z * (real)(STACK_CH_IM);
    lreal ar = (lreal)1, ai = (lreal)0, br = (lreal)0, bi = (lreal)0;
    lreal unit = (lreal)1;
    lmask live = L_TRUE;
    for (int n = 0; n < jp.max_iter && L_ANY(live); ++n) {
        lreal m2 = zr * zr + zi * zi;
        live &= m2 <= jp.bailout2;
        lmask tiny = live & (m2 < sqrt(REAL_MIN));
        *guard |= L_SEL((lmask)0, (lmask)GUARD_JACOBIAN_TINY, tiny);
        live &= !tiny;
        if (!L_ANY(live))
            break;
        lreal nar = (real)2 * (zr * ar - zi * ai), nai = (real)2 * (zr * ai + zi * ar);
        lreal nbr = (real)2 * (zr * br - zi * bi) + unit * (real)(STACK_CH_RE);
        lreal nbi = (real)2 * (zr * bi + zi * br) + unit * (real)(STACK_CH_IM);
        ar = L_SEL(ar, nar, live); ai = L_SEL(ai, nai, live);
        br = L_SEL(br, nbr, live); bi = L_SEL(bi, nbi, live);
        STACK_STEP(zr, zi, cr, ci, live);
        lreal s2 = fmax(ar * ar + ai * ai, br * br + bi * bi);
        lmask rescale = L_RESCALE_DUE(live, s2);
        if (L_ANY(rescale)) {
            lreal inv = (real)1 / sqrt(s2);
            ar = L_SEL(ar, ar * inv, rescale); ai = L_SEL(ai, ai * inv, rescale);
            br = L_SEL(br, br * inv, rescale); bi = L_SEL(bi, bi * inv, rescale);
            unit = L_SEL(unit, unit * inv, rescale);
        }
    }
    lmask cap = (zr * zr + zi * zi <= jp.bailout2) & (fabs(p.z) > (real)1);
    lreal gx = zr * ar + zi * ai, gy = zi * ar - zr * ai, gu = zr * br + zi * bi;
    lreal z0 = (lreal)0;
    return QUAT(L_SEL(gx, z0, cap), L_SEL(gy, z0, cap), L_SEL(gu, copysign((lreal)1, p.z), cap), z0);
}

#ifdef STACK_DE
/* The empirical estimate (march.method = "de"; Hart, Sandin & Kauffman 1989 §5.1: no proven one): the Julia and
 * Mandelbrot estimates of Hart, Sandin & Kauffman 1989 §3.1 eq. 8 in one, d = |z_n| ln|z_n| / (2 G) with
 * G = sqrt(|A_n|^2 + |B_n|^2) >= the norm of the 2 x 3 Jacobian of z_n in (x, y, u) (A, B as
 * in stack_normal), carried through the bounds |A_{n+1}| = 2 |z_n| |A_n| and
 * |B_{n+1}| <= 2 |z_n| |B_n| + |c_half| as mantissas times a common 2^e (no overflow at any
 * max_iter); outside the slab at least its exact distance |u| - 1.  *escaped: the point is
 * outside (stack_inside false).  Its error against the brute-force scan is measured, not
 * proven (benchmarks/results/kinds/kinds_error.md). */
inline lreal stack_distance_formula(quat p, julia_params jp, lmask *escaped)
{
    lreal zr = p.x, zi = p.y;
    lreal cr = (real)(STACK_CM_RE) + p.z * (real)(STACK_CH_RE);
    lreal ci = (real)(STACK_CM_IM) + p.z * (real)(STACK_CH_IM);
    real ch = hypot((real)(STACK_CH_RE), (real)(STACK_CH_IM));
    lreal m2 = zr * zr + zi * zi;
    lreal ga = (lreal)1, gb = (lreal)0;  /* |A| and |B| are ga * 2^e and gb * 2^e */
    lmask e = 0;
    lmask live = m2 <= jp.bailout2;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        lreal r2 = (real)2 * sqrt(m2);
        gb = L_SEL(gb, r2 * gb + ldexp((lreal)ch, L_INT(-e)), live);
        ga = L_SEL(ga, r2 * ga, live);
        lmask big = live & (fmax(ga, gb) > (real)1e16);
        if (L_ANY(big)) {
            lint k_;
            frexp(fmax(ga, gb), &k_);
            lmask k = L_SEL((lmask)0, L_MASK(k_), big);
            ga = ldexp(ga, L_INT(-k));
            gb = ldexp(gb, L_INT(-k));
            e += k;
        }
        STACK_STEP(zr, zi, cr, ci, live);
        m2 = zr * zr + zi * zi;
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    lmask slab = fabs(p.z) <= (real)1;
    lmask zout = m2 > jp.bailout2;
    *escaped = zout | !slab;
    lreal d = de_value(m2, ga * ga + gb * gb, e + e);
    lreal du = fabs(p.z) - (real)1;
    return L_SEL(fmax(L_SEL((lreal)0, d, zout), du), d, slab & zout);
}
#endif

#define julia_inside stack_inside
#define julia_level stack_level
#define KIND_NORMAL stack_normal
#ifdef STACK_DE
#define julia_distance_formula stack_distance_formula
inline lreal stack_distance(quat p, julia_params jp)
{
    lmask escaped;
    lreal d = stack_distance_formula(p, jp, &escaped);
    return L_SEL((lreal)0, d, escaped);
}
#define julia_distance stack_distance
#else
#undef ALG_HAS_DE
#endif
