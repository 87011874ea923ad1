/* kind/cubic_locus.cl (-D KIND_CUBIC_LOCUS, LOCUS_SIGN, LOCUS_R2; built only for fractal.kind =
 * "cubic_locus"): the cubic connectedness locus of Hart, Sandin & Kauffman 1989 §5.2, eq. 19,
 *     f_{a,b}(z) = z^3 - 3 a^2 z + b,   critical points +a and -a,
 *     C+ = {(a, b) : the orbit of +a stays bounded}  (Definition 4),  C- likewise for -a,
 * a 4D set in the point p = (Re a, Im a, Re b, Im b), seen through the 4D camera and slice
 * like the Julia sets.  p is inside when |p|^2 <= LOCUS_R2 (fractal.locus_radius^2: C+ is
 * unbounded - it holds every (a, a + 2 a^3), where +a is a fixed point - so it is drawn within
 * that 4-ball, cut by its sphere) and |z_n| <= bailout for n = 0 .. max_iter, z_0 = LOCUS_SIGN a
 * (+1: C+, -1: C-; fractal.component).  scene/rules.py refuses a bailout below the escape radius of
 * the maps in the ball (|z| > bailout then escapes), so the truncated set tends to C+.
 * No distance estimate is known (Hart, Sandin & Kauffman 1989 §5.2): the fixed scan only; ALG_HAS_DE is undefined
 * (shadows and ambient occlusion test inside points).
 *
 * Compiled after iterate.cl (the pattern of kind/mandelbrot.cl): the set test, level function
 * and normal below take over julia_inside, julia_level and the Jacobian normal (KIND_NORMAL,
 * defined at the end: normals/jacobian.cl projects its 4D gradient). */

/* z <- z (z^2 - 3 a^2) + b on (re, im) lane pairs; a2 = a^2; lanes outside live keep z */
#define LOCUS_STEP(zr, zi, a2r, a2i, br, bi, live) do { \
        lreal wr_ = zr * zr - zi * zi - (real)3 * (a2r), wi_ = (real)2 * zr * zi - (real)3 * (a2i); \
        lreal nr_ = zr * wr_ - zi * wi_ + (br), ni_ = zr * wi_ + zi * wr_ + (bi); \
        zr = L_SEL(zr, nr_, live); \
        zi = L_SEL(zi, ni_, live); \
    } while (0)

inline lmask locus_inside(quat p, julia_params jp)
{
    lreal a2r = p.x * p.x - p.y * p.y, a2i = (real)2 * p.x * p.y;
    lreal zr = (real)(LOCUS_SIGN) * p.x, zi = (real)(LOCUS_SIGN) * p.y;
    lmask ball = QNORM2(p) <= (real)(LOCUS_R2);
    lmask live = ball & (zr * zr + zi * zi <= jp.bailout2);
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        LOCUS_STEP(zr, zi, a2r, a2i, p.z, p.w, live);
        live = ball & (zr * zr + zi * zi <= jp.bailout2);
    }
    COUNT_ITER(jp, n);
    return live;
}

/* F = max(F_z, |p|^2 / R^2 - 1): F_z = |z_N|^2 / bailout^2 - 1, extrapolated past an escape as
 * (|z_n|^2 / bailout^2)^(3^(N - n)) - 1 (the cube's growth; iterate.cl julia_level), and the
 * ball's own level; F <= 0 exactly where locus_inside, continuous across the sphere */
