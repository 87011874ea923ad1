/* enclose/ball.cl: orbit enclosures of a ray segment for the algebras whose iterate is the
 * point itself (algebra/quaternion.cl, cquat.cl, commutative.cl), for march/proven.cl.
 *
 * The segment's points are p(s) = m + s v, s in [-1, 1] (m its midpoint, v half its
 * extent).  The enclosure is an affine form with one noise symbol, the segment's own s:
 *     q_n(s) in m_n + s v_n + B(r_n),
 * a centre, a tangent and a remainder ball (affine arithmetic with one symbol: Knoll,
 * Hijazi, Kensler, Schott, Hansen and Hagen 2009 enclose implicit surfaces along rays
 * this way).  The spread along the orbit's tangent is carried exactly to first order, so
 * only second-order terms and the part of the remainder that the map stretches go into the
 * ball; a ball alone would grow by the map's largest stretch in every direction at every
 * step (the wrapping that makes plain interval proofs fail near the surface).
 *
 * With q = m + d, d = s v + e, |e| <= r, rho = |v| + r >= |d|, and the algebra's bounds on
 * its product - ALG_ENCLOSE_K, a K with |a b| <= K |a| |b| (1 for quaternions, whose
 * norm is multiplicative; 2 for the multiplication tables: each coordinate of a b is
 * a^T P b with P a signed permutation) and ALG_LBOUND(m), a bound on the norm of h ->
 * m h (|m|; the tables' algebra/power.cl alg_lbound):
 *     f(q) = f(m) + J[s v] + J[e] + R,  J = julia_f_jvp at m,
 *     D = 2:  |J[e]| <= 2 L(m) r,   R = d d = s^2 v v + s (v e + e v) + e e,
 *     D = 3:  |J[e]| <= (L(m m) + 2 L(m)^2) r,   R = s^2 Q(v) + s^3 v^3 + the terms in e,
 * Q(x) the second-order term of (m + x)^3 (m x x + x m x + x x m; the tables' cube, with
 * its bracketing (algebra/power.cl), 2 (m x) x + (x x) m), which is the derivative of x^3
 * at v along m (julia_f_jvp(v, m)), |Q(x)| <= 3 K L(m) |x|^2; the terms in e are at most
 * 3 K L(m) (2 |v| + r) r + K^2 ((|v| + r)^3 - |v|^3).  The powers of s are split as affine
 * arithmetic splits a noise symbol's (Stolfi & de Figueiredo, "Self-Validated Numerical
 * Methods and Applications", 1997, §3.3; the best approximations of s^2 and s^3 on [-1, 1]
 * of degree below theirs, Chebyshev's): s^2 = 1/2 + (s^2 - 1/2), |s^2 - 1/2| <= 1/2, and
 * s^3 = 3 s / 4 + (s^3 - 3 s / 4), |s^3 - 3 s / 4| <= 1/4.  So
 *     D = 2:  m' = f(m) + v v / 2,   r' = 2 L(m) r + |v v| / 2 + 2 L(v) r + K r^2,
 *     D = 3:  m' = f(m) + Q(v) / 2,  v' = J[v] + 3 v^3 / 4,
 *             r' = (L(m m) + 2 L(m)^2) r + |Q(v)| / 2 + |v^3| / 4 + the terms in e,
 * against K (|v| + r)^2 and 3 K L(m) rho^2 + K^2 rho^3, rho = |v| + r, for the whole of R:
 * half the second-order growth, a quarter of the third (on the default scene, float64 twin
 * at 80x60, 22.4 enclosures a ray fell to 19.0).  Every radius is raised for the rounding
 * of the centre and tangent (enclose/disc.cl enc_radius). */

/* ml = |m| and vl = |v| are carried with the form: the proof's test, margin and hope and the
 * next step each took them, a square root each, on the march's critical path */
typedef struct { quat m, v; lreal r, ml, vl; } enclosure;

inline enclosure enc_form(quat m, quat v, lreal r)
{
    enclosure e = {m, v, r, QLEN(m), QLEN(v)};
    return e;
}

/* the rounding allowance of a step, in the terms' sizes: 4 (enclose/disc.cl's ENC_ROUND
 * times twice their sum); the rotated map (kind/rotate.cl, fractal.theta) turns the centre and
 * the tangent into and out of the unrotated frame, two more 2-term sums each, so 8 there.
 * Its bounds hold as they are (the rotation is the quaternions' alone, scene/rules.py): a left
 * multiplication by a unit quaternion keeps norms, so |J[e]| <= 2 |m| |e| and R's parts
 * keep their bounds for u f(u^-1 q) + u c as for f(q) + c, its v v being u (u^-1 v)^2. */
#ifdef ROTATE_COS
#define ENC_STEP_GAIN ((real)8)
#else
#define ENC_STEP_GAIN ((real)4)
#endif

inline enclosure enc_segment(quat o, quat d, lreal t0, lreal t1)
{
    lreal tm = (real)0.5 * (t0 + t1), hw = (real)0.5 * (t1 - t0);
    return enc_form(QRAY(o, d, tm), QSCALE(hw, d), enc_radius((lreal)0, QLEN(o) + fabs(tm) * QLEN(d), ENC_ROUND));
}

