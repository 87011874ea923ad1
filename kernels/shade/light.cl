/* shade/light.cl: the lighting terms of each hit that need the fractal itself, on a lane type
 * (common/lanes.cl; LANES hits per work-item, like the Jacobian normals): visibility of the
 * positioned light (shadows, Hart, Sandin & Kauffman 1989 §6's self-shadowing), ambient occlusion, and the
 * value a colour map turns into colour.  Compiled only when the scene uses one of them
 * (-D SHADOW_HARD / SHADOW_SOFT, AO, COLOR_ITERATION / COLOR_TRAP / COLOR_W); output
 * terms = (light visibility, ambient factor, colour value, 0) in [0, 1] each. */

/* Visibility of the light along o + t l, t in (0, tmax], clipped to the bounding ball.
 * With a distance estimate (ALG_HAS_DE): steps of max(d, step), 0 at the first point
 * inside; soft shadows (Quilez (n.d.)'s penumbra) take min(k d / t) over the way, d the
 * estimate without its 1/2 (Koebe) factor.  Without one: samples every `step` (the
 * scan's own spacing), 0 at the first inside - hard shadows, whichever was asked for.  At most max_steps points: a ray still
 * going there keeps what it has (lit).  Lanes outside ``lit`` trace nothing and get 0: no hit, or
 * a hit facing away from the light (LIGHT_FACES below), its own shadow. */
#if defined(SHADOW_HARD) || defined(SHADOW_SOFT)
/* A packet's shadow rays between steps. */
typedef struct {
    lreal t, t1, vis;
    lmask active;
} shadow_march;

inline shadow_march shadow_start(quat o, quat l, lreal tmax, lmask lit, real radius, real step)
{
    shadow_march m;
    lreal b = QDOT(o, l);
    quat perp = QRAY(o, l, -b);
    lreal disc = radius * radius - QNORM2(perp);
    lreal s = sqrt(fmax(disc, (real)0));
    m.t = fmax(-b - s, (lreal)step);
    m.t1 = fmin(-b + s, tmax);
    m.active = lit & (disc > (real)0) & (m.t1 > m.t);
    m.vis = L_SEL((lreal)0, (lreal)1, lit);
    return m;
}

/* the ray moves on by dt; lanes whose point was in the set (in) are in shadow and stop */
inline void shadow_move(shadow_march *m, lmask in, lreal dt)
{
    m->t = m->t + dt;
    m->vis = L_SEL(m->vis, (lreal)0, in);
    m->active &= !in & (m->t < m->t1);
}

#ifdef ALG_HAS_DE
/* a step by the estimate d at t (escaped: the point's orbit escaped; else the ray is in the set) */
inline void shadow_advance(shadow_march *m, lreal d, lmask escaped, real step, real softness)
{
#ifdef SHADOW_SOFT
    m->vis = L_SEL(m->vis, fmin(m->vis, softness * (real)2 * d / m->t), m->active & escaped);
#endif
    shadow_move(m, m->active & !escaped, fmax(d, (lreal)step));
}
#endif

inline lreal shadow_ray(quat o, quat l, lreal tmax, lmask lit, julia_params jp, real radius, real step,
                        real softness, int max_steps)
{
    shadow_march m = shadow_start(o, l, tmax, lit, radius, step);
    quat away = ORBIT_AWAY(jp);
    for (int i = 0; i < max_steps && L_ANY(m.active); ++i) {
        quat x = QSEL(away, QRAY(o, l, m.t), m.active);
#ifdef ALG_HAS_DE
        lmask escaped;
        lreal d = julia_distance_formula(x, jp, &escaped);
        shadow_advance(&m, d, escaped, step, softness);
#else
        shadow_move(&m, m.active & julia_inside(x, jp), (lreal)step);
#endif
    }
    return clamp(m.vis, (real)0, (real)1);
}

