/* rays.cl: one 4D ray per pixel from the pinhole 4D camera of seed 000 §4.
 * The host builds the orthonormal frame (forward, right, up; right from the 4D cross
 * product with the limbo vector); pixel (x, y) looks along
 *     normalize(forward + u right + v up),  u, v in [-tan(fov/2) aspect, ..] x [.., tan(fov/2)],
 * with y = 0 at the top row.  Every ray starts at the camera position.  The march makes
 * its rays with camera_ray (nothing per pixel on the device but the outputs); the
 * generate_rays kernel writes them out for the tests and benchmarks. */

inline real4 camera_ray(int x, int y, real4 forward, real4 right, real4 up, real tan_half_fov,
                        int width, int height)
{
    real aspect = (real)width / (real)height;
    real u = ((real)2 * ((real)x + (real)0.5) / (real)width - (real)1) * tan_half_fov * aspect;
    real v = ((real)1 - (real)2 * ((real)y + (real)0.5) / (real)height) * tan_half_fov;
    return normalize(forward + u * right + v * up);
}

__kernel void generate_rays(const int n_items, const real4 position, const real4 forward, const real4 right,
                            const real4 up, const real tan_half_fov, const int width,
                            const int height, const int x0, const int y0, const int tile_w,
                            __global real4 *origins, __global real4 *dirs)
{
    /* one tile of tile_w x (n_items / tile_w) pixels whose top-left pixel is (x0, y0) */
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    int x = x0 + (int)(i % (size_t)tile_w);
    int y = y0 + (int)(i / (size_t)tile_w);
    origins[i] = position;
    dirs[i] = camera_ray(x, y, forward, right, up, tan_half_fov, width, height);
}