inline lreal locus_level(quat p, julia_params jp, lmask *inside)
{
    lreal a2r = p.x * p.x - p.y * p.y, a2i = (real)2 * p.x * p.y;
    lreal zr = (real)(LOCUS_SIGN) * p.x, zi = (real)(LOCUS_SIGN) * p.y;
    lreal m2 = zr * zr + zi * zi;
    lmask live = m2 <= jp.bailout2;
    lmask steps = 0;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        LOCUS_STEP(zr, zi, a2r, a2i, p.z, p.w, live);
        m2 = zr * zr + zi * zi;
        steps = L_SEL(steps, steps + 1, live);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    lmask zin = m2 <= jp.bailout2;
    lreal out = kind_level(m2, jp.bailout2, jp.max_iter - steps, 3);
    lreal fz = L_SEL(out, m2 / jp.bailout2 - (real)1, zin);
    lreal fb = QNORM2(p) / (real)(LOCUS_R2) - (real)1;
    *inside = zin & (fb <= (real)0);
    return fmax(fz, fb);
}

/* The analytic normal: grad |z_N|^2 / 2 = (Re(conj z A), Re(conj z i A), Re(conj z B),
 * Re(conj z i B)), A = dz_N/da, B = dz_N/db (z is holomorphic in a and b):
 *     A_0 = LOCUS_SIGN, B_0 = 0,  A_{n+1} = f'(z_n) A_n - 6 a z_n,  B_{n+1} = f'(z_n) B_n + 1,
 * f'(z) = 3 (z^2 - a^2); rescaled both ways as in normals/jacobian.cl, the added terms kept at
 * the scale (kind/mandelbrot.cl's identity).  z_0 = a may be 0 exactly (a = 0): no stop there.
 * A point whose orbit stays bounded but lies past the sphere (the march's outside end of a hit
 * on the cut) gets the sphere's normal p. */
inline quat locus_normal(quat p, julia_params jp, lmask *guard)
{
    lreal a2r = p.x * p.x - p.y * p.y, a2i = (real)2 * p.x * p.y;
    lreal zr = (real)(LOCUS_SIGN) * p.x, zi = (real)(LOCUS_SIGN) * p.y;
    lreal ar = (lreal)(LOCUS_SIGN), ai = (lreal)0, br = (lreal)0, bi = (lreal)0;
    lreal unit = (lreal)1;
    lmask live = L_TRUE;
    for (int n = 0; n < jp.max_iter && L_ANY(live); ++n) {
        live &= zr * zr + zi * zi <= jp.bailout2;
        if (!L_ANY(live))
            break;
        lreal dr = (real)3 * (zr * zr - zi * zi - a2r), di = (real)3 * ((real)2 * zr * zi - a2i);
        lreal azr = p.x * zr - p.y * zi, azi = p.x * zi + p.y * zr;           /* a z */
        lreal nar = dr * ar - di * ai - unit * (real)6 * azr, nai = dr * ai + di * ar - unit * (real)6 * azi;
        lreal nbr = dr * br - di * bi + unit, nbi = dr * bi + di * br;
        ar = L_SEL(ar, nar, live); ai = L_SEL(ai, nai, live);
        br = L_SEL(br, nbr, live); bi = L_SEL(bi, nbi, live);
        LOCUS_STEP(zr, zi, a2r, a2i, p.z, p.w, live);
        lreal s2 = fmax(ar * ar + ai * ai, br * br + bi * bi);
        lmask rescale = L_RESCALE_DUE(live, s2);
        if (L_ANY(rescale)) {
            lreal inv = (real)1 / sqrt(s2);
            ar = L_SEL(ar, ar * inv, rescale); ai = L_SEL(ai, ai * inv, rescale);
            br = L_SEL(br, br * inv, rescale); bi = L_SEL(bi, bi * inv, rescale);
            unit = L_SEL(unit, unit * inv, rescale);
        }
    }
    lmask cut = (zr * zr + zi * zi <= jp.bailout2) & (QNORM2(p) > (real)(LOCUS_R2));
    quat g = QUAT(zr * ar + zi * ai, zi * ar - zr * ai, zr * br + zi * bi, zi * br - zr * bi);
    return QSEL(g, p, cut);
}

#define julia_inside locus_inside
#define julia_level locus_level
#define KIND_NORMAL locus_normal
#undef ALG_HAS_DE
