/* march/de.cl: distance-estimate marching (seed 001 §3.2, eq. 9), on a lane type
 * (common/lanes.cl):
 *     r_{n+1} = r_n + max(d(r_n), epsilon),
 * until a point is inside the truncated set (d = 0: its orbit never escaped, the
 * scene's own definition), which with the previous point - outside, since its orbit
 * escaped - is the certified bracket that march/refine.cl narrows.  The estimate falling
 * below epsilon does not end the march: it measures the distance to the limit set, not
 * to the max_iter-truncated one the picture shows, and at max_iter 20 points with d <
 * epsilon lie in front of the surface (their orbits escape at iteration 15-18); there
 * the march goes on in steps of epsilon, the smallest step, so parts of the set thinner
 * than epsilon along the ray can be stepped over (seed 001 §3.3's thin objects).  A ray
 * that came within epsilon by the estimate but found no inside point before the far end
 * is a miss, flagged GUARD_SHELL_MISS and counted - never a hit at an outside point.
 * The march starts at the bounding sphere (seed 001 §3.4) and is capped at max_steps
 * estimates (STATUS_CAPPED, counted).  Lanes outside ``live`` are left alone.
 *
 * Precision: where max(d, epsilon) is below half the spacing of t, t + step rounds back
 * to t; the step is then one ulp of t (the next representable t), flagged GUARD_ULP_STEP
 * and counted: the effective epsilon becomes the spacing of t (seed 001 §4.2's epsilon
 * as a function of distance, forced by the number format), and the bracket one ulp. */

/* Over-relaxed steps (Keinert, Schaefer, Korndoerfer, Ganse and Stamminger, "Enhanced Sphere
 * Tracing", 2014): each step is DE_OVER_RELAX times the estimate; where the new point's
 * sphere and the last one's do not overlap (r + r_prev < step: the path between them is
 * not covered) the step is taken back to (2 - DE_OVER_RELAX) times the last estimate,
 * inside its sphere, and the ray goes on with plain steps.  So the spheres still cover the
 * path, as plain steps' do, and a point beyond a gap is never a hit.  1.2 took 14 % fewer
 * estimates on the default scene (float64 twin, 160x120); 1.4 and more gained nothing
 * (the fallbacks ate it). */
#define DE_OVER_RELAX ((real)1.2)

inline lreal march_ray(quat o, quat d, lreal near, lreal far, lmask live, julia_params jp,
                       int z_resolution, int post_steps, int max_steps, lmask *status,
                       lmask *samples, lmask *flags, lreal *width, lreal *unresolved)
{
    lreal t = near, t_prev = near;
    lreal omega = DE_OVER_RELAX, step = 0, r_prev = 0;
    lmask active = live, shell = 0, hit = 0, miss = 0, first = 0;
    for (int i = 0; i < max_steps && L_ANY(active); ++i) {
        lmask out = active & (t > far);
        *samples = L_SEL(*samples, (lmask)i, out);
        miss |= out;
        active &= !out;
        lmask escaped;
        lreal dist = julia_distance_formula(QRAY(o, d, t), jp, &escaped);
        lreal r = L_SEL((lreal)0, dist, escaped);
        lmask gap = active & (omega > (real)1) & (r + r_prev < step);
        lmask got = active & !escaped & !gap;
        *samples = L_SEL(*samples, (lmask)(i + 1), got);
        hit |= got;
        if (i == 0)
            first = got;
        active &= !got;
        shell |= active & !gap & (dist < jp.epsilon);
        step = L_SEL(fmax(dist, jp.epsilon) * omega, step * ((real)1 - omega), gap);
        omega = L_SEL(omega, (lreal)1, gap);
        r_prev = L_SEL(r, r_prev, gap);
        lreal next = t + step;
        lmask stall = active & (next == t);    /* the step rounded away: one ulp instead */
        if (L_ANY(stall)) {   /* rare; nextafter on a packet took 16 % of a render on Intel's runtime */
            next = L_SEL(next, nextafter(t, (lreal)INFINITY), stall);
            *flags |= L_SEL((lmask)0, (lmask)GUARD_ULP_STEP, stall);
        }
        /* the bracket's outer end stays the last point whose sphere counted */
        t_prev = L_SEL(t_prev, t, active & !gap);
        t = L_SEL(t, next, active);
    }
    *samples = L_SEL(*samples, (lmask)max_steps, active);
    *flags |= L_SEL((lmask)0, (lmask)GUARD_SHELL_MISS, miss & shell);
    *status = L_SEL(*status, L_SEL(L_SEL((lmask)STATUS_CAPPED, (lmask)STATUS_MISS, miss),
                                   (lmask)STATUS_HIT, hit), live);
    lreal w;
    lreal a = refine_bracket(o, d, t_prev, t, hit & !first, post_steps, jp, &w);
    *width = L_SEL(*width, L_SEL((lreal)0, w, hit & !first), hit);
    lreal depth = L_SEL((lreal)INFINITY, L_SEL(t, a, hit & !first), hit);
    /* the estimate is no proof for the truncated set (above): nothing in front is proven */
    *unresolved = L_SEL(*unresolved, L_SEL(far - near, depth - near, hit), live);
    return depth;
}