#if LIGHT_PACKETS == 2 && defined(ALG_HAS_DE)
#define LIGHT_PAIRS   /* two packets' estimates side by side (iterate.cl julia_distance_formula_pair) */
#endif

#ifdef LIGHT_PAIRS
/* shadow_ray of two packets, [0] and [1], their estimates side by side (march/march.cl
 * PACKET_PAIRS): lane for lane the same steps and visibilities. */
inline void shadow_ray_pair(const quat *o, const quat *l, const lreal *tmax, const lmask *lit, julia_params jp,
                            real radius, real step, real softness, int max_steps, lreal *vis)
{
    shadow_march a = shadow_start(o[0], l[0], tmax[0], lit[0], radius, step);
    shadow_march b = shadow_start(o[1], l[1], tmax[1], lit[1], radius, step);
    quat away = ORBIT_AWAY(jp);
    for (int i = 0; i < max_steps && L_ANY(a.active | b.active); ++i) {
        lmask ea, eb;
        lreal da, db;
        julia_distance_formula_pair(QSEL(away, QRAY(o[0], l[0], a.t), a.active),
                                    QSEL(away, QRAY(o[1], l[1], b.t), b.active), jp, &ea, &eb, &da, &db);
        shadow_advance(&a, da, ea, step, softness);
        shadow_advance(&b, db, eb, step, softness);
    }
    vis[0] = clamp(a.vis, (real)0, (real)1);
    vis[1] = clamp(b.vis, (real)0, (real)1);
}
#endif
#endif

/* A hit whose normal points away from a light (n . l <= 0, l towards the light from the hit)
 * gets none of its diffuse or specular light (shade/shade.cl: both weigh by max(n . l, 0)): it
 * is its own shadow, visibility 0, and traces no shadow ray - a fifth of the default scene's
 * hits, an eighth of its shadow steps (float64 twin, 160x120). */
#define LIGHT_FACES(nw, lv) (QDOT((nw), (lv)) > (real)0)

/* 1 - strength * occlusion, occlusion = sum_i w_i max(h_i - 2 d(p + h_i n), 0) / h_i / sum w_i
 * at h_i = i dist / 5, w_i = 2^-i (Quilez (n.d.)'s ambient occlusion from the estimate; 2 d:
 * the estimate without its 1/2 factor); without an estimate, the share of the five points
 * inside the set (w_i-weighted occupancy). */
#ifdef AO
/* one sample's weighted occlusion, w max(h - 2 d, 0) / h, and the ambient factor of their sum */
inline lreal ao_sample(real w, real h, lreal d)
{
    return w * fmax((real)h - (real)2 * d, (real)0) / h;
}

inline lreal ao_value(lreal occ, real wsum, real strength)
{
    return clamp((real)1 - strength * occ / wsum, (real)0, (real)1);
}

inline lreal ambient_occlusion(quat p, quat n, julia_params jp, real dist, real strength)
{
    lreal occ = (lreal)0;
    real wsum = 0, w = 1;
    for (int i = 1; i <= 5; ++i) {
        real h = dist * (real)i / (real)5;
        quat x = QRAY(p, n, (lreal)h);
#ifdef ALG_HAS_DE
        occ += ao_sample(w, h, julia_distance(x, jp));
#else
        occ += L_SEL((lreal)0, (lreal)w, julia_inside(x, jp));
#endif
        wsum += w;
        w *= (real)0.5;
    }
    return ao_value(occ, wsum, strength);
}

