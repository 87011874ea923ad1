/* probe.cl: exposes the per-point iteration to the tests (never built for a scene):
 * the escape test and the distance estimate on a batch of 4D points. */

__kernel void probe_iterate(const int n_items, __global const real4 *points, const real4 c, const int max_iter,
                            const real bailout, __global int *inside, __global real *distance,
                            __global real *formula)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    julia_params jp = { c, bailout * bailout, 0, max_iter };
    int escaped;
    inside[i] = julia_inside(points[i], jp);
#ifdef ALG_HAS_DE
    distance[i] = julia_distance(points[i], jp);
    formula[i] = julia_distance_formula(points[i], jp, &escaped);
#else
    distance[i] = NAN;   /* no distance estimate for this algebra and function */
    formula[i] = NAN;
#endif
}
