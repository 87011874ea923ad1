/* path/environment.cl (-D ENV_MAP): shading.environment's image, an equirectangular map of
 * the scene's directions (pipeline/environment.py: its layout, +y up), looked up nearest and
 * sampled texel by texel in proportion to its light (Pharr, Jakob & Humphreys, "Physically
 * Based Rendering", 4th ed., 2023, §12.5.2).  A direction's scene coordinates are its dot
 * products with env_x, env_y, env_z (the slice's rotation of the scene axes into 4D).
 * rows: the marginal cumulative distribution of the rows (env_h + 1 values), cols: each
 * row's of its columns (env_w + 1 values a row). */

typedef struct {
    __global const float4 *image;
    __global const real *rows;
    __global const real *cols;
    int w, h;
    real4 ex, ey, ez;
} env_map;

/* the largest k in [0, n) with cdf[k] <= u (cdf[0] = 0 <= u < 1 = cdf[n]) */
inline int env_find(__global const real *cdf, int n, real u)
{
    int lo = 0, hi = n;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* the texel a 4D direction d falls in (its scene direction's), and that direction's sin(theta) */
inline int env_texel(const env_map *e, real4 d, real *sin_theta)
{
    real sx = DOT4(d, e->ex), sy = DOT4(d, e->ey), sz = DOT4(d, e->ez);
    real l = sqrt(sx * sx + sy * sy + sz * sz);
    real k = l > (real)0 ? (real)1 / l : (real)0;
    real y = clamp(sy * k, (real)-1, (real)1);
    *sin_theta = sqrt(fmax((real)1 - y * y, (real)0));
    real u = (atan2(sx * k, -sz * k) + (real)PATH_PI) * (real)(0.5 / PATH_PI);
    real v = acos(y) * (real)(1 / PATH_PI);
    int col = clamp((int)(u * (real)e->w), 0, e->w - 1);
    int row = clamp((int)(v * (real)e->h), 0, e->h - 1);
    return row * e->w + col;
}

/* the density (per steradian) of drawing direction d: the texel's probability times W H /
 * (2 pi^2 sin(theta)) */
inline real env_pdf(const env_map *e, real4 d)
{
    real st;
    int t = env_texel(e, d, &st);
    int row = t / e->w, col = t - row * e->w;
    __global const real *c = e->cols + (size_t)row * (size_t)(e->w + 1);
    real p = (e->rows[row + 1] - e->rows[row]) * (c[col + 1] - c[col]);
    return st > (real)0 ? p * (real)(e->w * e->h) / ((real)(2 * PATH_PI * PATH_PI) * st) : (real)0;
}

inline float4 env_radiance(const env_map *e, real4 d)
{
    real st;
    return e->image[env_texel(e, d, &st)];
}

/* a 4D direction drawn from the map by (u1, u2): a row by u1, a column of it by u2, a
 * uniform point of the texel from what is left of each */
inline real4 env_sample(const env_map *e, real u1, real u2)
{
    int row = env_find(e->rows, e->h, u1);
    real fr = (u1 - e->rows[row]) / fmax(e->rows[row + 1] - e->rows[row], REAL_MIN);
    __global const real *c = e->cols + (size_t)row * (size_t)(e->w + 1);
    int col = env_find(c, e->w, u2);
    real fc = (u2 - c[col]) / fmax(c[col + 1] - c[col], REAL_MIN);
    real theta = (real)PATH_PI * ((real)row + clamp(fr, (real)0, (real)1)) / (real)e->h;
    real phi = (real)(2 * PATH_PI) * ((real)col + clamp(fc, (real)0, (real)1)) / (real)e->w - (real)PATH_PI;
    real st = sin(theta);
    return st * sin(phi) * e->ex + cos(theta) * e->ey - st * cos(phi) * e->ez;
}
