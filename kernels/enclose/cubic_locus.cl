/* enclose/cubic_locus.cl (-D KIND_CUBIC_LOCUS with march.method = "proven"): the orbit
 * enclosures of a ray segment for the cubic connectedness locus (kind/cubic_locus.cl), for
 * march/proven.cl.  The segment's points p(s) = m + s v give a = x + i y and b = u + i w
 * exactly as forms in s (enclose/caff.cl); 3 a^2 is formed once and kept beside the orbit,
 * z_0 = LOCUS_SIGN a, z_{n+1} = z_n (z_n^2 - 3 a^2) + b.  A segment is empty when the orbit's
 * form leaves the bailout disc at some n = 0 .. max_iter, or when all its points lie outside
 * the ball |p|^2 <= LOCUS_R2 the locus is drawn in.  The locus iterates a complex map of its
 * own, so this piece is the whole enclosure (no algebra piece before it). */
#define ENC_STEPS(jp) ((jp).max_iter)

typedef caff_orbit enclosure;   /* off: every point is outside the ball (enclose/caff.cl) */
#define enc_outside orbit_outside
#define enc_margin orbit_margin
#define enc_hopeful orbit_hopeful
typedef struct { caff a3, b; } enc_param;          /* 3 a^2 and b */

inline enclosure enc_start(quat o, quat d, lreal t0, lreal t1, julia_params jp, enc_param *p)
{
    lreal tm = (real)0.5 * (t0 + t1), hw = (real)0.5 * (t1 - t0);
    quat m = QRAY(o, d, tm), v = QSCALE(hw, d);
    lreal r = enc_radius((lreal)0, QLEN(o) + fabs(tm) * QLEN(d), ENC_ROUND);
    caff a = caff_of(m.x, m.y, v.x, v.y, r);
    p->a3 = caff_scale(C((lreal)3, (lreal)0), caff_sqr(a));
    p->b = caff_of(m.z, m.w, v.z, v.w, r);
    lreal least = enc_least_norm(m, v) * ((real)1 - ENC_ROUND) - r;
    enclosure e = {caff_scale(C((lreal)(real)(LOCUS_SIGN), (lreal)0), a),
                   (least > (real)0) & (least * least > (real)(LOCUS_R2))};
    return e;
}

inline enclosure enc_next(enclosure e, enc_param p, lmask live)
{
    caff w = caff_add(caff_sqr(e.z), caff_scale(C((lreal)-1, (lreal)0), p.a3));
    enclosure out = {caff_add(caff_mul(e.z, w), p.b), e.off};
    return out;
}
