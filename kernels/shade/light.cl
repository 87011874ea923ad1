/* shade/light.cl: the lighting terms of each hit that need the fractal itself, on a lane type
 * (common/lanes.cl; LANES hits per work-item, like the Jacobian normals): visibility of the
 * positioned light (shadows, seed 001 §6's self-shadowing), ambient occlusion, and the
 * value a colour map turns into colour.  Compiled only when the scene uses one of them
 * (-D SHADOW_HARD / SHADOW_SOFT, AO, COLOR_ITERATION / COLOR_TRAP / COLOR_W); output
 * terms = (light visibility, ambient factor, colour value, 0) in [0, 1] each. */

/* Visibility of the light along o + t l, t in (0, tmax], clipped to the bounding ball.
 * With a distance estimate (ALG_HAS_DE): steps of max(d, step), 0 at the first point
 * inside; soft shadows (seed 004's penumbra) take min(k d / t) over the way, d the
 * estimate without its 1/2 (Koebe) factor.  Without one: samples every `step` (the
 * scan's own spacing), 0 at the first inside - hard shadows, whichever was asked for.  At most max_steps points: a ray still
 * going there keeps what it has (lit).  Lanes outside ``lit`` trace nothing and get 0: no hit, or
 * a hit facing away from the light (LIGHT_FACES below), its own shadow. */
#if defined(SHADOW_HARD) || defined(SHADOW_SOFT)
inline lreal shadow_ray(quat o, quat l, lreal tmax, lmask lit, julia_params jp, real radius, real step,
                        real softness, int max_steps)
{
    lreal b = QDOT(o, l);
    quat perp = QRAY(o, l, -b);
    lreal disc = radius * radius - QNORM2(perp);
    lreal s = sqrt(fmax(disc, (real)0));
    lreal t = fmax(-b - s, (lreal)step);
    lreal t1 = fmin(-b + s, tmax);
    lmask active = lit & (disc > (real)0) & (t1 > t);
    lreal vis = L_SEL((lreal)0, (lreal)1, lit);
    for (int i = 0; i < max_steps && L_ANY(active); ++i) {
        quat x = QRAY(o, l, t);
#ifdef ALG_HAS_DE
        lmask escaped;
        lreal d = julia_distance_formula(x, jp, &escaped);
        lmask in = active & !escaped;
#ifdef SHADOW_SOFT
        vis = L_SEL(vis, fmin(vis, softness * (real)2 * d / t), active & escaped);
#endif
        t = t + fmax(d, (lreal)step);
#else
        lmask in = active & julia_inside(x, jp);
        t = t + step;
#endif
        vis = L_SEL(vis, (lreal)0, in);
        active &= !in & (t < t1);
    }
    return clamp(vis, (real)0, (real)1);
}
#endif

/* A hit whose normal points away from a light (n . l <= 0, l towards the light from the hit)
 * gets none of its diffuse or specular light (shade/shade.cl: both weigh by max(n . l, 0)): it
 * is its own shadow, visibility 0, and traces no shadow ray - a fifth of the default scene's
 * hits, an eighth of its shadow steps (float64 twin, 160x120). */
#define LIGHT_FACES(nw, lv) (QDOT((nw), (lv)) > (real)0)

/* 1 - strength * occlusion, occlusion = sum_i w_i max(h_i - 2 d(p + h_i n), 0) / h_i / sum w_i
 * at h_i = i dist / 5, w_i = 2^-i (seed 004's ambient occlusion from the estimate; 2 d:
 * the estimate without its 1/2 factor); without an estimate, the share of the five points
 * inside the set (w_i-weighted occupancy). */
#ifdef AO
inline lreal ambient_occlusion(quat p, quat n, julia_params jp, real dist, real strength)
{
    lreal occ = (lreal)0;
    real wsum = 0, w = 1;
    for (int i = 1; i <= 5; ++i) {
        real h = dist * (real)i / (real)5;
        quat x = QRAY(p, n, (lreal)h);
#ifdef ALG_HAS_DE
        lreal d = julia_distance(x, jp);
        occ += w * fmax((real)h - (real)2 * d, (real)0) / h;
#else
        occ += L_SEL((lreal)0, (lreal)w, julia_inside(x, jp));
#endif
        wsum += w;
        w *= (real)0.5;
    }
    return clamp((real)1 - strength * occ / wsum, (real)0, (real)1);
}
#endif

/* The colour value of a hit.  Iteration: the smooth escape count nu = n + 1 -
 * log_D(ln|q_n|^2 / ln bailout^2) of the INSIDE end of the hit's bracket, iterated on past
 * max_iter up to 4 max_iter, as v = (nu - max_iter) / (3 max_iter), 1 where it never
 * escapes: how long the surface's orbits outlive the truncation, i.e. how close the
 * surface lies to the limit set (the outside end is no use: the truncated set's surface is
 * where orbits escape at max_iter, so its escape count is the same everywhere).  Trap:
 * 1 - exp(-3 min_n |q_n - trap|) over the outside end's orbit. */
