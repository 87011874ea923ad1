/* normals/gradient.cl: central-difference gradient of the distance estimate
 * (Hart, Sandin & Kauffman 1989 §4.1.2, eq. 15, the 6-point gradient; Quilez (n.d.) "method 1"), taken
 * along the camera's right, up and forward axes so the result is already the
 * normal of the 3D section the rays see.  It differences the estimate formula
 * without the "0 inside" clamp, which is continuous across the surface. */

inline real de_field(real4 p, julia_params jp)
{
    int escaped;
    return julia_distance_formula(p, jp, &escaped);
}

inline real4 normal_gradient(real4 p, julia_params jp, real h, real4 right, real4 up, real4 forward)
{
    return (real4)(de_field(p + h * right, jp) - de_field(p - h * right, jp),
                   de_field(p + h * up, jp) - de_field(p - h * up, jp),
                   de_field(p - h * forward, jp) - de_field(p + h * forward, jp), 0);
}

/* The step is max(h, h_per_distance |p - eye|): a fixed step, or (normals.step = "pixel") a
 * pixel's footprint at the hit, Hart, Sandin & Kauffman's linear clarity (1989, §4.2;
 * pipeline/plan.py gradient_step), no finer than h. */
__kernel void normals_gradient(const int n_items, __global const real4 *point, __global const int *status,
                               const real4 c, const int max_iter, const real bailout,
                               const real h, const real h_per_distance, const real4 eye, const real4 right,
                               const real4 up, const real4 forward, __global real4 *normal, __global int *flags)
{
    size_t i = get_global_id(0);
    HITS_ONLY(i, n_items, status, normal[i] = (real4)(0));
    julia_params jp = { c, bailout * bailout, 0, max_iter };
    real4 e = point[i] - eye;
    real hi = fmax(h, h_per_distance * sqrt(DOT4(e, e)));   /* not length(): common/lanes.cl DOT3 */
    real4 n = normal_gradient(point[i], jp, hi, right, up, forward);
    real l = sqrt(DOT4(n, n));   /* not length(): common/lanes.cl DOT3 */
    /* a flat or non-finite difference: the view axis, flagged (common/codes.cl) in the pixel's
     * flags word (normals/jacobian.cl), never 0 on a hit */
    int ok = l > (real)0 && isfinite(l);
    normal[i] = ok ? n / l : (real4)(0, 0, 1, 0);
    if (!ok)
        flags[i] |= GUARD_NORMAL_FALLBACK;
}
