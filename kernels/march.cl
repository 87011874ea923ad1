/* march.cl: the march kernel, one ray per work-item.  The ray o + t d (|d| = 1)
 * is clipped to the bounding 4-ball |p| <= radius, which provably holds the set
 * (seed 002, seed 004: bound first, march only inside); rays that miss it do no
 * iteration.  near/far < 0 mean "the sphere's entry/exit".  flags gets the march's
 * guard flags (real.cl), 0 when none fired; bracket the width of the certified
 * bracket behind each hit's depth (refine.cl), +inf where nothing was hit. */

__kernel void march(const int n_items, __global const real4 *origins, __global const real4 *dirs,
                    const real4 c, const int max_iter, const real bailout, const real epsilon,
                    const real radius, const real near_set, const real far_set,
                    const int z_resolution, const int post_steps, const int max_steps,
                    __global real *depth, __global real4 *point,
                    __global int *status, __global int *samples, __global int *flags,
                    __global real *bracket COUNTER_ARG)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)   /* launches are padded to whole work-groups (render.launch) */
        return;
    julia_params jp = { c, bailout * bailout, epsilon, max_iter COUNTER_INIT(i) };
    real4 o = origins[i];
    real4 d = dirs[i];

    /* |o + t d|^2 = radius^2  ->  t = -b -+ sqrt(b^2 - (|o|^2 - radius^2)).  The
     * discriminant is taken as radius^2 - |o - b d|^2 (the squared distance of the
     * ray's closest approach), which is the same for |d| = 1 but does not cancel
     * catastrophically: b^2 - |o|^2 loses everything in float32 for a camera 1e4 away
     * (ulp(1e8) = 8 > radius^2), which threw near/far off by ~1 (extreme case
     * camera_far). */
    real b = dot(o, d);
    real4 perp = o - b * d;
    real disc = radius * radius - dot(perp, perp);
    int st = STATUS_MISS;
    int n = 0;
    int fl = 0;
    real t = INFINITY;
    real width = INFINITY;
    if (disc >= (real)0) {
        real s = sqrt(disc);
        real near = fmax(-b - s, (real)0);
        real far = -b + s;
        if (near_set >= (real)0) near = near_set;
        if (far_set >= (real)0) far = far_set;
        if (far >= near)
            t = march_ray(o, d, near, far, jp, z_resolution, post_steps, max_steps, &st, &n, &fl, &width);
    }
    depth[i] = t;
    point[i] = st == STATUS_HIT ? o + t * d : (real4)(NAN);
    status[i] = st;
    samples[i] = n;
    flags[i] = fl;
    bracket[i] = st == STATUS_HIT ? width : INFINITY;
}