#ifdef LIGHT_PAIRS
/* ambient_occlusion of two packets, their estimates side by side: the same values */
inline void ambient_occlusion_pair(const quat *p, const quat *n, julia_params jp, real dist, real strength,
                                   lreal *amb)
{
    lreal occ_a = (lreal)0, occ_b = (lreal)0;
    real wsum = 0, w = 1;
    for (int i = 1; i <= 5; ++i) {
        real h = dist * (real)i / (real)5;
        lmask ea, eb;
        lreal da, db;
        julia_distance_formula_pair(QRAY(p[0], n[0], (lreal)h), QRAY(p[1], n[1], (lreal)h), jp, &ea, &eb, &da, &db);
        occ_a += ao_sample(w, h, L_SEL((lreal)0, da, ea));   /* julia_distance: 0 inside */
        occ_b += ao_sample(w, h, L_SEL((lreal)0, db, eb));
        wsum += w;
        w *= (real)0.5;
    }
    amb[0] = ao_value(occ_a, wsum, strength);
    amb[1] = ao_value(occ_b, wsum, strength);
}
#endif
#endif

/* The colour value of a hit.  Iteration: how long the orbit of the INSIDE end of the hit's
 * bracket stays in the unit ball, smoothly: n the first index with |q_n| > 1, and
 * nu = n - 1 + ln|q_(n-1)| / (ln|q_(n-1)| - ln|q_n|) (the crossing of |q| = 1 interpolated in
 * ln|q|, so nu runs on continuously where n steps), as v = nu / max_iter, 1 where it never
 * leaves within max_iter.  (The escape count is no use on the surface: the truncated set's
 * surface is where orbits escape right after max_iter, so it is the same everywhere - measured
 * 1.00 past max_iter on 95 % of the default scene's hits - where the time spent in the unit
 * ball ranges over 0 to 7 of its 12 iterations.)  Trap: 1 - exp(-3 min_n |q_n - trap|) over
 * the outside end's orbit. */
/* The orbit a colour follows: q_0 = p under q -> f(q) + c for a Julia set; for a
 * Mandelbrot set (kind/mandelbrot.cl) the orbit of the critical point 0 with c = p, from
 * q_1 = c (so its count starts at 1). */
#ifndef KIND_ORBIT_START   /* the Julia set's, where the kind's piece names no orbit of its own */
#define KIND_ORBIT_START(p) real4 oc_ = ALG_C(jp.c); quat q = ALG_IN(p)
#define KIND_ORBIT_F(q) julia_f(q, oc_)
#define KIND_ORBIT_N0 0
#endif
#ifdef COLOR_ITERATION
inline lreal orbit_value(quat p, julia_params jp)
{
    KIND_ORBIT_START(p);
    lreal m2 = ALG_NORM2(q), prev = m2;
    lmask live = m2 <= (real)1;
    lmask n = KIND_ORBIT_N0;
    for (int k = KIND_ORBIT_N0; k < jp.max_iter && L_ANY(live); ++k) {
        prev = L_SEL(prev, m2, live);
        q = QSEL(q, KIND_ORBIT_F(q), live);
        m2 = L_SEL(m2, ALG_NORM2(q), live);
        n = L_SEL(n, n + 1, live);
        live &= m2 <= (real)1;
    }
    /* squared norms: their logs are twice the norms', the ratio the same */
    lreal lo = log(fmax(prev, (real)REAL_MIN)), hi = log(fmax(m2, (real)1));
    lreal frac = clamp(-lo / fmax(hi - lo, (real)REAL_MIN), (real)0, (real)1);
    lreal nu = L_SEL(convert_lreal(n) - (real)1 + frac, (lreal)KIND_ORBIT_N0, n == KIND_ORBIT_N0);
    lreal v = clamp(nu / (real)jp.max_iter, (real)0, (real)1);
    return L_SEL(v, (lreal)1, live);
}
#endif
#ifdef COLOR_TRAP
inline lreal orbit_value(quat p, julia_params jp, real4 trap)
{
    KIND_ORBIT_START(p);
    quat tq = QSCALE((lreal)-1, ALG_IN(QUAT_UNIFORM(trap)));
    lreal m2 = ALG_NORM2(q);
    lmask live = m2 <= jp.bailout2;
    lreal best = ALG_NORM2(QADD(q, tq));
    for (int k = KIND_ORBIT_N0; k < jp.max_iter && L_ANY(live); ++k) {
        q = QSEL(q, KIND_ORBIT_F(q), live);
        m2 = ALG_NORM2(q);
        live &= m2 <= jp.bailout2;
        best = L_SEL(best, fmin(best, ALG_NORM2(QADD(q, tq))), live);
    }
    return (real)1 - exp((real)-3 * sqrt(best));
}
#endif

