/* enclose/caff.cl: complex affine forms in one real symbol s in [-1, 1], on the lane type
 * (common/lanes.cl), for the orbit enclosures of march/proven.cl: {m, v, r} holds every
 * m + s v + e with |e| <= r.  A ray segment's points are exactly such a form (its midpoint
 * and half its extent), and the forms keep the part of an orbit's spread that is linear in
 * s in the tangent v, so only what is not goes into the ball (enclose/ball.cl says why).
 * Products: (m1 + s v1 + e1)(m2 + s v2 + e2) = m1 m2 + s (m1 v2 + v1 m2) + s^2 v1 v2 +
 * (m1 + s v1) e2 + (m2 + s v2) e1 + e1 e2, and s^2 in [0, 1] puts v1 v2 / 2 into the centre
 * and |v1 v2| / 2 into the radius.  Every radius is raised for the rounding of the centre
 * and the tangent (enclose/disc.cl enc_radius, ENC_ROUND of the terms' sizes).  Used by the
 * split algebras (enclose/split.cl) and the kinds that iterate a complex map of their own
 * (enclose/julia_stack.cl, enclose/cubic_locus.cl). */

typedef struct { cplx m, v; lreal r; } caff;

inline caff A(cplx m, cplx v, lreal r) { caff z = {m, v, r}; return z; }

/* two reals m + s v (the ray's coordinates x, y) as one complex form */
inline caff caff_of(lreal mx, lreal my, lreal vx, lreal vy, lreal r) { return A(C(mx, my), C(vx, vy), r); }

inline caff caff_add(caff a, caff b)
{
    return A(c_add(a.m, b.m), c_add(a.v, b.v),
             enc_radius(a.r + b.r, c_abs(a.m) + c_abs(b.m) + c_abs(a.v) + c_abs(b.v), ENC_ROUND));
}

/* k a, k a complex lane value */
inline caff caff_scale(cplx k, caff a)
{
    lreal sk = c_abs(k);
    return A(c_mul(k, a.m), c_mul(k, a.v), enc_radius(sk * a.r, (real)2 * sk * (c_abs(a.m) + c_abs(a.v)), ENC_ROUND));
}

inline caff caff_mul(caff a, caff b)
{
    lreal ma = c_abs(a.m), mb = c_abs(b.m), va = c_abs(a.v), vb = c_abs(b.v);
    cplx vv = c_mul(a.v, b.v);
    cplx m = c_add(c_mul(a.m, b.m), C((real)0.5 * vv.re, (real)0.5 * vv.im));
    cplx v = c_add(c_mul(a.m, b.v), c_mul(a.v, b.m));
    lreal r = (real)0.5 * va * vb + (ma + va) * b.r + (mb + vb) * a.r + a.r * b.r;
    return A(m, v, enc_radius(r, (real)4 * (ma * mb + va * vb + ma * vb + va * mb), ENC_ROUND));
}

inline caff caff_sqr(caff a) { return caff_mul(a, a); }

/* how many times its extent the centre lies beyond the bailout (<= 0: inside) */
inline lreal caff_margin(caff z, real bailout) { return (c_abs(z.m) - bailout) / (c_abs(z.v) + z.r); }

/* every point has |z| > bailout: the least |m + s v| over s, less r */
inline lmask caff_outside(caff z, real bailout2)
{
    lreal l = enc_least_norm(QUAT(z.m.re, z.m.im, (lreal)0, (lreal)0), QUAT(z.v.re, z.v.im, (lreal)0, (lreal)0))
              * ((real)1 - ENC_ROUND) - z.r;
    return (l > (real)0) & (l * l > bailout2);
}

/* the part [-1, s] of the segment the form keeps beyond ``bailout`` (-1: none; ``live``: the
 * lanes that ask; enclose/disc.cl enc_prefix_of) */
inline lreal caff_prefix(caff z, real bailout, lmask live)
{
    quat m = QUAT(z.m.re, z.m.im, (lreal)0, (lreal)0);
    return enc_prefix_of(m, QUAT(z.v.re, z.v.im, (lreal)0, (lreal)0), QNORM2(m), bailout + z.r, live);
}

/* whether the form may still prove the segment (enclose/ball.cl enc_hopeful) */
inline lmask caff_hopeful(caff z, real bailout) { return c_abs(z.v) + z.r < (real)2 * (c_abs(z.m) + bailout); }

/* The enclosure of a kind that iterates a complex map of its own (enclose/julia_stack.cl,
 * enclose/cubic_locus.cl): the orbit's form, and whether every point of the segment lies
 * outside the kind's own domain (the stack's slab, the locus's ball), which proves it empty
 * by itself.  Those pieces name these enclosure, enc_outside, enc_margin, enc_hopeful. */
typedef struct { caff z; lmask off; } caff_orbit;

inline lmask orbit_outside(caff_orbit e, real bailout2) { return e.off | caff_outside(e.z, bailout2); }
inline lreal orbit_margin(caff_orbit e, real bailout) { return caff_margin(e.z, bailout); }
inline lmask orbit_hopeful(caff_orbit e, real bailout) { return caff_hopeful(e.z, bailout); }

#ifdef RAYS_FROM_BUFFERS
/* The form arithmetic alone, one form pair per work-item (the tests' handle, as
 * march/proven.cl's prove_segments): for forms a and b (centre and tangent as (m.re, m.im,
 * v.re, v.im), and the radius), a b, a + b, k a, and whether a lies outside the disc of
 * radius ``bailout``. */
__kernel void caff_ops(const int n_items, __global const real4 *a_mv, __global const real *a_r,
                       __global const real4 *b_mv, __global const real *b_r, const real4 k, const real bailout,
                       __global real4 *mul_mv, __global real *mul_r, __global real4 *add_mv, __global real *add_r,
                       __global real4 *scale_mv, __global real *scale_r, __global int *outside)
{
#if LANES == 1
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    caff a = A(C(a_mv[i].x, a_mv[i].y), C(a_mv[i].z, a_mv[i].w), a_r[i]);
    caff b = A(C(b_mv[i].x, b_mv[i].y), C(b_mv[i].z, b_mv[i].w), b_r[i]);
    caff p = caff_mul(a, b), s = caff_add(a, b), q = caff_scale(C(k.x, k.y), a);
    mul_mv[i] = (real4)(p.m.re, p.m.im, p.v.re, p.v.im);
    mul_r[i] = p.r;
    add_mv[i] = (real4)(s.m.re, s.m.im, s.v.re, s.v.im);
    add_r[i] = s.r;
    scale_mv[i] = (real4)(q.m.re, q.m.im, q.v.re, q.v.im);
    scale_r[i] = q.r;
    outside[i] = caff_outside(a, bailout * bailout) ? 1 : 0;
#endif
}
#endif