/* The orbit a colour follows: q_0 = p under q -> f(q) + c for a Julia set; for a
 * Mandelbrot set (kind/mandelbrot.cl) the orbit of the critical point 0 with c = p, from
 * q_1 = c (so its count starts at 1). */
#ifdef KIND_MANDELBROT
#define ORBIT_START(p) quat oc_ = ALG_IN(p); quat q = MANDEL_START(oc_)
#define ORBIT_F(q) mandel_f(q, oc_)
#define ORBIT_N0 1
#else
#define ORBIT_START(p) real4 oc_ = ALG_C(jp.c); quat q = ALG_IN(p)
#define ORBIT_F(q) julia_f(q, oc_)
#define ORBIT_N0 0
#endif
#ifdef COLOR_ITERATION
inline lreal orbit_value(quat p, julia_params jp)
{
    ORBIT_START(p);
    lreal m2 = ALG_NORM2(q);
    lmask live = m2 <= jp.bailout2;
    lmask n = ORBIT_N0;
    for (int k = ORBIT_N0; k < 4 * jp.max_iter && L_ANY(live); ++k) {
        q = QSEL(q, ORBIT_F(q), live);
        m2 = L_SEL(m2, ALG_NORM2(q), live);
        n = L_SEL(n, n + 1, live);
        live &= m2 <= jp.bailout2;
    }
    lreal ratio = log(fmax(m2, jp.bailout2)) / log(fmax(jp.bailout2, (real)1.0000001));
    lreal nu = convert_lreal(n) + (real)1 - log(fmax(ratio, (real)1)) / log((real)JULIA_GROWTH);
    lreal v = clamp((nu - (real)jp.max_iter) / ((real)3 * jp.max_iter), (real)0, (real)1);
    return L_SEL(v, (lreal)1, !(m2 > jp.bailout2));
}
#endif
#ifdef COLOR_TRAP
inline lreal orbit_value(quat p, julia_params jp, real4 trap)
{
    ORBIT_START(p);
    quat tq = QSCALE((lreal)-1, ALG_IN(QUAT((lreal)trap.x, (lreal)trap.y, (lreal)trap.z, (lreal)trap.w)));
    lreal m2 = ALG_NORM2(q);
    lmask live = m2 <= jp.bailout2;
    lreal best = ALG_NORM2(QADD(q, tq));
    for (int k = ORBIT_N0; k < jp.max_iter && L_ANY(live); ++k) {
        q = QSEL(q, ORBIT_F(q), live);
        m2 = ALG_NORM2(q);
        live &= m2 <= jp.bailout2;
        best = L_SEL(best, fmin(best, ALG_NORM2(QADD(q, tq))), live);
    }
    return (real)1 - exp((real)-3 * sqrt(best));
}
#endif

/* terms[i] = (visibility, ambient factor, colour value, 0) of hit i (normal in camera
 * coordinates: right, up, towards the eye; turned back into 4D with the camera frame;
 * the inside end of the bracket is point + bracket along the ray from the eye). */
