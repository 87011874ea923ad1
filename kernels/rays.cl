/* rays.cl: one 4D ray per pixel from the pinhole 4D camera of Odegaard & Wennergren §4.
 * The host builds the orthonormal frame (forward, right, up; right from the 4D cross
 * product with the limbo vector); pixel (x, y) looks along
 *     normalize(forward + u right + v up),  u, v in [-tan(fov/2) aspect, ..] x [.., tan(fov/2)],
 * with y = 0 at the top row.  Every ray starts at the camera position.  The march makes
 * its rays with camera_ray (nothing per pixel on the device but the outputs); the
 * generate_rays kernel writes them out for the tests and benchmarks. */

/* camera_ray_at's (u, v) of the point (x + ox, y + oy) of the image plane: the direction is
 * forward + u right + v up, normalised. */
inline void camera_uv(int x, int y, real ox, real oy, real tan_half_fov, int width, int height, real *u, real *v)
{
    real aspect = (real)width / (real)height;
    *u = ((real)2 * ((real)x + ox) / (real)width - (real)1) * tan_half_fov * aspect;
    *v = ((real)1 - (real)2 * ((real)y + oy) / (real)height) * tan_half_fov;
}

/* The direction forward + u right + v up over its length (|u|, |v| <= tan(fov / 2) aspect keep
 * the squares far from overflow), written out so that a packet's lanes (camera_dirs) make
 * each ray as one ray per work-item does, operation for operation. */
#define CAMERA_DIR(T, u, v, forward, right, up, x, y, z, w) \
    T x = forward.x + u * right.x + v * up.x, y = forward.y + u * right.y + v * up.y; \
    T z = forward.z + u * right.z + v * up.z, w = forward.w + u * right.w + v * up.w; \
    T l_ = sqrt(x * x + y * y + z * z + w * w)

inline real4 camera_dir(real u, real v, real4 forward, real4 right, real4 up)
{
    CAMERA_DIR(real, u, v, forward, right, up, x, y, z, w);
    return (real4)(x / l_, y / l_, z / l_, w / l_);
}

/* camera_dir in a packet's lanes, from each lane's (u, v) (camera_uv); one normalize a lane
 * had cost a sixth of a march whose rays all missed the ball */
inline quat camera_dirs(lreal u, lreal v, real4 forward, real4 right, real4 up)
{
    CAMERA_DIR(lreal, u, v, forward, right, up, x, y, z, w);
    return QUAT(x / l_, y / l_, z / l_, w / l_);
}

/* The ray through the point (x + ox, y + oy) of the image plane, (ox, oy) in [0, 1)^2 the
 * sample's place in the pixel (0.5, 0.5: its centre). */
inline real4 camera_ray_at(int x, int y, real ox, real oy, real4 forward, real4 right, real4 up,
                           real tan_half_fov, int width, int height)
{
    real u, v;
    camera_uv(x, y, ox, oy, tan_half_fov, width, height, &u, &v);
    return camera_dir(u, v, forward, right, up);
}

inline real4 camera_ray(int x, int y, real4 forward, real4 right, real4 up, real tan_half_fov,
                        int width, int height)
{
    return camera_ray_at(x, y, (real)0.5, (real)0.5, forward, right, up, tan_half_fov, width, height);
}

/* 24 random bits of (x, y, sample): a 32-bit integer hash (Wang's, then xorshift-multiply)
 * of the three, the same in reference.sample_offset, so a scene gives the same image. */
inline uint sample_hash(uint x, uint y, uint s)
{
    uint h = x * 73856093u ^ y * 19349663u ^ s * 83492791u;
    h = (h ^ 61u) ^ (h >> 16);
    h *= 9u;
    h ^= h >> 4;
    h *= 0x27d4eb2du;
    h ^= h >> 15;
    return h;
}

/* Stratified jitter (image.samples = n > 1): sample k of n lies in cell (k mod g, k div g) of
 * a g x g grid over the pixel (g = ceil(sqrt(n))), at a hashed place inside it; n = 1 is the
 * pixel's centre. */
inline void sample_offset(int x, int y, int k, int n, real *ox, real *oy)
{
    if (n <= 1) {
        *ox = (real)0.5;
        *oy = (real)0.5;
        return;
    }
    int g = (int)ceil(sqrt((float)n));
    uint h1 = sample_hash((uint)x, (uint)y, (uint)(2 * k));
    uint h2 = sample_hash((uint)x, (uint)y, (uint)(2 * k + 1));
    *ox = ((real)(k % g) + (real)(h1 >> 8) * (real)(1.0 / 16777216.0)) / (real)g;
    *oy = ((real)(k / g) + (real)(h2 >> 8) * (real)(1.0 / 16777216.0)) / (real)g;
}

/* The ray o + t d (|d| = 1) within the bounding 4-ball |p| <= radius: [*near, *far], near
 * clamped at the eye, each replaced by near_set / far_set where those are >= 0; returns the
 * lanes whose ray meets the ball.  |o + t d|^2 = radius^2  ->  t = -b -+ sqrt(b^2 - (|o|^2 -
 * radius^2)).  The discriminant is taken as radius^2 - |o - b d|^2 (the squared distance of
 * the ray's closest approach), which is the same for |d| = 1 but does not cancel
 * catastrophically: b^2 - |o|^2 loses everything in float32 for a camera 1e4 away
 * (ulp(1e8) = 8 > radius^2), which threw near/far off by ~1 (extreme case camera_far). */
inline lmask ball_span(quat o, quat d, real radius, real near_set, real far_set, lreal *near, lreal *far)
{
    lreal b = QDOT(o, d);
    quat perp = QRAY(o, d, -b);
    lreal disc = radius * radius - QNORM2(perp);
    lreal s = sqrt(fmax(disc, (real)0));
    *near = fmax(-b - s, (real)0);
    *far = -b + s;
    if (near_set >= (real)0) *near = (lreal)near_set;
    if (far_set >= (real)0) *far = (lreal)far_set;
    return disc >= (real)0;
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
