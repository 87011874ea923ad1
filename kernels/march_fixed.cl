/* march_fixed.cl: fixed z-resolution scan (seed 000 §3).  Samples
 * t_i = near + i (far - near) / z_resolution, i = 0 .. z_resolution; the first
 * sample inside the set ends the scan, and [t_{i-1}, t_i] - the previous sample
 * verified outside, this one inside - is the certified bracket refined by refine.cl.
 * A hit at the first sample has no outside sample before it: the depth is near itself,
 * width 0 (the first inside point at or after near, exactly).
 * At most z_resolution + 1 + post_steps (+2 for ITP) set tests per ray. */

inline real march_ray(real4 o, real4 d, real near, real far, julia_params jp,
                      int z_resolution, int post_steps, int max_steps, int *status, int *samples,
                      int *flags, real *width)
{
    real h = (far - near) / (real)z_resolution;
    real t_prev = near;
    for (int i = 0; i <= z_resolution; ++i) {
        real t = near + (real)i * h;
        if (julia_inside(o + t * d, jp)) {
            *samples = i + 1;
            *status = STATUS_HIT;
            if (i == 0) {
                *width = (real)0;
                return t;
            }
            return refine_bracket(o, d, t_prev, t, post_steps, jp, width);
        }
        t_prev = t;
    }
    *samples = z_resolution + 1;
    *status = STATUS_MISS;
    return INFINITY;
}
