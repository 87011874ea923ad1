/* march_fixed.cl: fixed z-resolution scan (seed 000 §3).  Samples
 * t_i = near + i (far - near) / z_resolution, i = 0 .. z_resolution; the first
 * sample inside the set is the hit, refined by post-stepping when enabled.
 * At most z_resolution + 1 + post_steps iterations of the set test per ray. */

inline int hit_test(real4 p, julia_params jp) { return julia_inside(p, jp); }

inline real march_ray(real4 o, real4 d, real near, real far, julia_params jp,
                      int z_resolution, int post_steps, int max_steps, int *status, int *samples,
                      int *flags)
{
    real h = (far - near) / (real)z_resolution;
    for (int i = 0; i <= z_resolution; ++i) {
        real t = near + (real)i * h;
        if (julia_inside(o + t * d, jp)) {
            *samples = i + 1;
            *status = STATUS_HIT;
#ifdef POST_STEP
            if (i > 0)        /* a hit at the first sample has no outside sample to bracket it */
                return post_step(o, d, t, h, post_steps, jp);
#endif
            return t;
        }
    }
    *samples = z_resolution + 1;
    *status = STATUS_MISS;
    return INFINITY;
}
