/* post_step.cl: post-stepping (seed 000 §7.1, eq. 11).  After a hit at t_hit found
 * with step h0 (the last sample before it missed), move half the previous distance
 * back while the current point hits and forward while it misses:
 *     d_n = d_{n-1} / 2,   p_n = p_{n-1} - d_n if p_{n-1} hits, else p_{n-1} + d_n.
 * n steps shrink the depth uncertainty from h0 to h0 / 2^n (eq. 12); the last
 * point is not classified, exactly as in the seed.  hit_test() is the march
 * method's own predicate: inside the set (fixed) or d < epsilon (de). */

inline int hit_test(real4 p, julia_params jp);

inline real post_step(real4 o, real4 d, real t_hit, real h0, int steps, julia_params jp)
{
    real t = t_hit;
    real h = h0;
    int hit = 1;
    for (int n = 1; n <= steps; ++n) {
        h *= (real)0.5;
        t = hit ? t - h : t + h;
        if (n < steps)
            hit = hit_test(o + t * d, jp);
    }
    return t;
}
