/* march/march.cl: the march kernel, LANES rays per work-item (common/lanes.cl; 1 by default).  Each work-item
 * makes its rays from the camera (rays.cl camera_ray) for pixels (x0, y0) + its index in a tile
 * tile_w wide; -D RAYS_FROM_BUFFERS reads them from origins/dirs instead (the tests' and
 * benchmarks' arbitrary rays).  The ray o + t d (|d| = 1)
 * is clipped to the bounding 4-ball |p| <= radius, which provably holds the set
 * (seed 002, seed 004: bound first, march only inside); rays that miss it do no
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
#define RAY_AT(i, ok, dk) do { \
        int px_ = x0 + (int)((i) % (size_t)tile_w), py_ = y0 + (int)((i) / (size_t)tile_w); \
        real ox_, oy_; \
        sample_offset(px_, py_, pixel_sample, pixel_samples, &ox_, &oy_); \
        ok = eye; \
        dk = camera_ray_at(px_, py_, ox_, oy_, forward, right, up, tan_half_fov, image_w, image_h); \
    } while (0)
#endif

/* -D CLIP: up to 4 half-spaces clip_n[k] . p <= clip_off[k] cut the set open (scene.Clip):
 * each clips [near, far]; a hit at the first point of an interval that a plane started
 * lies on that plane's cut face, flagged FLAG_CUT_FACE | k << 5 for march/clip.cl. */
#ifdef CLIP
/* FLAG_CUT_FACE: common/codes.cl */
#define CLIP_ARGS , const int n_clip, const real4 clip_n0, const real4 clip_n1, const real4 clip_n2, \
                  const real4 clip_n3, const real4 clip_off
#else
#define CLIP_ARGS
#endif

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

