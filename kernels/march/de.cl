/* march/de.cl: distance-estimate marching (Hart, Sandin & Kauffman 1989 §3.2, eq. 9), on a lane type
 * (common/lanes.cl):
 *     r_{n+1} = r_n + max(d(r_n), epsilon),
 * until a point is inside the truncated set (d = 0: its orbit never escaped, the
 * scene's own definition), which with the previous point - outside, since its orbit
 * escaped - is the certified bracket that march/refine.cl narrows.  The estimate falling
 * below epsilon does not end the march: it measures the distance to the limit set, not
 * to the max_iter-truncated one the picture shows, and at max_iter 20 points with d <
 * epsilon lie in front of the surface (their orbits escape at iteration 15-18); there
 * the march goes on in steps of epsilon, the smallest step, so parts of the set thinner
 * than epsilon along the ray can be stepped over (Hart, Sandin & Kauffman 1989 §3.3's thin objects).  A ray
 * that came within epsilon by the estimate but found no inside point before the far end
 * is a miss, flagged GUARD_SHELL_MISS and counted - never a hit at an outside point.
 * The march starts at the bounding sphere (Hart, Sandin & Kauffman 1989 §3.4) and is capped at max_steps
 * estimates (STATUS_CAPPED, counted).  Lanes outside ``live`` are left alone.
 *
 * Precision: where max(d, epsilon) is below half the spacing of t, t + step rounds back
 * to t; the step is then one ulp of t (the next representable t), flagged GUARD_ULP_STEP
 * and counted: the effective epsilon becomes the spacing of t (Hart, Sandin & Kauffman 1989 §4.2's epsilon
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

/* after the last step: the status, the samples' and flags' last words; returns the lanes
 * whose bracket the refinement narrows (march/refine.cl) */
inline lmask de_close(const de_march *m, lmask live, int max_steps, lmask *status, lmask *samples, lmask *flags)
{
    *samples = L_SEL(*samples, (lmask)max_steps, m->active);
    *flags |= L_SEL((lmask)0, (lmask)GUARD_SHELL_MISS, m->miss & m->shell);
    *status = L_SEL(*status, L_SEL(L_SEL((lmask)STATUS_CAPPED, (lmask)STATUS_MISS, m->miss),
                                   (lmask)STATUS_HIT, m->hit), live);
    return m->hit & !m->first;
}

/* the depth, given the refined bracket's outer end a and its width w */
inline lreal de_depth(const de_march *m, lreal a, lreal w, lreal near, lreal far, lmask live, lreal *width,
                      lreal *unresolved)
{
    lmask hit = m->hit, refined = m->hit & !m->first;
    *width = L_SEL(*width, L_SEL((lreal)0, w, refined), hit);
    lreal depth = L_SEL((lreal)INFINITY, L_SEL(m->t, a, refined), hit);
    /* the estimate is no proof for the truncated set (above): nothing in front is proven */
    *unresolved = L_SEL(*unresolved, L_SEL(far - near, depth - near, hit), live);
    return depth;
}

inline lreal march_ray(quat o, quat d, lreal near, lreal far, lmask live, julia_params jp,
                       int z_resolution, int post_steps, int max_steps, lmask *status,
                       lmask *samples, lmask *flags, lreal *width, lreal *unresolved)
{
    de_march m = de_start(near, live);
    quat away = ORBIT_AWAY(jp);
    for (int i = 0; i < max_steps && L_ANY(m.active); ++i) {
        de_leave(&m, i, far, samples);
        lmask escaped;
        lreal dist = julia_distance_formula(QSEL(away, QRAY(o, d, m.t), m.active), jp, &escaped);   /* ended: ORBIT_AWAY */
        de_advance(&m, i, dist, escaped, jp.epsilon, samples, flags);
    }
    lmask todo = de_close(&m, live, max_steps, status, samples, flags);
    lreal w;
    lreal a = refine_bracket(o, d, m.t_prev, m.t, todo, post_steps, jp, &w);
    return de_depth(&m, a, w, near, far, live, width, unresolved);
}

#ifdef PACKET_PAIRS
/* march_ray of two packets, [0] and [1], their estimates and set tests side by side
 * (iterate.cl julia_distance_formula_pair, march/refine.cl refine_bracket_pair): lane for
 * lane the same steps and results. */
inline void march_ray_pair(const quat *o, const quat *d, const lreal *near, const lreal *far, const lmask *live,
                           julia_params jp, int post_steps, int max_steps, lmask *status, lmask *samples,
                           lmask *flags, lreal *width, lreal *unresolved, lreal *depth)
{
    de_march m[2] = {de_start(near[0], live[0]), de_start(near[1], live[1])};
    quat away = ORBIT_AWAY(jp);
    for (int i = 0; i < max_steps && L_ANY(m[0].active | m[1].active); ++i) {
        de_leave(&m[0], i, far[0], &samples[0]);
        de_leave(&m[1], i, far[1], &samples[1]);
        lmask e0, e1;
        lreal d0, d1;
        julia_distance_formula_pair(QSEL(away, QRAY(o[0], d[0], m[0].t), m[0].active),
                                    QSEL(away, QRAY(o[1], d[1], m[1].t), m[1].active), jp, &e0, &e1, &d0, &d1);
        de_advance(&m[0], i, d0, e0, jp.epsilon, &samples[0], &flags[0]);
        de_advance(&m[1], i, d1, e1, jp.epsilon, &samples[1], &flags[1]);
    }
    lmask todo[2];
    lreal t_prev[2], t[2], a[2], w[2];
    for (int k = 0; k < 2; ++k) {
        todo[k] = de_close(&m[k], live[k], max_steps, &status[k], &samples[k], &flags[k]);
        t_prev[k] = m[k].t_prev;
        t[k] = m[k].t;
    }
    refine_bracket_pair(o, d, t_prev, t, todo, post_steps, jp, a, w);
    for (int k = 0; k < 2; ++k)
        depth[k] = de_depth(&m[k], a[k], w[k], near[k], far[k], live[k], &width[k], &unresolved[k]);
}
#endif
