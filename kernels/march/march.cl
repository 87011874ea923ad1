/* march/march.cl: the march kernel, LANES rays per work-item (common/lanes.cl; 1 by default).  Each work-item
 * makes its rays from the camera (rays.cl camera_ray) for pixels (x0, y0) + its index in a tile
 * tile_w wide; -D RAYS_FROM_BUFFERS reads them from origins/dirs instead (the tests' and
 * benchmarks' arbitrary rays).  The ray o + t d (|d| = 1)
 * is clipped to the bounding 4-ball |p| <= radius, which provably holds the set
 * (Quilez 2002, Quilez (n.d.): bound first, march only inside); rays that miss it do no
 * iteration.  near/far < 0 mean "the sphere's entry/exit".  flags gets the march's
 * guard flags (common/codes.cl), 0 when none fired; bracket the width of the certified
 * bracket behind each hit's depth (march/refine.cl), +inf where nothing was hit;
 * unresolved how far in front of the depth the space the march did not prove empty
 * begins (on a miss the unproven width; march/proven.cl; the other marches prove nothing:
 * all of it), 0 for rays that miss the bounding ball. */

#ifdef RAYS_FROM_BUFFERS
#define RAY_ARGS __global const real4 *origins, __global const real4 *dirs
#define RAY_AT(i, ok, dk) do { ok = origins[i]; dk = dirs[i]; } while (0)
#else
#define RAY_ARGS const real4 eye, const real4 forward, const real4 right, const real4 up, \
                 const real tan_half_fov, const int image_w, const int image_h, const int x0, const int y0, \
                 const int pixel_sample, const int pixel_samples
/* pixel i's (u, v) on the image plane (rays.cl camera_uv); a packet makes its directions from
 * its lanes' in its lanes (rays.cl camera_dirs), one ray per work-item its own (camera_dir) */
#define RAY_UV(i, u, v) do { \
        int px_ = x0 + (int)((i) % (size_t)tile_w), py_ = y0 + (int)((i) / (size_t)tile_w); \
        real ox_, oy_; \
        sample_offset(px_, py_, pixel_sample, pixel_samples, &ox_, &oy_); \
        camera_uv(px_, py_, ox_, oy_, tan_half_fov, image_w, image_h, &u, &v); \
    } while (0)
#define RAY_AT(i, ok, dk) do { \
        real u_, v_; \
        RAY_UV(i, u_, v_); \
        ok = eye; \
        dk = camera_dir(u_, v_, forward, right, up); \
    } while (0)
#endif

/* -D CLIP: up to 4 half-spaces clip_n[k] . p <= clip_off[k] cut the set open (scene.Clip):
 * each clips [near, far]; a hit at the first point of an interval that a plane started
 * lies on that plane's cut face, flagged FLAG_CUT_FACE | k << 5 for march/clip.cl. */
/* (FLAG_CUT_FACE: common/codes.cl; CLIP_ARGS: common/lanes.cl) */

/* -D CONE_START (the estimate's march of camera rays, march/cone.cl): each ray of a block
 * whose entry the block's cone covers starts at the cone's t_last; cone holds the tile's
 * blocks (cone_w to a row of them, the first the block of pixel (x0, y0)). */
#ifdef CONE_START
#define CONE_ARGS , __global const real2 *cone, const int cone_w
#define CONE_AT(i) (((y0 + (int)((i) / (size_t)tile_w)) / CONE_BLOCK - y0 / CONE_BLOCK) * cone_w + \
                    (x0 + (int)((i) % (size_t)tile_w)) / CONE_BLOCK - x0 / CONE_BLOCK)
#else
#define CONE_ARGS
#endif

#ifdef CLIP
/* Each half-space clip_n[k] . p <= clip_off[k] (k < n_clip) clips the ray's [near, far]; a ray
 * parallel to a plane and outside it is dead.  Returns 1 + the plane that set near, 0 where the
 * ball did (a hit there lies on that plane's cut face). */