inline enclosure enc_step(enclosure e, real4 c, lmask live)   /* ``live``: unused here */
{
#ifdef ALG_LBOUND_IS_LEN
    lreal s = e.ml, lm = e.ml, sv = e.vl;
#else
    lreal s = e.ml, lm = ALG_LBOUND(e.m), sv = e.vl;
#endif
    real K = (real)ALG_ENCLOSE_K;
    /* the terms' sizes: of the centre's products (with v v's) and of the tangent's (J's bound
     * times |v|: the tangent may cancel to far less than its terms) */
#if FUNC_POWER == 2
    /* v v, the rotated map's too (kind/rotate.cl); + (-0), which the compiler drops (+ 0 it may not) */
    quat vv = julia_f(e.v, (real4)(-0.0));
#ifdef ALG_LBOUND_IS_LEN
    lreal vvl = sv * sv, lv = sv;         /* |v v| = |v|^2 */
#else
    lreal vvl = QLEN(vv), lv = ALG_LBOUND(e.v);
#endif
    lreal r = (real)2 * lm * e.r + (real)0.5 * vvl + ((real)2 * lv + K * e.r) * e.r;
#ifdef ALG_LBOUND_IS_LEN
    lreal size = (s + sv) * (s + sv);     /* K = 1, L(m) = |m| */
#else
    lreal size = K * s * s + (real)2 * lm * sv + K * sv * sv;
#endif
    quat m = QADD(julia_f(e.m, c), QSCALE((lreal)0.5, vv));
    quat v = julia_f_jvp(e.m, e.v);
#else
    quat qv = julia_f_jvp(e.v, e.m);      /* Q(v), the second-order term at m along v */
    quat cv = julia_f(e.v, (real4)(-0.0));   /* v^3 */
#ifdef ALG_LBOUND_IS_LEN
    /* |v^3| = |v|^3, and |Q(v)| by its bound 3 |m| |v|^2: its own length, a square root an
     * iteration, cost the quaternion cube 10 % of its march's time for 2 % fewer enclosures */
    lreal cvl = sv * sv * sv, qvl = (real)3 * lm * sv * sv;
#else
    lreal cvl = QLEN(cv), qvl = QLEN(qv);
#endif
    lreal jn = ALG_LBOUND_SQR(e.m) + (real)2 * lm * lm;
    lreal r = jn * e.r + (real)0.5 * qvl + (real)0.25 * cvl +
              ((real)3 * K * lm * ((real)2 * sv + e.r) + K * K * ((real)3 * sv * sv + ((real)3 * sv + e.r) * e.r)) * e.r;
    lreal size = K * K * s * s * s + jn * sv + ((real)3 * K * lm + K * K * sv) * sv * sv;
    quat m = QADD(julia_f(e.m, c), QSCALE((lreal)0.5, qv));
    quat v = QADD(julia_f_jvp(e.m, e.v), QSCALE((lreal)0.75, cv));
#endif
    return enc_form(m, v, enc_radius(r, ENC_STEP_GAIN * size + (real)2 * length(c), ENC_ROUND));
}

/* the sum of two forms in the same s: the Mandelbrot kind adds the segment's own points
 * (enclose/mandelbrot.cl) */
inline enclosure enc_add(enclosure a, enclosure b)
{
    return enc_form(QADD(a.m, b.m), QADD(a.v, b.v), enc_radius(a.r + b.r, a.ml + b.ml + a.vl + b.vl, ENC_ROUND));
}

/* the form plus a constant k in the algebra's coordinates */
inline enclosure enc_shift(enclosure e, real4 k)
{
    return enc_form(QADD_UNIFORM(e.m, k), e.v, enc_radius(e.r, e.ml + length(k), ENC_ROUND));
}

inline lmask enc_outside(enclosure e, real bailout2)
{
    lreal l = enc_least_norm(e.m, e.v) * ((real)1 - ENC_ROUND) - e.r;   /* enclose/disc.cl */
    return (l > (real)0) & (l * l > bailout2);
}

/* the part [-1, s] of the segment the form keeps outside the bailout (-1: none; ``live``: the
 * lanes that ask), march/proven.cl's partial proofs (enclose/disc.cl enc_prefix_of): every
 * point's |q| >= |m + s v| (1 - ENC_ROUND) - r > bailout there */
#define ENC_HAS_PREFIX
inline lreal enc_prefix(enclosure e, real bailout, lmask live)
{
    return enc_prefix_of(e.m, e.v, e.ml * e.ml, bailout + e.r, live);
}

/* how many times its extent the centre lies beyond the bailout (<= 0: inside): the march
 * sizes its next segment by it */
inline lreal enc_margin(enclosure e, real bailout) { return (e.ml - bailout) / (e.vl + e.r); }

/* the lanes whose form may pass a test (march/proven.cl ENC_GATE): a positive margin needs
 * |m| > bailout, the segment outside needs more, and a part outside needs its start
 * |m - v| <= |m| + |v| beyond bailout + r */
#define ENC_HAS_GATE
inline lmask enc_gate(enclosure e, real bailout)
{
    return (e.ml > bailout) | (e.ml + e.vl > bailout + e.r);
}

/* whether the form may still prove the segment: an extent past twice the centre's distance
 * plus the bailout grows faster than the centre from here on (the proof only gives up) */
inline lmask enc_hopeful(enclosure e, real bailout)
{
    return e.vl + e.r < (real)2 * (e.ml + bailout);
}

