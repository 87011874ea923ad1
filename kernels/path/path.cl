/* path/path.cl (-D PATH): the path tracer's stages between the marches, one ray per
 * work-item (shading.integrator = "path").  Each sample of each pixel of a tile is a path
 * of at most BOUNCES hits (Kajiya, "The Rendering Equation", 1986, §7: one path per sample):
 *
 * A launch holds ``n_items`` = n_pix x k work-items: k samples of each of the tile's n_pix
 * pixels (item i: pixel i % n_pix, sample ``sample`` + i / n_pix), so that a small tile
 * still fills the device and pays each launch's fixed cost once for k samples.
 *
 *   path_camera  the camera ray through a random point of the pixel and of the lens (a thin
 *                lens of radius ``aperture`` focused at ``focus`` along the view axis; 0:
 *                a pinhole), or none where the pixel already meets the noise target;
 *   (march)      march/march.cl with -D RAYS_FROM_BUFFERS, the render's own march;
 *   (normals)    the render's normals, the Jacobian's where the Z-buffer's were asked for;
 *   path_bounce  at a miss the environment (the background for a camera ray); at a hit one
 *                light's sample (next-event estimation: the key light, shading.lights or
 *                the sky, chosen by what each can give the point: light_weight) waiting on
 *                its shadow ray, and the next ray
 *                drawn from the material (path/sample.cl), Russian roulette from the third
 *                hit on (Arvo & Kirk, "Particle Transport and Image Synthesis", 1990, §4);
 *   (march)      the shadow rays, the same march;
 *   path_shadow  a light's sample counts where its shadow ray reached it;
 *   path_film    each pixel's mean and its squared deviations, sample by sample in order
 *                (Welford, 1962), from which the stated noise comes; one item a pixel.
 *
 * Light: shading.light and each of shading.lights gives a white matte surface facing it
 * its colour (a point light without falloff, or a distant one: irradiance pi color); the
 * sky is an environment of radiance ambient * sky (times shading.environment's image), drawn
 * cosine-weighted about the normal (uniform) or by the image's light, and joined with the
 * material's samples by the power heuristic.  A path holds
 * thru = (throughput, the weight the sky gets where its next ray escapes) and rad =
 * (radiance, coverage); rad.w = -1 marks a pixel that takes no sample (path_film skips it). */

#ifdef EXTRA_LIGHTS
#define EXTRA_LIGHT_COUNT EXTRA_LIGHTS
#else
#define EXTRA_LIGHT_COUNT 0
#endif
/* The sky: uniform (radiance sky, drawn cosine-weighted about the normal), or with -D ENV_MAP
 * shading.environment's image (path/environment.cl) times sky, drawn by its light. */
#ifdef ENV_MAP
#define ENV_PARAMS , __global const float4 *env, __global const real *env_rows, __global const real *env_cols, \
                   const int env_w, const int env_h, const real4 env_x, const real4 env_y, const real4 env_z
#define ENV_INIT env_map em = { env, env_rows, env_cols, env_w, env_h, env_x, env_y, env_z }
#define SKY_RADIANCE(d4) (sky * env_radiance(&em, (d4)))
#define SKY_PDF(n, d3) env_pdf(&em, to_world((d3), right, up, forward))
#define SKY_SAMPLE(n, u1, u2) path_unit(to_cam(env_sample(&em, (u1), (u2)), right, up, forward))
#else
#define ENV_PARAMS
#define ENV_INIT
#define SKY_RADIANCE(d4) (sky)
#define SKY_PDF(n, d3) (fmax(DOT3((n), (d3)), (real)0) * (real)(1 / PATH_PI))
#define SKY_SAMPLE(n, u1, u2) path_cosine((n), (u1), (u2))
#endif
#define PATH_FAR(radius) ((real4)(4 * (radius), 0, 0, 0))   /* a ray the march finds outside the ball */
/* the random dimensions of a hit, in Sobol' pairs (path/sample.cl): (0, 1) the light's or the
 * sky's direction, 2 which light, 3 which lobe, (4, 5) the next direction, 6 the roulette */
#define DIM(bounce, k) (4u + 8u * (uint)(bounce) + (uint)(k))

inline pvec to_cam(real4 a, real4 right, real4 up, real4 forward)
{
    return PVEC(DOT4(a, right), DOT4(a, up), -DOT4(a, forward));
}

inline real4 to_world(pvec a, real4 right, real4 up, real4 forward)
{
    return a.x * right + a.y * up - a.z * forward;
}