inline lmask clip_span(quat o, quat d, int n_clip, real4 clip_n0, real4 clip_n1, real4 clip_n2, real4 clip_n3,
                       real4 clip_off, lreal *near, lreal *far, lmask *live)
{
    lmask cut = 0;
    for (int k = 0; k < n_clip; ++k) {
        real4 nk = CLIP_NORMAL(k);
        real off = CLIP_OFFSET(k);
        lreal dn = QDOT_UNIFORM(d, nk), on = QDOT_UNIFORM(o, nk) - off;
        lreal tp = -on / dn;
        *far = L_SEL(*far, fmin(*far, tp), dn > (real)0);
        lmask raise = (dn < (real)0) & (tp > *near);
        *near = L_SEL(*near, tp, raise);
        cut = L_SEL(cut, (lmask)(k + 1), raise);
        *live &= !((dn == (real)0) & (on > (real)0));
    }
    return cut;
}
#endif

#if LANES > 1
/* A packet's results written to its lanes' pixels (lane_index; a lane past the tile's edge is
 * not written): depth, the hit point (NaN off hits), status, samples, guard flags, the
 * certified bracket (+inf off hits) and the unresolved width. */
inline void march_scatter(const size_t *lane_index, int n_items, quat o, quat d, lreal t, lmask st, lmask n,
                          lmask fl, lreal width, lreal unres, __global real *depth, __global real4 *point,
                          __global int *status, __global int *samples, __global int *flags,
                          __global real *bracket, __global real *unresolved)
{
    for (int k = 0; k < LANES; ++k) {
        size_t i = lane_index[k];
        if (i >= (size_t)n_items)
            continue;
        real tk = LANE(t, k);
        int sk = MASK_LANE(st, k);
        real4 ok = LANE_QUAT(o, k);
        real4 dk = LANE_QUAT(d, k);
        depth[i] = tk;
        point[i] = sk == STATUS_HIT ? ok + tk * dk : (real4)(NAN);
        status[i] = sk;
        samples[i] = MASK_LANE(n, k);
        flags[i] = MASK_LANE(fl, k);
        bracket[i] = sk == STATUS_HIT ? LANE(width, k) : INFINITY;
        unresolved[i] = LANE(unres, k);
    }
}
#endif

/* -D PACKET_PAIRS (common/lanes.cl PACKETS; march/de.cl only): each work-item marches two
 * neighbouring blocks, their estimates side by side (march_ray_pair). */
