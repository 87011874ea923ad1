/* enclose/split.cl: orbit enclosures of a ray segment in a split algebra
 * (algebra/hypercomplex.cl), for march/proven.cl.  The iterate is kept as its two idempotent
 * components a, b, each a complex number iterated on its own by f, so each gets an affine
 * form in the segment's s in [-1, 1] (enclose/ball.cl says why):
 *     a_n(s) in m + s v + B(r)   (complex m, v),
 * pushed through f by Taylor's theorem (the powers, sqr and cube, by products of forms,
 * enclose/caff.cl, whose s^2 terms go half into the centre; the functions with f'' = +-f to
 * second order, caff_f below): with d = s v + e, |e| <= r, rho = |v| + r,
 *     f(m + d) = f(m) + s f'(m) v + f'(m) e + R,   |R| <= rho^2 / 2 sup|f''|,
 * the sup over the disc of radius rho around m, which the function piece bounds
 * (FUNC_M2(m, rho), function/<name>.cl).  Where it gives no bound (a pole or a branch cut
 * in the disc) or the piece has none, the form is widened to its disc {m, |v| + r} and
 * pushed through the piece's cfun_disc (enclose/disc.cl) instead, tangent 0.  All points
 * are outside the bailout ball when |h|^2 = (|a|^2 + |b|^2) / 2 > bailout^2 at the least
 * |(a, b)| the forms allow. */

typedef struct { caff a, b; } enclosure;   /* caff: enclose/caff.cl */

/* ``live``: the lanes whose result counts (a finished lane's garbage must not send the
 * whole packet down the disc path) */
inline caff caff_f(caff z, lmask live)
{
#ifdef FUNC_POWER
    /* the powers by products of forms (enclose/caff.cl), which put half of each s^2 term into
     * the centre: the square's remainder |v|^2 / 2 + 2 (|m| + |v|) r + r^2 against Taylor's
     * rho^2, the cube's about 3/2 |m| |v|^2 + |v|^3 / 2 against 3 (|m| + rho) rho^2 */
#if FUNC_POWER == 2
    return caff_sqr(z);
#else
    return caff_mul(caff_sqr(z), z);
#endif
#else
    lreal rho = c_abs(z.v) + z.r;
    caff out = z;
#ifdef FUNC_M2
    cplx fm = cfun(z.m), d1 = cfun_d(z.m);
    cplx v = c_mul(d1, z.v);
    lreal da = c_abs(d1);
#ifdef FUNC_D2_SIGN
    /* f'' = FUNC_D2_SIGN f and FUNC_M2 bounds f''' too (function/sin.cl and its kin): the
     * second-order term f''(m) d^2 / 2 kept at m, its s^2 v^2 split as the powers' (half into
     * the centre), Taylor's remainder of third order:
     *     r' = |f'(m)| r + |f''(m)| (|v|^2 / 4 + (|v| + r / 2) r) + rho^3 / 6 sup|f'''|,
     * against rho^2 / 2 sup|f''|; the centre and its size take f''(m) v^2 / 4 */
    lreal fa = c_abs(fm), va = c_abs(z.v);
    fm = c_add(fm, c_scale((lreal)((real)0.25 * (real)FUNC_D2_SIGN), c_mul(fm, c_sqr(z.v))));
    lreal r = da * z.r * ENC_UP +
              (fa * ((real)0.25 * va * va + (va + (real)0.5 * z.r) * z.r) + rho * rho * rho * FUNC_M2(z.m, rho) / (real)6) * ENC_UP;
    lreal size = fa * ((real)1 + va * va) + (real)4 * c_abs(v);
#else
    lreal r = da * z.r * ENC_UP + (real)0.5 * rho * rho * FUNC_M2(z.m, rho) * ENC_UP;
#ifdef FUNC_ROUND_GAIN   /* a function whose value loses more than a few ulps (function/pwr.cl) */
    lreal size = (c_abs(fm) + (real)4 * c_abs(v)) * FUNC_ROUND_GAIN(z.m);
#else
    lreal size = c_abs(fm) + (real)4 * c_abs(v);
#endif
#endif
    r = enc_radius(L_SEL(r, (lreal)INFINITY, isnan(r) | isnan(size)), size, ENC_ROUND_FN);
    out = A(fm, v, r);
    lmask bad = live & !(r < (lreal)INFINITY);
    if (!L_ANY(bad))
        return out;
#else
    lmask bad = L_TRUE;
#endif
    cdisc w = cfun_disc(D(z.m, enc_radius(rho, (lreal)0, ENC_ROUND)));
    return A(C(L_SEL(out.m.re, w.m.re, bad), L_SEL(out.m.im, w.m.im, bad)),
             C(L_SEL(out.v.re, (lreal)0, bad), L_SEL(out.v.im, (lreal)0, bad)), L_SEL(out.r, w.r, bad));
#endif
}

/* the points o + t d, t in [t0, t1]: centre, tangent and the rounding of o + t d and ALG_IN */
inline enclosure enc_segment(quat o, quat d, lreal t0, lreal t1)
{
    lreal tm = (real)0.5 * (t0 + t1), hw = (real)0.5 * (t1 - t0);
    quat q = ALG_IN(QRAY(o, d, tm)), v = ALG_IN(QSCALE(hw, d));
    lreal r = enc_radius((lreal)0, (real)2 * (QLEN(o) + fabs(tm) * QLEN(d)), ENC_ROUND);
    enclosure e = {A(C(q.x, q.y), C(v.x, v.y), r), A(C(q.z, q.w), C(v.z, v.w), r)};
    return e;
}