#if (defined(SHADOW_HARD) || defined(SHADOW_SOFT)) && defined(LIGHT_POINT)
/* vis: the positioned light's visibility from each packet's points o (off the surface,
 * outside), a hit facing away from it its own shadow */
inline void key_light_shadows(const quat *o, const quat *p, const quat *nw, const lmask *hit, real4 light_pos,
                              julia_params jp, real radius, real step, real softness, int max_steps, lreal *vis)
{
    quat lp = QUAT_UNIFORM(light_pos);
    quat l[LIGHT_PACKETS];
    lreal dist[LIGHT_PACKETS];
    lmask facing[LIGHT_PACKETS];
    for (int b = 0; b < LIGHT_PACKETS; ++b) {
        quat lv = QADD(lp, QSCALE((lreal)-1, o[b]));
        dist[b] = QLEN(lv);
        l[b] = QSCALE((real)1 / fmax(dist[b], REAL_MIN), lv);
        facing[b] = hit[b] & LIGHT_FACES(nw[b], QADD(lp, QSCALE((lreal)-1, p[b])));
    }
#ifdef LIGHT_PAIRS
    shadow_ray_pair(o, l, dist, facing, jp, radius, step, softness, max_steps, vis);
#else
    for (int b = 0; b < LIGHT_PACKETS; ++b)
        vis[b] = shadow_ray(o[b], l[b], dist[b], facing[b], jp, radius, step, softness, max_steps);
#endif
}
#endif

#ifdef EXTRA_SHADOWS
/* ve[j]: shading.lights' visibility, the same shadow ray towards each (a distant one: along
 * its direction, out of the bounding ball) */
inline void extra_light_shadows(const quat *o, const quat *p, const quat *nw, const lmask *hit,
                                __global const real4 *lights_geo, __global const float4 *lights_rgb, real4 right,
                                real4 up, real4 forward, julia_params jp, real radius, real step, real softness,
                                int max_steps, lreal (*ve)[LIGHT_PACKETS])
{
    for (int j = 0; j < EXTRA_LIGHTS; ++j) {
        real4 g = lights_geo[j];
        quat gq = QUAT_UNIFORM(g);
        quat l[LIGHT_PACKETS];
        lreal dist[LIGHT_PACKETS];
        lmask facing[LIGHT_PACKETS];
        for (int b = 0; b < LIGHT_PACKETS; ++b) {
            quat lv, to;      /* towards the light from o, and from the hit as shade.cl takes it */
            if (lights_rgb[j].w != 0.0f) {
                lv = to = gq;
                dist[b] = (lreal)INFINITY;
            } else {
                lv = QADD(gq, QSCALE((lreal)-1, o[b]));
                to = QADD(gq, QSCALE((lreal)-1, p[b]));
                dist[b] = QLEN(lv);
            }
            l[b] = QSCALE((real)1 / fmax(QLEN(lv), REAL_MIN), lv);
            /* a light with no direction in the rays' 3D space: shade.cl lights along the
             * view instead, which every hit faces */
            lmask flat = (QDOT_UNIFORM(to, right) == (real)0) & (QDOT_UNIFORM(to, up) == (real)0) &
                         (QDOT_UNIFORM(to, forward) == (real)0);
            facing[b] = hit[b] & (LIGHT_FACES(nw[b], to) | flat);
        }
#ifdef LIGHT_PAIRS
        shadow_ray_pair(o, l, dist, facing, jp, radius, step, softness, max_steps, ve[j]);
#else
        for (int b = 0; b < LIGHT_PACKETS; ++b)
            ve[j][b] = shadow_ray(o[b], l[b], dist[b], facing[b], jp, radius, step, softness, max_steps);
#endif
    }
}
#endif