PACKET_KERNEL void march(const int n_items, const int tile_w, RAY_ARGS,
                    const real4 c, const int max_iter, const real bailout, const real epsilon,
                    const real radius, const real near_set, const real far_set,
                    const int z_resolution, const int post_steps, const int max_steps,
                    __global real *depth, __global real4 *point,
                    __global int *status, __global int *samples, __global int *flags,
                    __global real *bracket, __global real *unresolved COUNTER_ARG CLIP_ARGS CONE_ARGS)
{
    /* LANES neighbouring rays per packet (common/lanes.cl): one ray, or a block of BLOCK_W x
     * BLOCK_H pixels of the tile (tile_w wide, n_items / tile_w high), PACKETS packets per
     * work-item; launches are padded to whole work-groups (opencl/runner.launch) and a block may
     * reach past the tile's edges */
#if LANES == 1
    size_t i0 = get_global_id(0);
    if (i0 >= (size_t)n_items)
        return;
#else
    size_t lane_index[PACKETS][LANES];
    for (int p = 0; p < PACKETS; ++p)
        if (!packet_lanes(get_global_id(0), p, PACKETS, n_items, tile_w, lane_index[p]))
            return;
    /* a lane past the tile's edge repeats the first packet's first pixel and is not written */
    size_t i0 = lane_index[0][0];
#endif
    julia_params jp = { c, bailout * bailout, epsilon, max_iter COUNTER_INIT(i0) };
    quat o[PACKETS], d[PACKETS];
    lreal near[PACKETS], far[PACKETS], start[PACKETS];
    lmask live[PACKETS];
#ifdef CLIP
    lmask cut[PACKETS];             /* 1 + the plane that set near, 0: the ball did */
#endif
#ifdef CONE_START
    lmask coned[PACKETS];
#endif
    for (int p = 0; p < PACKETS; ++p) {
        lmask valid;
#if LANES == 1
        RAY_AT(i0, o[p], d[p]);
        valid = 1;
#elif defined(RAYS_FROM_BUFFERS)
        for (int k = 0; k < LANES; ++k) {  /* gather into structure-of-arrays lanes */
            size_t i = lane_index[p][k] < (size_t)n_items ? lane_index[p][k] : i0;
            real4 ok, dk;
            RAY_AT(i, ok, dk);
            SET_LANE_QUAT(o[p], k, ok);
            SET_LANE_QUAT(d[p], k, dk);
            MASK_LANE(valid, k) = lane_index[p][k] < (size_t)n_items ? -1 : 0;
        }
#else
        lreal u, v;
        for (int k = 0; k < LANES; ++k) {  /* each lane's place on the image plane */
            size_t i = lane_index[p][k] < (size_t)n_items ? lane_index[p][k] : i0;
            RAY_UV(i, LANE(u, k), LANE(v, k));
            MASK_LANE(valid, k) = lane_index[p][k] < (size_t)n_items ? -1 : 0;
        }
        o[p] = QUAT_UNIFORM(eye);
        d[p] = camera_dirs(u, v, forward, right, up);
#endif
        live[p] = valid & ball_span(o[p], d[p], radius, near_set, far_set, &near[p], &far[p]);
#ifdef CLIP
        cut[p] = clip_span(o[p], d[p], n_clip, clip_n0, clip_n1, clip_n2, clip_n3, clip_off, &near[p], &far[p],
                           &live[p]);
#endif
        live[p] &= far[p] >= near[p];
        start[p] = near[p];
#ifdef CONE_START
        lreal t_lo, t_last;
#if LANES == 1
        real2 cv = cone[CONE_AT(i0)];
        t_lo = cv.x;
        t_last = cv.y;
#else
        for (int k = 0; k < LANES; ++k) {
            real2 cv = cone[CONE_AT(lane_index[p][k] < (size_t)n_items ? lane_index[p][k] : i0)];
            LANE(t_lo, k) = cv.x;
            LANE(t_last, k) = cv.y;
        }
#endif
        coned[p] = live[p] & (t_last > near[p]) & (near[p] >= t_lo) & (t_last < far[p]);
        start[p] = L_SEL(near[p], t_last, coned[p]);
#endif
    }
    lmask st[PACKETS], n[PACKETS], fl[PACKETS];
    lreal t[PACKETS], width[PACKETS], unres[PACKETS];
    for (int p = 0; p < PACKETS; ++p) {
        st[p] = STATUS_MISS;
        n[p] = fl[p] = 0;
        t[p] = width[p] = INFINITY;
        unres[p] = 0;
    }
#if PACKETS == 2
    if (L_ANY(live[0] | live[1]))
        march_ray_pair(o, d, start, far, live, jp, post_steps, max_steps, st, n, fl, width, unres, t);
#else
    if (L_ANY(live[0]))
        t[0] = march_ray(o[0], d[0], start[0], far[0], live[0], jp, z_resolution, post_steps, max_steps,
                         &st[0], &n[0], &fl[0], &width[0], &unres[0]);
#endif
    for (int p = 0; p < PACKETS; ++p) {
#ifdef CONE_START
        /* a first point inside: the cone's estimate was wrong for this ray; march it from its entry */
        lmask redo = coned[p] & (st[p] == STATUS_HIT) & (width[p] == (real)0);
        if (L_ANY(redo)) {
            lreal t2 = march_ray(o[p], d[p], near[p], far[p], redo, jp, z_resolution, post_steps, max_steps,
                                 &st[p], &n[p], &fl[p], &width[p], &unres[p]);
            t[p] = L_SEL(t[p], t2, redo);
        }
        /* the estimate proves nothing: unresolved is measured from the entry, as without the cone */
        unres[p] = L_SEL(unres[p], unres[p] + (start[p] - near[p]), coned[p] & !redo);
#endif
#ifdef CLIP
        fl[p] |= L_SEL((lmask)0, (lmask)FLAG_CUT_FACE | ((cut[p] - 1) << 5),
                       (st[p] == STATUS_HIT) & (width[p] == (real)0) & (cut[p] > 0));
#endif
#if LANES == 1
        depth[i0] = t[p];
        point[i0] = st[p] == STATUS_HIT ? o[p] + t[p] * d[p] : (real4)(NAN);
        status[i0] = st[p];
        samples[i0] = n[p];
        flags[i0] = fl[p];
        bracket[i0] = st[p] == STATUS_HIT ? width[p] : INFINITY;
        unresolved[i0] = unres[p];
#else
        march_scatter(lane_index[p], n_items, o[p], d[p], t[p], st[p], n[p], fl[p], width[p], unres[p], depth, point,
                      status, samples, flags, bracket, unresolved);
#endif
    }
}
