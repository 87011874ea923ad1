/* march/fixed.cl: fixed z-resolution scan (Odegaard & Wennergren §3), on a lane type (common/lanes.cl).
 * Samples t_i = near + i (far - near) / z_resolution, i = 0 .. z_resolution; the first
 * sample inside the set ends a ray's scan, and [t_{i-1}, t_i] - the previous sample
 * verified outside, this one inside - is the certified bracket refined by march/refine.cl.
 * A hit at the first sample has no outside sample before it: the depth is near itself,
 * width 0 (the first inside point at or after near, exactly).  Lanes outside ``live``
 * (rays that miss the bounding sphere) are left alone.
 * At most z_resolution + 1 + post_steps (+2 for ITP) set tests per ray. */

inline lreal march_ray(quat o, quat d, lreal near, lreal far, lmask live, julia_params jp,
                       int z_resolution, int post_steps, int max_steps, lmask *status,
                       lmask *samples, lmask *flags, lreal *width, lreal *unresolved)
{
    lreal h = (far - near) / (real)z_resolution;
    lreal t_prev = near, t_hit = near;
    lmask active = live, found = 0, first = 0;
    for (int i = 0; i <= z_resolution && L_ANY(active); ++i) {
        lreal t = near + (real)i * h;
        lmask got = active & julia_inside(QRAY(o, d, t), jp);
        *samples = L_SEL(*samples, (lmask)(i + 1), got);
        t_hit = L_SEL(t_hit, t, got);
        if (i == 0)
            first = got;
        found |= got;
        t_prev = L_SEL(t_prev, t, active & !got);
        active &= !got;
    }
    *samples = L_SEL(*samples, (lmask)(z_resolution + 1), active);
    *status = L_SEL(*status, L_SEL((lmask)STATUS_MISS, (lmask)STATUS_HIT, found), live);
    lreal w;
    lreal a = refine_bracket(o, d, t_prev, t_hit, found & !first, post_steps, jp, &w);
    *width = L_SEL(*width, L_SEL((lreal)0, w, found & !first), found);
    lreal depth = L_SEL((lreal)INFINITY, L_SEL(t_hit, a, found & !first), found);
    /* samples prove nothing between them: all of the ray in front of the depth is unproven */
    *unresolved = L_SEL(*unresolved, L_SEL(far - near, depth - near, found), live);
    return depth;
}