PACKET_KERNEL void light_terms(const int n_items, const int tile_w, __global const real4 *point, __global const real4 *normal,
                          __global const int *status, __global const real *bracket, const real4 eye, const real4 c, const int max_iter, const real bailout,
                          const real epsilon, const real4 right, const real4 up, const real4 forward,
                          const real4 light_pos, const real radius, const real step, const real bias,
                          const real softness, const int max_steps, const real ao_distance,
                          const real ao_strength, const real4 trap, __global const real4 *lights_geo,
                          __global const float4 *lights_rgb, __global float4 *terms,
                          __global float4 *vis_extra)
{
#if LANES == 1
    size_t i0 = get_global_id(0);
    if (i0 >= (size_t)n_items)
        return;
#else
    size_t lane_index[LANES];   /* the march's blocks (common/lanes.cl): neighbours take like paths */
    if (!block_lanes(get_global_id(0), n_items, tile_w, lane_index))
        return;
#endif
    julia_params jp = { c, bailout * bailout, epsilon, max_iter };
    quat p, nw, pin;
    lmask hit;
#if LANES == 1
    hit = status[i0] == STATUS_HIT;
    if (!hit) {
        terms[i0] = (float4)(1, 1, 0, 0);
        return;
    }
    p = point[i0];
    real4 nc = normal[i0];
    nw = nc.x * right + nc.y * up - nc.z * forward;
    pin = p + bracket[i0] * normalize(p - eye);
#else
    /* a miss or a lane past the edge takes a point whose orbit leaves the bailout ball at once,
     * as do its occlusion points: at the origin (inside many sets) its estimates ran to max_iter
     * and held its packet's loops that long */
    real4 away = (real4)((real)4 * (bailout + radius + ao_distance), 0, 0, 0);
    for (int k = 0; k < LANES; ++k) {   /* gather */
        size_t i = lane_index[k];
        int h = i < (size_t)n_items && status[i] == STATUS_HIT;
        real4 pk = h ? point[i] : away;
        real4 nc = h ? normal[i] : (real4)(0, 0, 1, 0);
        real4 nk = nc.x * right + nc.y * up - nc.z * forward;
        real4 ik = h ? pk + bracket[i] * normalize(pk - eye) : pk;
        ((real *)&pin.x)[k] = ik.x; ((real *)&pin.y)[k] = ik.y; ((real *)&pin.z)[k] = ik.z; ((real *)&pin.w)[k] = ik.w;
        ((real *)&p.x)[k] = pk.x; ((real *)&p.y)[k] = pk.y; ((real *)&p.z)[k] = pk.z; ((real *)&p.w)[k] = pk.w;
        ((real *)&nw.x)[k] = nk.x; ((real *)&nw.y)[k] = nk.y; ((real *)&nw.z)[k] = nk.z; ((real *)&nw.w)[k] = nk.w;
        ((mask_t *)&hit)[k] = h ? -1 : 0;
    }
#endif
    lreal vis = (lreal)1, amb = (lreal)1, val = (lreal)0;
#ifdef EXTRA_SHADOWS
    lreal ve[3] = {(lreal)1, (lreal)1, (lreal)1};
#endif
    if (L_ANY(hit)) {   /* a block of misses (the background) has nothing to light */
        quat o = QRAY(p, nw, (lreal)bias);   /* off the surface, outside: where shadow rays and occlusion start */
#if (defined(SHADOW_HARD) || defined(SHADOW_SOFT)) && defined(LIGHT_POINT)
        {
            quat lp = QUAT((lreal)light_pos.x, (lreal)light_pos.y, (lreal)light_pos.z, (lreal)light_pos.w);
            quat lv = QADD(lp, QSCALE((lreal)-1, o));
            lreal dist = QLEN(lv);
            quat l = QSCALE((real)1 / fmax(dist, REAL_MIN), lv);
            lmask facing = hit & LIGHT_FACES(nw, QADD(lp, QSCALE((lreal)-1, p)));
            vis = shadow_ray(o, l, dist, facing, jp, radius, step, softness, max_steps);
        }
#endif
#ifdef EXTRA_SHADOWS
        /* shading.lights: the same shadow ray towards each (a distant one: along its direction,
         * out of the bounding ball) */
        {
            for (int j = 0; j < EXTRA_LIGHTS; ++j) {
                real4 g = lights_geo[j];
                quat gq = QUAT((lreal)g.x, (lreal)g.y, (lreal)g.z, (lreal)g.w);
                quat lv, to;      /* towards the light from o, and from the hit as shade.cl takes it */
                lreal dist;
                if (lights_rgb[j].w != 0.0f) {
                    lv = to = gq;
                    dist = (lreal)INFINITY;
                } else {
                    lv = QADD(gq, QSCALE((lreal)-1, o));
                    to = QADD(gq, QSCALE((lreal)-1, p));
                    dist = QLEN(lv);
                }
                quat l = QSCALE((real)1 / fmax(QLEN(lv), REAL_MIN), lv);
                /* a light with no direction in the rays' 3D space: shade.cl lights along the
                 * view instead, which every hit faces */
                lmask flat = (QDOT_UNIFORM(to, right) == (real)0) & (QDOT_UNIFORM(to, up) == (real)0) &
                             (QDOT_UNIFORM(to, forward) == (real)0);
                lmask facing = hit & (LIGHT_FACES(nw, to) | flat);
                ve[j] = shadow_ray(o, l, dist, facing, jp, radius, step, softness, max_steps);
            }
        }
#endif
#ifdef AO
        amb = ambient_occlusion(o, nw, jp, ao_distance, ao_strength);
#endif
#if defined(COLOR_ITERATION)
        val = orbit_value(pin, jp);
#elif defined(COLOR_TRAP)
        val = orbit_value(p, jp, trap);
#elif defined(COLOR_W)
        val = clamp((real)0.5 + p.w / radius, (real)0, (real)1);   /* w over [-R/2, R/2]: the visible range */
#endif
    }
#if LANES == 1
    terms[i0] = (float4)((float)vis, (float)amb, (float)val, 0.0f);
#ifdef EXTRA_SHADOWS
    vis_extra[i0] = (float4)((float)ve[0], (float)ve[1], (float)ve[2], 0.0f);
#endif
#else
    for (int k = 0; k < LANES; ++k) {   /* scatter */
        size_t i = lane_index[k];
        if (i >= (size_t)n_items)
            continue;
        terms[i] = status[i] == STATUS_HIT
                       ? (float4)((float)((real *)&vis)[k], (float)((real *)&amb)[k], (float)((real *)&val)[k], 0.0f)
                       : (float4)(1, 1, 0, 0);
#ifdef EXTRA_SHADOWS
        vis_extra[i] = status[i] == STATUS_HIT
                       ? (float4)((float)((real *)&ve[0])[k], (float)((real *)&ve[1])[k], (float)((real *)&ve[2])[k], 0.0f)
                       : (float4)(1, 1, 1, 0);
#endif
    }
#endif
}
