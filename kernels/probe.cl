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

/* One step of the map in the algebra's coordinates: q = ALG_IN(p), f(q) + ALG_C(c) and its
 * derivative along ALG_IN(h) (the tests hold julia_f / julia_f_jvp to the reference). */
__kernel void probe_step(const int n_items, __global const real4 *points, __global const real4 *dirs,
                         const real4 c, __global real4 *value, __global real4 *jvp)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    quat q = ALG_IN(points[i]);
    value[i] = julia_f(q, ALG_C(c));
    jvp[i] = julia_f_jvp(q, ALG_IN(dirs[i]));
}

/* The scene's complex function alone (function/<name>.cl): cfun and cfun_d at complex points
 * (re, im), for the tests of each function piece against its twin. */
__kernel void probe_cfun(const int n_items, __global const real *re, __global const real *im,
                         __global real *f_re, __global real *f_im, __global real *d_re, __global real *d_im)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
#if LANES == 1
    cplx z = C(re[i], im[i]);
    cplx f = cfun(z), d = cfun_d(z);
    f_re[i] = f.re; f_im[i] = f.im;
    d_re[i] = d.re; d_im[i] = d.im;
#endif
}

/* The enclosures' bound on the norm of h -> q h (enclose/ball.cl ALG_LBOUND) at points q =
 * ALG_IN(p), NAN where the algebra has none (the tests hold it above the product's norm). */
__kernel void probe_lbound(const int n_items, __global const real4 *points, __global real *lbound)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
#if defined(ALG_LBOUND) && LANES == 1
    lbound[i] = ALG_LBOUND(ALG_IN(points[i]));
#else
    lbound[i] = NAN;
#endif
}
