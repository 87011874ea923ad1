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

/* A packet's march by the estimate: its state between steps. */
typedef struct {
    lreal t, t_prev, omega, step, r_prev;
    lmask active, shell, hit, miss, first;
} de_march;

inline de_march de_start(lreal near, lmask live)
{
    de_march m;
    m.t = m.t_prev = near;
    m.omega = (lreal)DE_OVER_RELAX;
    m.step = m.r_prev = (lreal)0;
    m.active = live;
    m.shell = m.hit = m.miss = m.first = (lmask)0;
    return m;
}

/* the start of step i: lanes past far are misses */
inline void de_leave(de_march *m, int i, lreal far, lmask *samples)
{
    lmask out = m->active & (m->t > far);
    *samples = L_SEL(*samples, (lmask)i, out);
    m->miss |= out;
    m->active &= !out;
}

/* step i, given the estimate dist at t (escaped: the point's orbit escaped) */
inline void de_advance(de_march *m, int i, lreal dist, lmask escaped, real epsilon, lmask *samples,
                       lmask *flags)
{
    lreal r = L_SEL((lreal)0, dist, escaped);
    lmask gap = m->active & (m->omega > (real)1) & (r + m->r_prev < m->step);
    lmask got = m->active & !escaped & !gap;
    *samples = L_SEL(*samples, (lmask)(i + 1), got);
    m->hit |= got;
    if (i == 0)
        m->first = got;
    m->active &= !got;
    m->shell |= m->active & !gap & (dist < epsilon);
    m->step = L_SEL(fmax(dist, epsilon) * m->omega, m->step * ((real)1 - m->omega), gap);
    m->omega = L_SEL(m->omega, (lreal)1, gap);
    m->r_prev = L_SEL(r, m->r_prev, gap);
    lreal next = m->t + m->step;
    lmask stall = m->active & (next == m->t);    /* the step rounded away: one ulp instead */
    if (L_ANY(stall)) {   /* rare; nextafter on a packet took 16 % of a render on Intel's runtime */
        next = L_SEL(next, nextafter(m->t, (lreal)INFINITY), stall);
        *flags |= L_SEL((lmask)0, (lmask)GUARD_ULP_STEP, stall);
    }
    /* the bracket's outer end stays the last point whose sphere counted */
    m->t_prev = L_SEL(m->t_prev, m->t, m->active & !gap);
    m->t = L_SEL(m->t, next, m->active);
}

/* after the last step: the status, the refined bracket and the depth */
inline lreal de_end(de_march *m, quat o, quat d, lreal near, lreal far, lmask live, int post_steps,
                    int max_steps, julia_params jp, lmask *status, lmask *samples, lmask *flags,
                    lreal *width, lreal *unresolved)
{
    lmask hit = m->hit, first = m->first;
    *samples = L_SEL(*samples, (lmask)max_steps, m->active);
    *flags |= L_SEL((lmask)0, (lmask)GUARD_SHELL_MISS, m->miss & m->shell);
    *status = L_SEL(*status, L_SEL(L_SEL((lmask)STATUS_CAPPED, (lmask)STATUS_MISS, m->miss),
                                   (lmask)STATUS_HIT, hit), live);
    lreal w;
    lreal a = refine_bracket(o, d, m->t_prev, m->t, hit & !first, post_steps, jp, &w);
    *width = L_SEL(*width, L_SEL((lreal)0, w, hit & !first), hit);
    lreal depth = L_SEL((lreal)INFINITY, L_SEL(m->t, a, hit & !first), hit);
    /* the estimate is no proof for the truncated set (above): nothing in front is proven */
    *unresolved = L_SEL(*unresolved, L_SEL(far - near, depth - near, hit), live);
    return depth;
}

inline lreal march_ray(quat o, quat d, lreal near, lreal far, lmask live, julia_params jp,
                       int z_resolution, int post_steps, int max_steps, lmask *status,
                       lmask *samples, lmask *flags, lreal *width, lreal *unresolved)
{
    de_march m = de_start(near, live);
    for (int i = 0; i < max_steps && L_ANY(m.active); ++i) {
        de_leave(&m, i, far, samples);
        lmask escaped;
        lreal dist = julia_distance_formula(QRAY(o, d, m.t), jp, &escaped);
        de_advance(&m, i, dist, escaped, jp.epsilon, samples, flags);
    }
    return de_end(&m, o, d, near, far, live, post_steps, max_steps, jp, status, samples, flags, width,
                  unresolved);
}

#ifdef PACKET_PAIRS
/* march_ray of two packets, [0] and [1], their estimates side by side
 * (iterate.cl julia_distance_formula_pair): lane for lane the same steps and results. */
inline void march_ray_pair(const quat *o, const quat *d, const lreal *near, const lreal *far, const lmask *live,
                           julia_params jp, int post_steps, int max_steps, lmask *status, lmask *samples,
                           lmask *flags, lreal *width, lreal *unresolved, lreal *depth)
{
    de_march a = de_start(near[0], live[0]), b = de_start(near[1], live[1]);
    for (int i = 0; i < max_steps && L_ANY(a.active | b.active); ++i) {
        de_leave(&a, i, far[0], &samples[0]);
        de_leave(&b, i, far[1], &samples[1]);
        lmask ea, eb;
        lreal da, db;
        julia_distance_formula_pair(QRAY(o[0], d[0], a.t), QRAY(o[1], d[1], b.t), jp, &ea, &eb, &da, &db);
        de_advance(&a, i, da, ea, jp.epsilon, &samples[0], &flags[0]);
        de_advance(&b, i, db, eb, jp.epsilon, &samples[1], &flags[1]);
    }
    depth[0] = de_end(&a, o[0], d[0], near[0], far[0], live[0], post_steps, max_steps, jp, &status[0],
                      &samples[0], &flags[0], &width[0], &unresolved[0]);
    depth[1] = de_end(&b, o[1], d[1], near[1], far[1], live[1], post_steps, max_steps, jp, &status[1],
                      &samples[1], &flags[1], &width[1], &unresolved[1]);
}
#endif