/* the pixel (0 .. n_pix - 1) and the sample of launch item i */
inline size_t item_pixel(size_t i, int n_pix)
{
    return i % (size_t)n_pix;
}

inline uint item_sample(size_t i, int n_pix, int sample)
{
    return (uint)sample + (uint)(i / (size_t)n_pix);
}

inline uint pixel_key(size_t i, int tile_w, int x0, int y0, int image_w)
{
    int px = x0 + (int)(i % (size_t)tile_w), py = y0 + (int)(i / (size_t)tile_w);
    return (uint)py * (uint)image_w + (uint)px;
}

inline float film_lum(float4 c)
{
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

/* standard error of a pixel's mean luminance after n samples (m2: squared deviations) */
inline float film_error(float m2, int n)
{
    return n > 1 ? sqrt(fmax(m2, 0.0f) / ((float)n * (float)(n - 1))) : INFINITY;
}

__kernel void path_camera(const int n_items, const int n_pix, const int tile_w, const int x0, const int y0, const real4 eye,
                          const real4 forward, const real4 right, const real4 up, const real tan_half_fov,
                          const int image_w, const int image_h, const real aperture, const real focus,
                          const real radius, const int sample, const float noise, const int min_samples,
                          __global const float4 *film_m2, __global const int *film_count,
                          __global real4 *origins, __global real4 *dirs, __global float4 *thru,
                          __global float4 *rad)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    size_t ip = item_pixel(i, n_pix);
    uint s = item_sample(i, n_pix, sample);
    /* the noise target, from the film before this launch: the same launches on any tiling */
    int n = film_count[ip];
    if (noise > 0.0f && n >= min_samples && film_error(film_m2[ip].w, n) <= noise) {
        origins[i] = PATH_FAR(radius);
        dirs[i] = (real4)(1, 0, 0, 0);
        thru[i] = (float4)(0.0f);
        rad[i] = (float4)(0.0f, 0.0f, 0.0f, -1.0f);
        return;
    }
    uint key = pixel_key(ip, tile_w, x0, y0, image_w);
    int px = x0 + (int)(ip % (size_t)tile_w), py = y0 + (int)(ip / (size_t)tile_w);
    real u, v;
    real2 jit = path_rand2(key, s, 0u);
    camera_uv(px, py, jit.x, jit.y, tan_half_fov, image_w, image_h, &u, &v);
    real4 d = camera_dir(u, v, forward, right, up);
    real4 o = eye;
    if (aperture > (real)0) {
        /* the thin lens: every ray through the pixel's point of the focal plane */
        real2 ul = path_rand2(key, s, 2u);
        real2 l = aperture * path_disc(ul.x, ul.y);
        real4 f = eye + d * (focus / DOT4(d, forward));
        o = eye + l.x * right + l.y * up;
        real4 e = f - o;
        d = e / sqrt(DOT4(e, e));
    }
    origins[i] = o;
    dirs[i] = d;
    thru[i] = (float4)(1.0f, 1.0f, 1.0f, 1.0f);
    rad[i] = (float4)(0.0f);
}

/* What a light (a position, or with lc.w != 0 a direction; size: a sphere's radius or a sun's
 * angular radius in degrees) can give a white matte surface at o facing n, the share next-event
 * estimation chooses it by: its luminance times a bound on the cosine over the cone it fills,
 * cos(theta - alpha) <= n . l + sin(alpha), clamped to [0, 1] - zero only where no direction of
 * the light is above the surface (Pharr, Jakob & Humphreys 2023, §12.6, light sampling by
 * power; here bounded per point, so a light behind the surface is never drawn). */
inline real light_weight(real4 lv, float4 lc, real size, real4 o, pvec n, real4 right, real4 up, real4 forward)
{
    real4 dv = lc.w != 0.0f ? lv : lv - o;
    real dist = sqrt(DOT4(dv, dv));
    pvec l = path_unit(to_cam(dv, right, up, forward));
    real sin_a = (real)0;
    if (size > (real)0)
        sin_a = lc.w != 0.0f ? sin(fmin(size, (real)90) * (real)(PATH_PI / 180)) : fmin(size / fmax(dist, size), (real)1);
    real lum = (real)0.2126 * lc.x + (real)0.7152 * lc.y + (real)0.0722 * lc.z;
    return lum * clamp(DOT3(n, l) + sin_a, (real)0, (real)1);
}

/* The colour of a hit: the scene's, or the colour map's entry for its colour value *val
 * (shade/light.cl orbit_value, the inside end of its bracket for the iteration value; 0 for
 * the flat colour) */