/* val: the colour map's value (shading.coloring): the bracket's inside end's smooth time in
 * the unit ball, the orbit trap, or w over [-R/2, R/2] (the visible range) */
inline void colour_values(const quat *p, const quat *pin, julia_params jp, real radius, real4 trap, lreal *val)
{
    for (int b = 0; b < LIGHT_PACKETS; ++b) {
#if defined(COLOR_ITERATION)
        val[b] = orbit_value(pin[b], jp);
#elif defined(COLOR_TRAP)
        val[b] = orbit_value(p[b], jp, trap);
#elif defined(COLOR_W)
        val[b] = clamp((real)0.5 + p[b].w / radius, (real)0, (real)1);
#endif
    }
}

#if LANES > 1
/* The hits of a work-item's packets, lane by lane: the point, its camera normal turned back
 * into 4D with the camera frame, the inside end of its bracket (point + bracket along the ray
 * from the eye), and whether it is one.  A miss or a lane past the edge takes ``away``, a
 * point whose orbit leaves the bailout ball at once, as do its occlusion points: at the
 * origin (inside many sets) its estimates ran to max_iter and held its packet's loops that long. */
inline void light_gather(const size_t (*lane_index)[LANES], int n_items, __global const real4 *point,
                         __global const real4 *normal, __global const int *status, __global const real *bracket,
                         real4 eye, real4 right, real4 up, real4 forward, real4 away, quat *p, quat *nw, quat *pin,
                         lmask *hit)
{
    for (int b = 0; b < LIGHT_PACKETS; ++b) {
        for (int k = 0; k < LANES; ++k) {
            size_t i = lane_index[b][k];
            int h = i < (size_t)n_items && status[i] == STATUS_HIT;
            real4 pk = h ? point[i] : away;
            real4 nc = h ? normal[i] : (real4)(0, 0, 1, 0);
            real4 nk = nc.x * right + nc.y * up - nc.z * forward;
            real4 ik = h ? pk + bracket[i] * normalize(pk - eye) : pk;
            SET_LANE_QUAT(pin[b], k, ik);
            SET_LANE_QUAT(p[b], k, pk);
            SET_LANE_QUAT(nw[b], k, nk);
            MASK_LANE(hit[b], k) = h ? -1 : 0;
        }
    }
}

/* Each lane's terms written to its pixel, (1, 1, 0, 0) off hits; with -D EXTRA_SHADOWS its
 * visibility of shading.lights too, (1, 1, 1, 0) off hits */
