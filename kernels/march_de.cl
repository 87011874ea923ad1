/* march_de.cl: distance-estimate marching (seed 001 §3.2, eq. 9):
 *     r_{n+1} = r_n + m max(d(r_n), epsilon),
 * a hit when d < epsilon (which adds thickness to thin dendrites, seed 001 §3.3).
 * The march starts at the bounding sphere (seed 001 §3.4 avoids bad estimates far
 * away) and is capped at max_steps estimates; a ray that runs into the cap is
 * reported as STATUS_CAPPED, never left running.
 *
 * Precision: where max(d, epsilon) is below half the spacing of t (epsilon under
 * ulp(t) / 2, or d that small just outside the surface), t + step rounds back to t
 * and the march could not advance.  The step is then raised to one ulp of t (the
 * next representable t), so the effective epsilon becomes the spacing of t - seed
 * 001 §4.2's epsilon as a function of distance, forced by the number format - and
 * the march walks ulp by ulp until d < epsilon or the point is inside (d = 0).
 * A hit reached by such a step returns t_prev, the last point outside, one ulp
 * before: no bracket is left for post-stepping to halve, and the first point inside
 * would give the normals an orbit that never escaped (its Jacobian gradient points
 * anywhere: float32 normals 52 degrees off float64's, median, at epsilon 1e-8).
 * Flagged GUARD_ULP_STEP and counted on the host. */

inline int hit_test(real4 p, julia_params jp) { return julia_distance(p, jp) < jp.epsilon; }

inline real march_ray(real4 o, real4 d, real near, real far, julia_params jp,
                      int z_resolution, int post_steps, int max_steps, int *status, int *samples,
                      int *flags)
{
    real t = near;
    real t_prev = near;
    int ulp_step = 0;               /* the last step was one ulp */
    for (int i = 0; i < max_steps; ++i) {
        if (t > far) {
            *samples = i;
            *status = STATUS_MISS;
            return INFINITY;
        }
        real dist = julia_distance(o + t * d, jp);
        if (dist < jp.epsilon) {
            *samples = i + 1;
            *status = STATUS_HIT;
            if (ulp_step)
                return t_prev;
#ifdef POST_STEP
            if (i > 0)
                return post_step(o, d, t, t - t_prev, post_steps, jp);
#endif
            return t;
        }
        t_prev = t;
        t += fmax(dist, jp.epsilon);
        ulp_step = t == t_prev;
        if (ulp_step) {             /* the step rounded away: one ulp instead (see above) */
            t = nextafter(t_prev, (real)INFINITY);
            *flags |= GUARD_ULP_STEP;
        }
    }
    *samples = max_steps;
    *status = STATUS_CAPPED;
    return INFINITY;
}