inline pvec hit_base(real4 p, real4 d, real bracket, julia_params jp, real radius, real4 trap,
                     float4 color, __global const float4 *lut, int n_lut, real *val_out)
{
    *val_out = (real)0;
#if defined(COLOR_ITERATION) || defined(COLOR_TRAP) || defined(COLOR_W)
#if defined(COLOR_ITERATION)
    real val = orbit_value(p + bracket * d, jp);
#elif defined(COLOR_TRAP)
    real val = orbit_value(p, jp, trap);
#else
    real val = clamp((real)0.5 + p.w / radius, (real)0, (real)1);
#endif
    *val_out = clamp(val, (real)0, (real)1);
    float x = clamp((float)val, 0.0f, 1.0f) * (float)(n_lut - 1);
    int k = min((int)x, n_lut - 2);
    float4 c = mix(lut[k], lut[k + 1], x - (float)k);
#else
    float4 c = color;
#endif
    return clamp(PVEC((real)c.x, (real)c.y, (real)c.z), (real)0, (real)1);
}

__kernel void path_bounce(const int n_items, const int n_pix, const int tile_w, const int x0, const int y0, const int image_w,
                          const int sample, const int bounce, const int bounces, __global const int *status,
                          __global const real4 *point, __global const real4 *normal,
                          __global const real *bracket, const real4 c, const int max_iter, const real bailout,
                          const real4 right, const real4 up, const real4 forward, const real4 light_pos,
                          const float4 light_color, const float light_radius, __global const real4 *lights_geo,
                          __global const float4 *lights_rgb, __global const float *lights_size,
                          const float4 color, const float4 background,
                          const float4 sky, const real sky_weight, const real metallic, const real alpha2, const real f0s,
                          const real emission,
                          const real bias, const real radius, const real4 trap, __global const float4 *lut,
                          const int n_lut, __global real4 *origins, __global real4 *dirs,
                          __global float4 *thru, __global float4 *rad, __global float4 *pending,
                          __global real4 *s_origins, __global real4 *s_dirs, __global float4 *albedo,
                          __global float4 *first_normal ENV_PARAMS)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    ENV_INIT;
    float4 T = thru[i];
    float4 R = rad[i];
    real4 d4 = dirs[i];
    int st = status[i];
    s_origins[i] = PATH_FAR(radius);
    s_dirs[i] = (real4)(1, 0, 0, 0);
    pending[i] = (float4)(0.0f);
    origins[i] = PATH_FAR(radius);
    dirs[i] = (real4)(1, 0, 0, 0);
    if (bounce == 0) {
        albedo[i] = (float4)(0.0f);
        first_normal[i] = (float4)(0.0f);
    }
    if (T.x + T.y + T.z <= 0.0f)
        return;
    thru[i] = (float4)(0.0f);
    if (st != STATUS_HIT) {
        if (st == STATUS_MISS) {   /* capped: unknown, nothing counted */
            if (bounce == 0)
                R.xyz += background.xyz;
            else
                R.xyz += T.xyz * SKY_RADIANCE(d4).xyz * T.w;
        }
        rad[i] = R;
        return;
    }
    if (bounce == 0)
        R.w = 1.0f;
    uint key = pixel_key(item_pixel(i, n_pix), tile_w, x0, y0, image_w);
    uint s = item_sample(i, n_pix, sample);
    julia_params jp = { c, bailout * bailout, (real)0, max_iter };
    real4 p = point[i];
    pvec v = -to_cam(d4, right, up, forward);
    pvec n = path_unit(PVEC(normal[i].x, normal[i].y, normal[i].z));
    if (DOT3(n, v) < (real)0)   /* seen from behind (a cut face, a thin part): light the side seen */
        n = -n;
    real4 n4 = to_world(n, right, up, forward);
    real val;
    pvec base = hit_base(p, d4, bracket[i], jp, radius, trap, color, lut, n_lut, &val);
    /* the surface's own light: emission x its colour x (1 - its colour value), brightest where
     * a trap's orbits pass closest */
    float4 glow = convert_float4(emission * ((real)1 - val) * base);
    R.xyz += T.xyz * glow.xyz;
    if (bounce == 0) {   /* the denoiser's guides: the first hit's colour and normal */
        albedo[i] = (float4)((float)base.x, (float)base.y, (float)base.z, 1.0f);
        first_normal[i] = (float4)((float)n.x, (float)n.y, (float)n.z, 0.0f);
    }
    real nv = fmax(DOT3(n, v), (real)1e-6);
    real ps = spec_share(base, metallic, f0s, nv);
    real4 o = p + bias * n4;
    /* next-event estimation: one light, chosen in proportion to what it can give here */
    float sky_on = sky.x + sky.y + sky.z > 0.0f ? 1.0f : 0.0f;
    int key_on = (light_color.x + light_color.y + light_color.z > 0.0f) ? 1 : 0;
    if (key_on + EXTRA_LIGHT_COUNT + (int)sky_on == 0) {   /* nothing lights the scene: a black path */
        rad[i] = R;
        return;
    }
    /* the key light is a point (light_pos: shade.light) */
    real w_key = light_weight(light_pos, (float4)(light_color.xyz, 0.0f), (real)light_radius, o, n, right, up, forward);
    real w_sky = sky_on > 0.0f ? sky_weight : (real)0;
    real w_all = w_key + w_sky;
    for (int e = 0; e < EXTRA_LIGHT_COUNT; e++)
        w_all += light_weight(lights_geo[e], lights_rgb[e], (real)lights_size[e], o, n, right, up, forward);
    /* the light j whose share of w_all holds the random number; none where no light can reach */
    real u_pick = path_rand(key, s, DIM(bounce, 2)) * w_all;
    int j = u_pick < w_key ? 0 : -1;
    real w_j = w_key, w_cum = w_key;
    for (int e = 0; e < EXTRA_LIGHT_COUNT; e++) {
        real w_e = light_weight(lights_geo[e], lights_rgb[e], (real)lights_size[e], o, n, right, up, forward);
        if (j < 0 && u_pick < w_cum + w_e) {
            j = e + 1;
            w_j = w_e;
        }
        w_cum += w_e;
    }
    if (j < 0 && w_sky > (real)0) {
        j = 1 + EXTRA_LIGHT_COUNT;
        w_j = w_sky;
    }
    real p_sky = w_all > (real)0 ? w_sky / w_all : (real)0;   /* the sky's share, for both ways to it */
    pvec l = PVEC(0, 0, 1);
    float4 le = (float4)(0.0f);
    real dist = (real)INFINITY, wl = (real)0;
    if (j < 0) {
        /* no light faces this point: nothing to draw */
    } else if (j < 1 + EXTRA_LIGHT_COUNT) {
        /* if-else, not ?: on vectors, here and below (see path_unit) */
        real4 lv = light_pos - o;
        float4 lc = (float4)(light_color.xyz, 0.0f);
        real size = (real)light_radius;
        if (j > 0) {
            lc = lights_rgb[j - 1];
            lv = lights_geo[j - 1];
            size = (real)lights_size[j - 1];
            if (lc.w == 0.0f)
                lv = lv - o;
        }
        l = path_unit(to_cam(lv, right, up, forward));
        dist = lc.w != 0.0f ? (real)INFINITY : sqrt(DOT4(lv, lv));
        if (size > (real)0) {
            /* a sphere (size: its radius) or a sun (size: its angular radius, degrees): a
             * direction drawn uniformly in the cone it fills, shadows softened by it; its
             * light spread over the cone, so that it lights as a point would (Pharr, Jakob &
             * Humphreys 2023, §12.2.2, the cone of a sphere) */
            real cmax = lc.w != 0.0f ? cos(fmin(size, (real)90) * (real)(PATH_PI / 180))
                                     : sqrt(fmax((real)1 - (size / fmax(dist, size)) * (size / fmax(dist, size)), (real)0));
            real2 uc = path_rand2(key, s, DIM(bounce, 0));
            real ct = (real)1 - uc.x * ((real)1 - cmax);
            real st = sqrt(fmax((real)1 - ct * ct, (real)0)), phi = (real)(2 * PATH_PI) * uc.y;
            l = path_unit(path_local(l, st * cos(phi), st * sin(phi), ct));
            dist = fmax(dist - size, (real)0);   /* the sphere's near side: a hit beyond it is behind the light */
        }
        le = (float)PATH_PI * (float4)(lc.xyz, 0.0f);   /* a white matte surface facing it: its colour */
        wl = (real)1;                   /* a light no bounce can hit: its sample takes it all */
    } else {
        real2 us = path_rand2(key, s, DIM(bounce, 0));
        l = SKY_SAMPLE(n, us.x, us.y);
        dist = (real)INFINITY;
        real pl = SKY_PDF(n, l);
        float4 sl = SKY_RADIANCE(to_world(l, right, up, forward));
        le = pl > (real)0 ? (float4)(sl.xyz, 0.0f) / (float)pl : (float4)(0.0f);
        /* both strategies' densities of l, the light's times its choice (p_sky) as at an
         * escape below: weights that sum to one over the two ways to the sky; at the last
         * hit no ray is drawn from the material, and the light's sample takes it all */
        wl = bounce + 1 >= bounces ? (real)1
                                   : power_weight(pl * p_sky, bsdf_eval(n, v, l, base, metallic, f0s, alpha2, ps).w);
    }
    real4 fl = bsdf_eval(n, v, l, base, metallic, f0s, alpha2, ps);
    if (j >= 0 && fl.x + fl.y + fl.z > (real)0) {
        float4 add = (float4)(T.xyz, 0.0f) * convert_float4(fl) * le * (float)(wl * w_all / w_j);
        pending[i] = (float4)(add.xyz, (float)dist);
        s_origins[i] = o;
        s_dirs[i] = to_world(l, right, up, forward);
    }
    rad[i] = R;
    if (bounce + 1 >= bounces)
        return;
    /* the next ray, from the material */
    real2 ud = path_rand2(key, s, DIM(bounce, 4));
    real u1 = ud.x, u2 = ud.y;
    pvec h = ggx_half(n, alpha2, u1, u2);
    pvec nd_spec = (real)2 * DOT3(v, h) * h - v;
    pvec nd_diff = path_cosine(n, u1, u2);
    pvec nd = path_unit(path_rand(key, s, DIM(bounce, 3)) < ps ? nd_spec : nd_diff);
    real4 fb = bsdf_eval(n, v, nd, base, metallic, f0s, alpha2, ps);
    if (!(fb.w > (real)0) || fb.x + fb.y + fb.z <= (real)0)
        return;
    float4 w = (float4)(T.xyz, 0.0f) * convert_float4(fb / fb.w);
    if (bounce >= 2) {   /* Russian roulette: go on with probability q, weighed by 1 / q */
        float q = clamp(fmax(w.x, fmax(w.y, w.z)), 0.05f, 0.95f);
        if ((float)path_rand(key, s, DIM(bounce, 6)) >= q)
            return;
        w /= q;
    }
    /* the weight the sky gets where this ray escapes: against the sky's own sample of it */
    real psky = sky_on > 0.0f ? SKY_PDF(n, nd) * p_sky : (real)0;
    thru[i] = (float4)(w.xyz, (float)power_weight(fb.w, psky));
    origins[i] = o;
    dirs[i] = to_world(nd, right, up, forward);
}

