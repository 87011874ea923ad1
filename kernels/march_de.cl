/* march_de.cl: distance-estimate marching (seed 001 §3.2, eq. 9),
 *     r_{n+1} = r_n + max(d(r_n), epsilon),
 * until a point is inside the truncated set (d = 0: its orbit never escaped, the
 * scene's own definition), which with the previous point - outside, since its orbit
 * escaped - is the certified bracket that refine.cl narrows.  The estimate falling
 * below epsilon does not end the march: it measures the distance to the limit set, not
 * to the max_iter-truncated one the picture shows, and at max_iter 20 points with d <
 * epsilon lie in front of the surface (their orbits escape at iteration 15-18); there
 * the march goes on in steps of epsilon, the smallest step, so parts of the set thinner
 * than epsilon along the ray can be stepped over (seed 001 §3.3's thin objects).  A ray
 * that came within epsilon by the estimate but found no inside point before the far end
 * is a miss, flagged GUARD_SHELL_MISS and counted - never a hit at an outside point.
 * The march starts at the bounding sphere (seed 001 §3.4) and is capped at max_steps
 * estimates (STATUS_CAPPED, counted).
 *
 * Precision: where max(d, epsilon) is below half the spacing of t, t + step rounds back
 * to t; the step is then one ulp of t (the next representable t), flagged GUARD_ULP_STEP
 * and counted: the effective epsilon becomes the spacing of t (seed 001 §4.2's epsilon
 * as a function of distance, forced by the number format), and the bracket one ulp. */

inline real march_ray(real4 o, real4 d, real near, real far, julia_params jp,
                      int z_resolution, int post_steps, int max_steps, int *status, int *samples,
                      int *flags, real *width)
{
    real t = near;
    real t_prev = near;
    int shell = 0;                  /* the estimate fell below epsilon somewhere on the ray */
    for (int i = 0; i < max_steps; ++i) {
        if (t > far) {
            *samples = i;
            *status = STATUS_MISS;
            if (shell)
                *flags |= GUARD_SHELL_MISS;
            return INFINITY;
        }
        int escaped;
        real dist = julia_distance_formula(o + t * d, jp, &escaped);
        if (!escaped) {
            *samples = i + 1;
            *status = STATUS_HIT;
            if (i == 0) {
                *width = (real)0;
                return t;
            }
            return refine_bracket(o, d, t_prev, t, post_steps, jp, width);
        }
        shell |= dist < jp.epsilon;
        t_prev = t;
        t += fmax(dist, jp.epsilon);
        if (t == t_prev) {          /* the step rounded away: one ulp instead (see above) */
            t = nextafter(t_prev, (real)INFINITY);
            *flags |= GUARD_ULP_STEP;
        }
    }
    *samples = max_steps;
    *status = STATUS_CAPPED;
    return INFINITY;
}