inline enclosure enc_step(enclosure e, real4 c, lmask live)
{
    caff a = caff_f(e.a, live), b = caff_f(e.b, live);
    cplx ca = C((lreal)c.x, (lreal)c.y), cb = C((lreal)c.z, (lreal)c.w);
    enclosure out = {A(c_add(a.m, ca), a.v, enc_radius(a.r, c_abs(a.m) + c_abs(ca), ENC_ROUND)),
                     A(c_add(b.m, cb), b.v, enc_radius(b.r, c_abs(b.m) + c_abs(cb), ENC_ROUND))};
    return out;
}

/* the sum of two forms in the same s, per component (enclose/mandelbrot.cl) */
inline enclosure enc_add(enclosure x, enclosure y)
{
    enclosure out = {caff_add(x.a, y.a), caff_add(x.b, y.b)};
    return out;
}

/* the form plus a constant k in the algebra's coordinates (the components' (x, y), (z, w)) */
inline enclosure enc_shift(enclosure e, real4 k)
{
    cplx ka = C((lreal)k.x, (lreal)k.y), kb = C((lreal)k.z, (lreal)k.w);
    enclosure out = {A(c_add(e.a.m, ka), e.a.v, enc_radius(e.a.r, c_abs(e.a.m) + c_abs(ka), ENC_ROUND)),
                     A(c_add(e.b.m, kb), e.b.v, enc_radius(e.b.r, c_abs(e.b.m) + c_abs(kb), ENC_ROUND))};
    return out;
}

/* every point has |h|^2 > bailout2: |(a, b)| >= |(ma + s va, mb + s vb)| - |(ra, rb)|, the
 * first least over s in [-1, 1] (the distance from 0 to a segment in R^4) */
inline lmask enc_outside(enclosure e, real bailout2)
{
    quat m = QUAT(e.a.m.re, e.a.m.im, e.b.m.re, e.b.m.im), v = QUAT(e.a.v.re, e.a.v.im, e.b.v.re, e.b.v.im);
    lreal l = enc_least_norm(m, v) * ((real)1 - ENC_ROUND) - lane_hypot(e.a.r, e.b.r);   /* enclose/disc.cl */
    return (l > (real)0) & ((real)0.5 * l * l > bailout2);
}

/* the part [-1, s] of the segment the forms keep outside the bailout (-1: none; ``live``: the
 * lanes that ask), march/proven.cl's partial proofs (enclose/disc.cl enc_prefix_of): every
 * point's |h|^2 = |(a, b)|^2 / 2 with |(a, b)| >= |m + s v| (1 - ENC_ROUND) - |(ra, rb)| >
 * sqrt(2) bailout there */
#define ENC_HAS_PREFIX
inline lreal enc_prefix(enclosure e, real bailout, lmask live)
{
    quat m = QUAT(e.a.m.re, e.a.m.im, e.b.m.re, e.b.m.im), v = QUAT(e.a.v.re, e.a.v.im, e.b.v.re, e.b.v.im);
    return enc_prefix_of(m, v, QNORM2(m), (real)1.4142135623730951 * bailout + lane_hypot(e.a.r, e.b.r), live);
}

/* how many times its extent the centre lies beyond the bailout (<= 0: inside) */
inline lreal enc_centre_norm(enclosure e)
{
    return sqrt((real)0.5 * (e.a.m.re * e.a.m.re + e.a.m.im * e.a.m.im + e.b.m.re * e.b.m.re + e.b.m.im * e.b.m.im));
}

inline lreal enc_extent(enclosure e)
{
    return lane_hypot(c_abs(e.a.v) + e.a.r, c_abs(e.b.v) + e.b.r) * (real)0.70710678118654752;
}

inline lreal enc_margin(enclosure e, real bailout) { return (enc_centre_norm(e) - bailout) / enc_extent(e); }

/* the lanes whose forms may pass a test (march/proven.cl ENC_GATE): a positive margin needs
 * the centre's |h| past the bailout, a part outside needs the start's |(a, b)| <= |m| + |v|
 * past sqrt(2) bailout + |(ra, rb)| */
#define ENC_HAS_GATE
inline lmask enc_gate(enclosure e, real bailout)
{
    lreal hm = enc_centre_norm(e);
    lreal vl = sqrt(e.a.v.re * e.a.v.re + e.a.v.im * e.a.v.im + e.b.v.re * e.b.v.re + e.b.v.im * e.b.v.im);
    return (hm > bailout) | ((real)1.4142135623730951 * (hm - bailout) + vl > lane_hypot(e.a.r, e.b.r));
}

/* Each component on its own (march/proven.cl's part ladder, enclose/julia.cl
 * ENC_PART_LADDER_POWER): |h| >= |a| / sqrt(2), so every point whose a lies beyond ta there
 * is outside (ta: the ladder's radius for the iterations left), and likewise for b.  The
 * gate, the test, the margin and the partial proof of those two forms. */
inline lmask enc_gate_parts(enclosure e, real ta, real tb)
{
    return (c_abs(e.a.m) > ta) | (c_abs(e.b.m) > tb);
}

inline lmask enc_outside_parts(enclosure e, real ta2, real tb2)
{
    return caff_outside(e.a, ta2) | caff_outside(e.b, tb2);
}

inline lreal enc_margin_parts(enclosure e, real ta, real tb)
{
    return fmax(caff_margin(e.a, ta), caff_margin(e.b, tb));
}

inline lreal enc_prefix_parts(enclosure e, real ta, real tb, lmask live)
{
    return fmax(caff_prefix(e.a, ta, live), caff_prefix(e.b, tb, live));
}

/* whether the forms may still prove the segment (enclose/ball.cl enc_hopeful; NaN: no) */
inline lmask enc_hopeful(enclosure e, real bailout)
{
    return enc_extent(e) < (real)2 * (enc_centre_norm(e) + bailout);
}