__kernel void path_shadow(const int n_items, __global const int *status, __global const real *depth,
                          __global const float4 *pending, __global float4 *rad)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    float4 q = pending[i];
    /* reached: nothing hit before the light (a step cap counts as a hit: not shown empty) */
    if (q.x + q.y + q.z > 0.0f && (status[i] == STATUS_MISS || (status[i] == STATUS_HIT && depth[i] > (real)q.w)))
        rad[i].xyz += q.xyz;
}

__kernel void path_film(const int n_items, const int batch, __global const float4 *rad,
                        __global const float4 *albedo, __global const float4 *first_normal,
                        __global float4 *film_mean, __global float4 *film_m2, __global float4 *film_albedo,
                        __global float4 *film_normal, __global int *film_count)
{
    size_t p = get_global_id(0);
    if (p >= (size_t)n_items)
        return;
    int n = film_count[p];
    float4 m = film_mean[p], q = film_m2[p], a = film_albedo[p], nr = film_normal[p];
    for (int j = 0; j < batch; j++) {   /* the pixel's samples of this launch, in order */
        size_t i = p + (size_t)j * (size_t)n_items;
        float4 x = rad[i];
        if (x.w < 0.0f)
            continue;
        n += 1;
        float4 dlt = x - m;
        float4 m1 = m + dlt / (float)n;
        float lum_old = film_lum(m), lum_new = film_lum(m1), lx = film_lum(x);
        q.xyz += dlt.xyz * (x.xyz - m1.xyz);
        q.w += (lx - lum_old) * (lx - lum_new);
        m = m1;
        a += (albedo[i] - a) / (float)n;
        nr += (first_normal[i] - nr) / (float)n;
    }
    film_mean[p] = m;
    film_m2[p] = q;
    film_albedo[p] = a;
    film_normal[p] = nr;
    film_count[p] = n;
}
