/* march/cone.cl: where the camera rays of a block of CONE_BLOCK x CONE_BLOCK pixels can start
 * the distance-estimate march (-D CONE_START, with march/de.cl; seed 000 §4's near plane
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

PACKET_KERNEL void cone_starts(const int n_items, const int blocks_w, const int bx0, const int by0,
                          const real4 eye, const real4 forward, const real4 right, const real4 up,
                          const real tan_half_fov, const int image_w, const int image_h,
                          const real4 c, const int max_iter, const real bailout, const real radius,
                          const real near_set, const real far_set, const int max_steps,
                          __global real2 *cone)
{
    /* LANES blocks per work-item, one after another along the tile's rows of blocks */
    size_t i0 = get_global_id(0) * LANES;
    if (i0 >= (size_t)n_items)
        return;
    julia_params jp = { c, bailout * bailout, (real)0, max_iter COUNTER_NONE };
    real k = CONE_SPREAD * (real)2 * tan_half_fov / (real)image_h;
    quat o = QUAT_UNIFORM(eye), d;   /* every ray leaves the eye */
#if LANES == 1
    {
        int bx = bx0 + (int)(i0 % (size_t)blocks_w), by = by0 + (int)(i0 / (size_t)blocks_w);
        d = camera_ray_at(bx * CONE_BLOCK, by * CONE_BLOCK, (real)(CONE_BLOCK / 2), (real)(CONE_BLOCK / 2),
                          forward, right, up, tan_half_fov, image_w, image_h);
    }
#else
    lreal u, v;
    for (int j = 0; j < LANES; ++j) {   /* gather; a lane past the end repeats block i0 */
        size_t i = i0 + j < (size_t)n_items ? i0 + j : i0;
        int bx = bx0 + (int)(i % (size_t)blocks_w), by = by0 + (int)(i / (size_t)blocks_w);
        camera_uv(bx * CONE_BLOCK, by * CONE_BLOCK, (real)(CONE_BLOCK / 2), (real)(CONE_BLOCK / 2), tan_half_fov,
                  image_w, image_h, &((real *)&u)[j], &((real *)&v)[j]);
    }
    d = camera_dirs(u, v, forward, right, up);   /* as the march's packets make theirs */
#endif
    lreal t, far;   /* the ray's entry and exit of the bounding ball, as march/march.cl takes them */
    lmask active = ball_span(o, d, radius, near_set, far_set, &t, &far) & (far >= t);
    lreal t_lo = (lreal)INFINITY, t_last = (lreal)-1;
    quat away = ORBIT_AWAY(jp);
    for (int i = 0; i < max_steps && L_ANY(active); ++i) {
        lmask escaped;
        lreal dist = julia_distance_formula(QSEL(away, QRAY(o, d, t), active), jp, &escaped);
        lreal r = k * t;
        lmask held = active & escaped & (dist > (real)2 * r);
        if (i == 0)
            t_lo = L_SEL(t_lo, t - (dist - r), held);
        t_last = L_SEL(t_last, t, held);
        t = L_SEL(t, (t + dist) / ((real)1 + k), held);
        active = held & (t <= far);
    }
#if LANES == 1
    cone[i0] = (real2)(t_lo, t_last);
#else
    for (int j = 0; j < LANES && i0 + j < (size_t)n_items; ++j)   /* scatter */
        cone[i0 + j] = (real2)(((real *)&t_lo)[j], ((real *)&t_last)[j]);
#endif
}
