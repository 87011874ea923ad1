/* march/cone.cl: where the camera rays of a block of CONE_BLOCK x CONE_BLOCK pixels can start
 * the distance-estimate march (-D CONE_START, with march/de.cl; Odegaard & Wennergren §4's near plane
 * from a low-resolution pass, taken along a cone).
 *
 * Every ray of the block leaves the eye o; each passes through its pixel within 2 sqrt(2)
 * pixels of the block's centre on the image plane (any sample of image.samples too), so its
 * point at parameter t lies within k t of the centre ray's point, k = 2 sqrt(2) pixel widths
 * of the plane at distance 1 (unit directions: |d_i - d_c| <= the distance of their points
 * on the plane, which is at least 1 away).  The centre ray is marched with the estimate
 * while its balls hold that cone: a ball of radius dist at t covers the cone's points from
 * t - (dist - k t) back to (t + dist) / (1 + k) ahead (triangle inequality), so the next
 * point is (t + dist) / (1 + k), and the march ends where dist falls below 2 k t, its
 * orbit does not escape, or the ball's exit is reached.  cone[b] = (t_lo, t_last): the
 * first ball covers the cone from t_lo, and t_last is the last centre point whose ball held
 * it (-1 where none did).  A ray of the block whose own entry is at or after t_lo starts its
 * march at t_last, a point the estimate puts outside; everything in front is the estimate's
 * word, as the march's own steps are (march/de.cl: the estimate proves nothing, so the
 * rays' unresolved stays measured from their entry).  Rays whose first point then turns
 * out inside are marched again from their entry (march/march.cl). */
#define CONE_BLOCK 4
#define CONE_SPREAD ((real)2.8285)    /* 2 sqrt(2), rounded up: pixels from the block's centre */

/* the centre rays' directions of LANES blocks from block i0 + first on (a lane past the end
 * repeats block i0), as the march's packets make theirs */
inline quat cone_dirs(size_t i0, size_t first, int n_items, int blocks_w, int bx0, int by0, real4 forward,
                      real4 right, real4 up, real tan_half_fov, int image_w, int image_h)
{
#if LANES == 1
    int bx = bx0 + (int)(i0 % (size_t)blocks_w), by = by0 + (int)(i0 / (size_t)blocks_w);
    return camera_ray_at(bx * CONE_BLOCK, by * CONE_BLOCK, (real)(CONE_BLOCK / 2), (real)(CONE_BLOCK / 2),
                         forward, right, up, tan_half_fov, image_w, image_h);
#else
    lreal u, v;
    for (int j = 0; j < LANES; ++j) {   /* gather */
        size_t i = i0 + first + j < (size_t)n_items ? i0 + first + j : i0;
        int bx = bx0 + (int)(i % (size_t)blocks_w), by = by0 + (int)(i / (size_t)blocks_w);
        camera_uv(bx * CONE_BLOCK, by * CONE_BLOCK, (real)(CONE_BLOCK / 2), (real)(CONE_BLOCK / 2), tan_half_fov,
                  image_w, image_h, &LANE(u, j), &LANE(v, j));
    }
    return camera_dirs(u, v, forward, right, up);
#endif
}

/* step i of a packet's cone, given the estimate dist at t: where the ball holds the cone
 * (dist > 2 k t) the cone moves on to (t + dist) / (1 + k) */
inline void cone_step(int i, lreal dist, lmask escaped, real k, lreal far, lreal *t, lmask *active, lreal *t_lo,
                      lreal *t_last)
{
    lreal r = k * *t;
    lmask held = *active & escaped & (dist > (real)2 * r);
    if (i == 0)
        *t_lo = L_SEL(*t_lo, *t - (dist - r), held);
    *t_last = L_SEL(*t_last, *t, held);
    *t = L_SEL(*t, (*t + dist) / ((real)1 + k), held);
    *active = held & (*t <= far);
}

/* LANES blocks per packet, PACKETS packets per work-item (-D PACKET_PAIRS: two, their estimates
 * side by side, iterate.cl julia_distance_formula_pair: lane for lane the same cones), one after
 * another along the tile's rows of blocks */
PACKET_KERNEL void cone_starts(const int n_items, const int blocks_w, const int bx0, const int by0,
                          const real4 eye, const real4 forward, const real4 right, const real4 up,
                          const real tan_half_fov, const int image_w, const int image_h,
                          const real4 c, const int max_iter, const real bailout, const real radius,
                          const real near_set, const real far_set, const int max_steps,
                          __global real2 *cone)
{
    size_t i0 = get_global_id(0) * LANES * PACKETS;
    if (i0 >= (size_t)n_items)
        return;
    julia_params jp = { c, bailout * bailout, (real)0, max_iter COUNTER_NONE };
    real k = CONE_SPREAD * (real)2 * tan_half_fov / (real)image_h;
    quat o = QUAT_UNIFORM(eye), d[PACKETS];   /* every ray leaves the eye */
    lreal t[PACKETS], far[PACKETS], t_lo[PACKETS], t_last[PACKETS];
    lmask active[PACKETS];
    for (int p = 0; p < PACKETS; ++p) {
        d[p] = cone_dirs(i0, (size_t)p * LANES, n_items, blocks_w, bx0, by0, forward, right, up, tan_half_fov,
                         image_w, image_h);
        /* the ray's entry and exit of the bounding ball, as march/march.cl takes them */
        active[p] = ball_span(o, d[p], radius, near_set, far_set, &t[p], &far[p]) & (far[p] >= t[p]);
        t_lo[p] = (lreal)INFINITY;
        t_last[p] = (lreal)-1;
    }
    quat away = ORBIT_AWAY(jp);
#if PACKETS == 2
    for (int i = 0; i < max_steps && L_ANY(active[0] | active[1]); ++i) {
        lmask e0, e1;
        lreal d0, d1;
        julia_distance_formula_pair(QSEL(away, QRAY(o, d[0], t[0]), active[0]),
                                    QSEL(away, QRAY(o, d[1], t[1]), active[1]), jp, &e0, &e1, &d0, &d1);
        cone_step(i, d0, e0, k, far[0], &t[0], &active[0], &t_lo[0], &t_last[0]);
        cone_step(i, d1, e1, k, far[1], &t[1], &active[1], &t_lo[1], &t_last[1]);
    }
#else
    for (int i = 0; i < max_steps && L_ANY(active[0]); ++i) {
        lmask escaped;
        lreal dist = julia_distance_formula(QSEL(away, QRAY(o, d[0], t[0]), active[0]), jp, &escaped);
        cone_step(i, dist, escaped, k, far[0], &t[0], &active[0], &t_lo[0], &t_last[0]);
    }
#endif
#if LANES == 1
    cone[i0] = (real2)(t_lo[0], t_last[0]);
#else
    for (int p = 0; p < PACKETS; ++p)
        for (int j = 0; j < LANES && i0 + p * LANES + j < (size_t)n_items; ++j)   /* scatter */
            cone[i0 + p * LANES + j] = (real2)(LANE(t_lo[p], j), LANE(t_last[p], j));
#endif
}
