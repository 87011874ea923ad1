/* enclose/julia_stack.cl (-D KIND_JULIA_STACK with march.method = "proven"): the orbit
 * enclosures of a ray segment for a stack of complex Julia sets (kind/julia_stack.cl), for
 * march/proven.cl.  The segment's points p(s) = m + s v give z_0 = x + i y and u exactly as
 * forms in s (enclose/caff.cl), so c(u) = c_mid + u c_half is one too, kept beside the orbit
 * and added at every step: z_{n+1} = z_n^2 + c(u).  A segment is empty when the orbit's form
 * leaves the bailout disc at some n = 0 .. max_iter, or when all its u lie beyond the slab
 * |u| <= 1 (the set's caps).  The stack iterates a complex map of its own, so this piece is
 * the whole enclosure (no algebra piece before it). */
#define ENC_STEPS(jp) ((jp).max_iter)

typedef caff_orbit enclosure;   /* off: every point is beyond the slab (enclose/caff.cl) */
#define enc_outside orbit_outside
#define enc_margin orbit_margin
#define enc_hopeful orbit_hopeful
typedef caff enc_param;                             /* c(u) */

inline enclosure enc_start(quat o, quat d, lreal t0, lreal t1, julia_params jp, enc_param *p)
{
    lreal tm = (real)0.5 * (t0 + t1), hw = (real)0.5 * (t1 - t0);
    quat m = QRAY(o, d, tm), v = QSCALE(hw, d);
    lreal r = enc_radius((lreal)0, QLEN(o) + fabs(tm) * QLEN(d), ENC_ROUND);
    cplx cm = C((lreal)(real)(STACK_CM_RE), (lreal)(real)(STACK_CM_IM));
    cplx ch = C((lreal)(real)(STACK_CH_RE), (lreal)(real)(STACK_CH_IM));
    /* c(u) = c_mid + u c_half with u = m.z + s v.z (+ its rounding r) */
    lreal sh = c_abs(ch);
    *p = A(c_add(cm, C(m.z * ch.re, m.z * ch.im)), C(v.z * ch.re, v.z * ch.im),
           enc_radius(sh * r, c_abs(cm) + (real)2 * sh * (fabs(m.z) + fabs(v.z)), ENC_ROUND));
    enclosure e = {caff_of(m.x, m.y, v.x, v.y, r), (fabs(m.z) - fabs(v.z) - r) > (real)1};
    return e;
}

inline enclosure enc_next(enclosure e, enc_param c, lmask live)
{
    enclosure out = {caff_add(caff_sqr(e.z), c), e.off};
    return out;
}
