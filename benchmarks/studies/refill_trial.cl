/* benchmarks/refill_trial.cl: a trial of compaction, appended by benchmarks/refill_trial.py to the
 * march program of a scene (kernel_config.source of its march_config, the same -D switches), and
 * used by nothing else.  The estimate's march of the camera rays (march/de.cl's de_start,
 * de_leave, de_advance; the cone's starts, march/cone.cl; no refinement, no pairs), one packet
 * per work-item fed from a queue of queue_blocks blocks: a lane whose ray ends writes its
 * result and takes the queue's next ray at once, its direction, span and cone start made for
 * the fresh lanes together.  queue_blocks = 1 is the blocks' own schedule.  Each lane's
 * arithmetic is its ray's whatever the schedule, so every queue gives the same t, status and
 * step count bit for bit. */
#define NONE_RAY ((size_t)-1)
PACKET_KERNEL void march_refill(const int n_blocks, const int n_items, const int tile_w,
    const real4 eye, const real4 forward, const real4 right, const real4 up, const real tan_half_fov,
    const int image_w, const int image_h, const int x0, const int y0,
    const real4 c, const int max_iter, const real bailout, const real epsilon,
    const real radius, const real near_set, const real far_set, const int max_steps,
    __global const real2 *cone, const int cone_w, const int queue_blocks,
    __global real *out_t, __global int *out_status, __global int *out_samples)
{
    const int pixel_sample = 0, pixel_samples = 1;
    size_t b0 = get_global_id(0) * (size_t)queue_blocks;
    if (b0 >= (size_t)n_blocks)
        return;
    size_t b1 = min(b0 + (size_t)queue_blocks, (size_t)n_blocks), next_block = b0;
    julia_params jp = { c, bailout * bailout, epsilon, max_iter };
    size_t lane_ray[LANES], qidx[LANES];
    int qn = 0, qpos = 0;
    quat o = QUAT_UNIFORM(eye), d = QUAT_UNIFORM(forward);
    quat away = ORBIT_AWAY(jp);
    lreal u = 0, v = 0, far = 0;
    lmask nstep = 0, dummy = 0, capped = 0;
    de_march m = de_start((lreal)0, (lmask)0);
    for (int k = 0; k < LANES; ++k)
        lane_ray[k] = NONE_RAY;
    lmask ended = L_TRUE;
    for (;;) {
        while (L_ANY(ended)) {
            lmask fresh = 0;
            for (int k = 0; k < LANES; ++k) {
                if (!((mask_t *)&ended)[k])
                    continue;
                size_t r = lane_ray[k];
                if (r != NONE_RAY) {
                    int hit = ((mask_t *)&m.hit)[k] != 0, miss = ((mask_t *)&m.miss)[k] != 0;
                    out_t[r] = hit ? ((real *)&m.t)[k] : INFINITY;
                    out_status[r] = hit ? STATUS_HIT : (miss || !((mask_t *)&capped)[k] ? STATUS_MISS : STATUS_CAPPED);
                    out_samples[r] = ((mask_t *)&nstep)[k];
                }
                lane_ray[k] = NONE_RAY;
                while (qpos == qn && next_block < b1) {
                    packet_lanes(next_block++, 0, 1, n_items, tile_w, qidx);
                    qn = LANES;
                    qpos = 0;
                }
                while (qpos < qn && qidx[qpos] >= (size_t)n_items)
                    ++qpos;
                if (qpos < qn) {
                    size_t i = qidx[qpos++];
                    lane_ray[k] = i;
                    real uk, vk;
                    int px_ = x0 + (int)(i % (size_t)tile_w), py_ = y0 + (int)(i / (size_t)tile_w);
                    real ox_, oy_;
                    sample_offset(px_, py_, pixel_sample, pixel_samples, &ox_, &oy_);
                    camera_uv(px_, py_, ox_, oy_, tan_half_fov, image_w, image_h, &uk, &vk);
                    ((real *)&u)[k] = uk;
                    ((real *)&v)[k] = vk;
                    ((mask_t *)&fresh)[k] = -1;
                }
            }
            ended = 0;
            if (!L_ANY(fresh))
                break;
            quat dn = camera_dirs(u, v, forward, right, up);
            d = QSEL(d, dn, fresh);
            lreal nr, fr;
            lmask live = fresh & ball_span(o, dn, radius, near_set, far_set, &nr, &fr) & (fr >= nr);
            lreal t_lo = (lreal)INFINITY, t_last = (lreal)-1;
            for (int k = 0; k < LANES; ++k) {
                if (!((mask_t *)&fresh)[k])
                    continue;
                size_t i = lane_ray[k];
                real2 cv = cone[CONE_AT(i)];
                ((real *)&t_lo)[k] = cv.x;
                ((real *)&t_last)[k] = cv.y;
            }
            lmask coned = live & (t_last > nr) & (nr >= t_lo) & (t_last < fr);
            lreal start = L_SEL(nr, t_last, coned);
            de_march f = de_start(start, live);
            m.t = L_SEL(m.t, f.t, fresh); m.t_prev = L_SEL(m.t_prev, f.t_prev, fresh);
            m.omega = L_SEL(m.omega, f.omega, fresh); m.step = L_SEL(m.step, f.step, fresh);
            m.r_prev = L_SEL(m.r_prev, f.r_prev, fresh);
            m.active = L_SEL(m.active, f.active, fresh); m.shell = L_SEL(m.shell, f.shell, fresh);
            m.hit = L_SEL(m.hit, f.hit, fresh); m.miss = L_SEL(m.miss, f.miss, fresh);
            far = L_SEL(far, fr, fresh);
            nstep = L_SEL(nstep, (lmask)0, fresh);
            capped = L_SEL(capped, (lmask)0, fresh);
            ended = fresh & !live;   /* missed the ball: done at once */
        }
        if (!L_ANY(m.active))
            break;
        lmask before = m.active;
        de_leave(&m, 1, far, &dummy);
        lmask esc;
        lreal dist = julia_distance_formula(QSEL(away, QRAY(o, d, m.t), m.active), jp, &esc);
        de_advance(&m, 1, dist, esc, jp.epsilon, &dummy, &dummy);
        nstep -= before;
        lmask cap = m.active & (nstep >= max_steps);
        capped |= cap;
        m.active &= !cap;
        ended = before & !m.active;
    }
}