PACKET_KERNEL void march(const int n_items, const int tile_w, RAY_ARGS,
                    const real4 c, const int max_iter, const real bailout, const real epsilon,
                    const real radius, const real near_set, const real far_set,
                    const int z_resolution, const int post_steps, const int max_steps,
                    __global real *depth, __global real4 *point,
                    __global int *status, __global int *samples, __global int *flags,
                    __global real *bracket, __global real *unresolved COUNTER_ARG CLIP_ARGS CONE_ARGS)
{
    /* LANES neighbouring rays per work-item (common/lanes.cl): one ray, or a block of BLOCK_W x
     * BLOCK_H pixels of the tile (tile_w wide, n_items / tile_w high); launches are padded
     * to whole work-groups (render.launch) and a block may reach past the tile's edges */
#if LANES == 1
    size_t i0 = get_global_id(0);
    if (i0 >= (size_t)n_items)
        return;
#else
    size_t lane_index[LANES];
    if (!block_lanes(get_global_id(0), n_items, tile_w, lane_index))
        return;
    /* a lane past the tile's edge repeats the block's first pixel and is not written */
    size_t i0 = lane_index[0];
#endif
    julia_params jp = { c, bailout * bailout, epsilon, max_iter COUNTER_INIT(i0) };
    quat o, d;
    lmask valid;
#if LANES == 1
    RAY_AT(i0, o, d);
    valid = 1;
#else
    for (int k = 0; k < LANES; ++k) {  /* gather into structure-of-arrays lanes */
        size_t i = lane_index[k] < (size_t)n_items ? lane_index[k] : i0;
        real4 ok, dk;
        RAY_AT(i, ok, dk);
        ((real *)&o.x)[k] = ok.x; ((real *)&o.y)[k] = ok.y;
        ((real *)&o.z)[k] = ok.z; ((real *)&o.w)[k] = ok.w;
        ((real *)&d.x)[k] = dk.x; ((real *)&d.y)[k] = dk.y;
        ((real *)&d.z)[k] = dk.z; ((real *)&d.w)[k] = dk.w;
        ((mask_t *)&valid)[k] = lane_index[k] < (size_t)n_items ? -1 : 0;
    }
#endif

    lreal near, far;
    lmask live = valid & ball_span(o, d, radius, near_set, far_set, &near, &far);
#ifdef CLIP
    lmask cut = 0;                  /* 1 + the plane that set near, 0: the ball did */
    for (int k = 0; k < n_clip; ++k) {
        real4 nk = k == 0 ? clip_n0 : k == 1 ? clip_n1 : k == 2 ? clip_n2 : clip_n3;
        real off = k == 0 ? clip_off.x : k == 1 ? clip_off.y : k == 2 ? clip_off.z : clip_off.w;
        lreal dn = QDOT_UNIFORM(d, nk), on = QDOT_UNIFORM(o, nk) - off;
        lreal tp = -on / dn;
        far = L_SEL(far, fmin(far, tp), dn > (real)0);
        lmask raise = (dn < (real)0) & (tp > near);
        near = L_SEL(near, tp, raise);
        cut = L_SEL(cut, (lmask)(k + 1), raise);
        live &= !((dn == (real)0) & (on > (real)0));
    }
#endif
    live &= far >= near;
    lreal start = near;
#ifdef CONE_START
    lreal t_lo, t_last;
#if LANES == 1
    real2 cv = cone[CONE_AT(i0)];
    t_lo = cv.x;
    t_last = cv.y;
#else
    for (int k = 0; k < LANES; ++k) {
        real2 cv = cone[CONE_AT(lane_index[k] < (size_t)n_items ? lane_index[k] : i0)];
        ((real *)&t_lo)[k] = cv.x;
        ((real *)&t_last)[k] = cv.y;
    }
#endif
    lmask coned = live & (t_last > near) & (near >= t_lo) & (t_last < far);
    start = L_SEL(near, t_last, coned);
#endif
    lmask st = STATUS_MISS, n = 0, fl = 0;
    lreal t = INFINITY, width = INFINITY, unres = 0;
    if (L_ANY(live))
        t = march_ray(o, d, start, far, live, jp, z_resolution, post_steps, max_steps, &st, &n, &fl,
                      &width, &unres);
#ifdef CONE_START
    /* a first point inside: the cone's estimate was wrong for this ray; march it from its entry */
    lmask redo = coned & (st == STATUS_HIT) & (width == (real)0);
    if (L_ANY(redo)) {
        lreal t2 = march_ray(o, d, near, far, redo, jp, z_resolution, post_steps, max_steps, &st, &n, &fl,
                             &width, &unres);
        t = L_SEL(t, t2, redo);
    }
    /* the estimate proves nothing: unresolved is measured from the entry, as without the cone */
    unres = L_SEL(unres, unres + (start - near), coned & !redo);
#endif
#ifdef CLIP
    fl |= L_SEL((lmask)0, (lmask)FLAG_CUT_FACE | ((cut - 1) << 5), (st == STATUS_HIT) & (width == (real)0) & (cut > 0));
#endif
#if LANES == 1
    depth[i0] = t;
    point[i0] = st == STATUS_HIT ? o + t * d : (real4)(NAN);
    status[i0] = st;
    samples[i0] = n;
    flags[i0] = fl;
    bracket[i0] = st == STATUS_HIT ? width : INFINITY;
    unresolved[i0] = unres;
#else
    for (int k = 0; k < LANES; ++k) {   /* scatter */
        size_t i = lane_index[k];
        if (i >= (size_t)n_items)
            continue;
        real tk = ((real *)&t)[k];
        int sk = ((mask_t *)&st)[k];
        real4 ok = (real4)(((real *)&o.x)[k], ((real *)&o.y)[k], ((real *)&o.z)[k], ((real *)&o.w)[k]);
        real4 dk = (real4)(((real *)&d.x)[k], ((real *)&d.y)[k], ((real *)&d.z)[k], ((real *)&d.w)[k]);
        depth[i] = tk;
        point[i] = sk == STATUS_HIT ? ok + tk * dk : (real4)(NAN);
        status[i] = sk;
        samples[i] = ((mask_t *)&n)[k];
        flags[i] = ((mask_t *)&fl)[k];
        bracket[i] = sk == STATUS_HIT ? ((real *)&width)[k] : INFINITY;
        unresolved[i] = ((real *)&unres)[k];
    }
#endif
}
