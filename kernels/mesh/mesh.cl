/* mesh/mesh.cl: the scene's 3D slice of the set on a grid, and the vertices of its surface
 * (pyjulia4d/app/mesh.py; twin pyjulia4d/reference/mesh.py).  One point per work-item.
 *
 * The grid is the slice's own 3D space (x, y, z), mapped to the world as the camera's points
 * are (geometry/camera.py to_world): p = x rx + y ry + z rz + offset, rx, ry, rz the slice
 * rotation's first three columns and offset = distance n/|n|.  A grid point is inside when it
 * lies in the bounding ball |p| <= radius and in the truncated set (julia_inside: the scene's
 * own definition, every kind's).  Marching cubes on that mask puts a vertex on each grid edge
 * whose ends differ; mesh_vertices then moves it onto the surface: onto the ball's sphere where
 * the ball cuts the set, else to the crossing of the set's surface refined by refine_bracket
 * (march/refine.cl: ITP on the level function, or bisection), from a bracket [outside end,
 * inside end] that the mask certified.
 *
 * -D CLIP: up to 4 half-spaces clip_n[k] . p <= clip_off[k] (the render's clip.planes, in the
 * world) cut the set as the render cuts it.  A grid point is then inside only in all of them
 * too, and a vertex whose edge enters that convex region (ball and half-spaces) at a point of
 * the set lies on the cut face: on the plane (or sphere) it entered through, width 0.  So a
 * plane below the set cuts a flat base, and the mesh stays closed (CLIP_ARGS: common/lanes.cl). */

/* Whether p is in the ball and in every half-space (the region the set is cut to). */
inline int mesh_kept(real4 p, real radius2 CLIP_ARGS)
{
    if (dot(p, p) > radius2)
        return 0;
#ifdef CLIP
    for (int k = 0; k < n_clip; ++k) {
        if (dot(CLIP_NORMAL(k), p) > CLIP_OFFSET(k))
            return 0;
    }
#endif
    return 1;
}

/* Where the ray po + a d (d a unit vector, a in [0, len]) enters the region of mesh_kept:
 * the largest entry of the ball's sphere and of each plane the ray starts outside. */
inline real mesh_entry(real4 po, real4 d, real len, real radius2 CLIP_ARGS)
{
    real a = 0;
    if (dot(po, po) > radius2) {   /* where the edge enters the ball: |po + a d| = radius */
        real b = dot(po, d), e = dot(po, po) - radius2;
        a = -b - sqrt(fmax(b * b - e, (real)0));
    }
#ifdef CLIP
    for (int k = 0; k < n_clip; ++k) {
        real so = dot(CLIP_NORMAL(k), po) - CLIP_OFFSET(k), sd = dot(CLIP_NORMAL(k), d);
        if (so > 0 && sd < 0)
            a = fmax(a, so / -sd);
    }
#endif
    return clamp(a, (real)0, len);
}

inline real4 mesh_point(real4 origin, real spacing, real4 rx, real4 ry, real4 rz, real4 offset,
                        int i, int j, int k)
{
    real x = origin.x + spacing * (real)i, y = origin.y + spacing * (real)j, z = origin.z + spacing * (real)k;
    return x * rx + y * ry + z * rz + offset;
}

/* inside[(k - k0) ny nx + j nx + i] for the grid points (i, j, k), k0 <= k < k0 + n / (nx ny) */
__kernel void mesh_sample(const int n, const int nx, const int ny, const int k0, const real4 origin,
                          const real spacing, const real4 rx, const real4 ry, const real4 rz, const real4 offset,
                          const real radius2, const real4 c, const int max_iter, const real bailout
                          CLIP_ARGS, __global uchar *inside)
{
    size_t g = get_global_id(0);
    if (g >= (size_t)n)
        return;
    int i = (int)(g % (size_t)nx), j = (int)((g / (size_t)nx) % (size_t)ny), k = (int)(g / ((size_t)nx * ny));
    real4 p = mesh_point(origin, spacing, rx, ry, rz, offset, i, j, k0 + k);
    julia_params jp = { c, bailout * bailout, 0, max_iter };
    inside[g] = (mesh_kept(p, radius2 CLIP_PASS) && julia_inside(p, jp)) ? 1 : 0;
}

/* The vertex on the grid edge between the world points ends_a[g] and ends_b[g], one inside
 * (ball, half-spaces and set) and one outside, in either order (the mask they came from is
 * not kept: both are tested again, as mesh_sample tested them): on the sphere |p| = radius or
 * a clip plane where the edge enters that region at a point of the set, else within width[g]
 * of the set's crossing (refined with ``steps`` set tests on the part of the edge in the
 * region; the vertex is the bracket's middle).  An edge whose ends agree (none, from marching
 * cubes) gets its midpoint, width -1. */
inline int mesh_inside(real4 p, real radius2, julia_params jp CLIP_ARGS)
{
    return mesh_kept(p, radius2 CLIP_PASS) && julia_inside(p, jp);
}

__kernel void mesh_vertices(const int n, __global const real4 *ends_a, __global const real4 *ends_b,
                            const real radius2, const real4 c, const int max_iter, const real bailout
                            CLIP_ARGS, const int steps, __global real4 *vertex, __global real *width,
                            __global real4 *inside_end)
{
    size_t g = get_global_id(0);
    if (g >= (size_t)n)
        return;
    julia_params jp = { c, bailout * bailout, 0, max_iter };
    real4 pa = ends_a[g], pb = ends_b[g];
    int ia = mesh_inside(pa, radius2, jp CLIP_PASS), ib = mesh_inside(pb, radius2, jp CLIP_PASS);
    if (ia == ib) {
        vertex[g] = inside_end[g] = (real)0.5 * (pa + pb);
        width[g] = -1;
        return;
    }
    real4 po = ia ? pb : pa, d = (ia ? pa : pb) - po;
    real len = length(d);
    d /= len;
    real a = 0;
    if (!mesh_kept(po, radius2 CLIP_PASS)) {   /* the outside end is cut away: where the edge comes in */
        a = mesh_entry(po, d, len, radius2 CLIP_PASS);
        real4 pe = po + a * d;
        if (julia_inside(pe, jp)) {   /* the set reaches the cut here: the sphere's or a plane's face */
            vertex[g] = inside_end[g] = pe;
            width[g] = 0;
            return;
        }
    }
    real w;
    real t = refine_bracket(po, d, a, len, 1, steps, jp, &w);
    vertex[g] = po + (t + (real)0.5 * w) * d;
    width[g] = w;
    inside_end[g] = po + (t + w) * d;   /* verified inside: where the render's colourings start */
}
