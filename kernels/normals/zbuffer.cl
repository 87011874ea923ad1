/* normals/zbuffer.cl: normals from Z-buffer neighbours (Odegaard & Wennergren §5.1, eqs. 7-9;
 * Hart, Sandin & Kauffman 1989 §4.1.1, eqs. 12-14): the normal of the plane through the hit point and
 * its neighbours' hit points, in camera coordinates (so perspective is handled).
 * Along each image axis: the central difference of Odegaard & Wennergren when both neighbours
 * hit with depth jumps within a factor 2 of each other; at a depth discontinuity
 * the one-sided difference with the smaller jump (Hart, Sandin & Kauffman 1989), so silhouettes do not
 * tilt the normal; with no neighbour hit, the image axis itself. */

inline real3 cam_point(__global const real4 *point, size_t i, real4 eye,
                       real4 right, real4 up, real4 forward)
{
    real4 v = point[i] - eye;
    return (real3)(DOT4(v, right), DOT4(v, up), -DOT4(v, forward));   /* common/lanes.cl DOT3 */
}

/* Tangent along one image axis from neighbours a (step -1) and b (step +1),
 * returned as the +1 direction. */
inline real3 zb_tangent(__global const real4 *point, __global const real *depth,
                        __global const int *status, size_t i, size_t ia, size_t ib,
                        int has_a, int has_b, real3 p, real3 axis,
                        real4 eye, real4 right, real4 up, real4 forward)
{
    int ok_a = has_a && status[ia] == STATUS_HIT;
    int ok_b = has_b && status[ib] == STATUS_HIT;
    if (ok_a && ok_b) {
        real da = fabs(depth[ia] - depth[i]), db = fabs(depth[ib] - depth[i]);
        if (fmax(da, db) <= (real)2 * fmin(da, db))
            return (real)0.5 * (cam_point(point, ib, eye, right, up, forward) -
                                cam_point(point, ia, eye, right, up, forward));
        if (da < db)
            ok_b = 0;
        else
            ok_a = 0;
    }
    if (ok_b)
        return cam_point(point, ib, eye, right, up, forward) - p;
    if (ok_a)
        return p - cam_point(point, ia, eye, right, up, forward);
    return axis;
}

__kernel void normals_zbuffer(const int n_items, __global const real4 *point, __global const real *depth,
                              __global const int *status, const int width, const int height,
                              const real4 eye, const real4 right, const real4 up,
                              const real4 forward, __global real4 *normal, __global int *flags)
{
    size_t i = get_global_id(0);
    HITS_ONLY(i, n_items, status, normal[i] = (real4)(0));
    int x = (int)(i % (size_t)width);
    int y = (int)(i / (size_t)width);
    real3 p = cam_point(point, i, eye, right, up, forward);
    /* +x is right; +y in the image is down, so "up" is row y - 1 */
    real3 tx = zb_tangent(point, depth, status, i, i - 1, i + 1, x > 0, x < width - 1, p,
                          (real3)(1, 0, 0), eye, right, up, forward);
    real3 ty = zb_tangent(point, depth, status, i, i + width, i - width, y < height - 1, y > 0, p,
                          (real3)(0, 1, 0), eye, right, up, forward);
    real3 n = (real3)(tx.y * ty.z - tx.z * ty.y, tx.z * ty.x - tx.x * ty.z, tx.x * ty.y - tx.y * ty.x);   /* tx x ty */
    real3 view = -p;                          /* towards the eye */
    if (DOT3(n, view) < (real)0)
        n = -n;
    real l = sqrt(DOT3(n, n));
    int guard = 0;
    if (!(l > (real)0) || !isfinite(l)) {
        /* degenerate plane: face the eye; if the hit is the eye itself (camera inside the
         * set, depth 0) the view axis.  Flagged either way (common/codes.cl). */
        guard = GUARD_NORMAL_FALLBACK;
        n = view, l = sqrt(DOT3(view, view));
        if (!(l > (real)0) || !isfinite(l))
            n = (real3)(0, 0, 1), l = 1;
    }
    normal[i] = (real4)(n / l, 0);
    if (guard)
        flags[i] |= guard;   /* the pixel's flags word (normals/jacobian.cl) */
}