inline void light_scatter(const size_t (*lane_index)[LANES], int n_items, __global const int *status,
                          const lreal *vis, const lreal *amb, const lreal *val, __global float4 *terms
#ifdef EXTRA_SHADOWS
                          , lreal (*ve)[LIGHT_PACKETS], __global float4 *vis_extra
#endif
                          )
{
    for (int b = 0; b < LIGHT_PACKETS; ++b) {
        for (int k = 0; k < LANES; ++k) {
            size_t i = lane_index[b][k];
            if (i >= (size_t)n_items)
                continue;
            terms[i] = status[i] == STATUS_HIT
                           ? (float4)((float)LANE(vis[b], k), (float)LANE(amb[b], k),
                                      (float)LANE(val[b], k), 0.0f)
                           : (float4)(1, 1, 0, 0);
#ifdef EXTRA_SHADOWS
            vis_extra[i] = status[i] == STATUS_HIT
                           ? (float4)((float)LANE(ve[0][b], k), (float)LANE(ve[1][b], k),
                                      (float)LANE(ve[2][b], k), 0.0f)
                           : (float4)(1, 1, 1, 0);
#endif
        }
    }
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
    /* LIGHT_PACKETS blocks per work-item (common/lanes.cl): the march's, or two where only the
     * light terms pair their estimates (MARCH_UNPAIRED) */
#if LANES == 1
    size_t i0 = get_global_id(0);
#else
    size_t lane_index[LIGHT_PACKETS][LANES];   /* the march's blocks (common/lanes.cl): neighbours take like paths */
    for (int k = 0; k < LIGHT_PACKETS; ++k)
        if (!packet_lanes(get_global_id(0), k, LIGHT_PACKETS, n_items, tile_w, lane_index[k]))
            return;
#endif
    julia_params jp = { c, bailout * bailout, epsilon, max_iter };
    quat p[LIGHT_PACKETS], nw[LIGHT_PACKETS], pin[LIGHT_PACKETS];
    lmask hit[LIGHT_PACKETS];
#if LANES == 1
    HITS_ONLY(i0, n_items, status, terms[i0] = (float4)(1, 1, 0, 0));
    hit[0] = L_TRUE;
    p[0] = point[i0];
    real4 nc = normal[i0];
    nw[0] = nc.x * right + nc.y * up - nc.z * forward;
    pin[0] = p[0] + bracket[i0] * normalize(p[0] - eye);
#else
    light_gather(lane_index, n_items, point, normal, status, bracket, eye, right, up, forward,
                 (real4)((real)4 * (bailout + radius + ao_distance), 0, 0, 0), p, nw, pin, hit);
#endif
    lreal vis[LIGHT_PACKETS], amb[LIGHT_PACKETS], val[LIGHT_PACKETS];
#ifdef EXTRA_SHADOWS
    lreal ve[3][LIGHT_PACKETS];
#endif
    lmask any_hit = 0;
    for (int b = 0; b < LIGHT_PACKETS; ++b) {
        vis[b] = amb[b] = (lreal)1;
        val[b] = (lreal)0;
#ifdef EXTRA_SHADOWS
        ve[0][b] = ve[1][b] = ve[2][b] = (lreal)1;
#endif
        any_hit |= hit[b];
    }
    if (L_ANY(any_hit)) {   /* a block of misses (the background) has nothing to light */
        quat o[LIGHT_PACKETS];     /* off the surface, outside: where shadow rays and occlusion start */
        for (int b = 0; b < LIGHT_PACKETS; ++b)
            o[b] = QRAY(p[b], nw[b], (lreal)bias);
#if (defined(SHADOW_HARD) || defined(SHADOW_SOFT)) && defined(LIGHT_POINT)
        key_light_shadows(o, p, nw, hit, light_pos, jp, radius, step, softness, max_steps, vis);
#endif
#ifdef EXTRA_SHADOWS
        extra_light_shadows(o, p, nw, hit, lights_geo, lights_rgb, right, up, forward, jp, radius, step, softness,
                            max_steps, ve);
#endif
#ifdef AO
#ifdef LIGHT_PAIRS
        ambient_occlusion_pair(o, nw, jp, ao_distance, ao_strength, amb);
#else
        for (int b = 0; b < LIGHT_PACKETS; ++b)
            amb[b] = ambient_occlusion(o[b], nw[b], jp, ao_distance, ao_strength);
#endif
#endif
        colour_values(p, pin, jp, radius, trap, val);
    }
#if LANES == 1
    terms[i0] = (float4)((float)vis[0], (float)amb[0], (float)val[0], 0.0f);
#ifdef EXTRA_SHADOWS
    vis_extra[i0] = (float4)((float)ve[0][0], (float)ve[1][0], (float)ve[2][0], 0.0f);
#endif
#else
#ifdef EXTRA_SHADOWS
    light_scatter(lane_index, n_items, status, vis, amb, val, terms, ve, vis_extra);
#else
    light_scatter(lane_index, n_items, status, vis, amb, val, terms);
#endif
#endif
}
