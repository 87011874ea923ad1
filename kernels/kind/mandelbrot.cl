/* kind/mandelbrot.cl (-D KIND_MANDELBROT; built only for fractal.kind = "mandelbrot"): the
 * Mandelbrot set of the algebra's q -> f(q) + c, the 4D set of parameters c whose orbit of
 * the critical point 0 stays bounded (Hart, Sandin & Kauffman 1989 §2.1: "only one critical
 * point ... always 0"; Quilez 2002 ray traces these with the same
 * primitive as the Julia sets).  The point p is c (in the algebra's coordinates ALG_IN(p),
 * per lane), q_0 = 0 and q_1 = f(0) + c = c exactly, so the orbit starts there: p is inside
 * when |q_n| <= bailout for n = 1 .. max_iter (q_0 = 0 always is).  fractal.c is unused.
 * Other functions start from their critical value, q_1 = v + c (MANDEL_START below).
 *
 * Compiled after iterate.cl (its de_value, DE_GROW, JULIA_DF2): the set test, level function
 * and distance estimate below take over the names julia_inside, julia_level,
 * julia_distance_formula and julia_distance for every later piece (march, refine, gradient
 * normals, shadows); its hooks at the end give the Jacobian normals and the colourings its
 * orbit. */
/* f(q) + c with c a lane value (the point), f the algebra's own (julia_f at c = 0) */
inline quat mandel_f(quat q, quat c) { return QADD(julia_f(q, (real4)(0)), c); }

/* q_1 = v + c: v the critical or asymptotic value of f (scene.MANDELBROT_START, compiled in as
 * -D MANDEL_V_X.. in the point's coordinates: 1 for cos, cosh and sin, i for sinh); 0 for the
 * powers, exp and reciprocal, which compile nothing here. */
#ifdef MANDEL_V_X
#define MANDEL_START(c) QADD(c, ALG_IN(QUAT((lreal)MANDEL_V_X, (lreal)MANDEL_V_Y, (lreal)MANDEL_V_Z, (lreal)MANDEL_V_W)))
#else
#define MANDEL_START(c) (c)
#endif

inline lmask mandel_inside(quat p, julia_params jp)
{
    quat c = ALG_IN(p);
    quat q = MANDEL_START(c);
    lmask live = ALG_NORM2(q) <= jp.bailout2;
    int n = 1;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        q = QSEL(q, mandel_f(q, c), live);
        live = ALG_NORM2(q) <= jp.bailout2;
    }
    COUNT_ITER(jp, n - 1);
    return live;
}

/* F = |q_N|^2 / bailout^2 - 1, extrapolated past an escape as in iterate.cl julia_level */
inline lreal mandel_level(quat p, julia_params jp, lmask *inside)
{
    quat c = ALG_IN(p);
    quat q = MANDEL_START(c);
    lreal m2 = ALG_NORM2(q);
    lmask live = m2 <= jp.bailout2;
    lmask steps = 1;                /* q_1 = c: one iteration done */
    int n = 1;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        q = QSEL(q, mandel_f(q, c), live);
        m2 = ALG_NORM2(q);
        steps = L_SEL(steps, steps + 1, live);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n - 1);
    return level_value(m2, steps, jp, inside);
}

#ifdef PACKET_PAIRS
/* two packets' orbits of q -> f(q) + c from their points (the pairs below, as iterate.cl's) */
#define MANDEL_PAIR_START(pa, pb) \
    quat ca = ALG_IN(pa), cb = ALG_IN(pb); \
    quat qa = MANDEL_START(ca), qb = MANDEL_START(cb); \
    lreal m2a = ALG_NORM2(qa), m2b = ALG_NORM2(qb); \
    lmask live_a = m2a <= jp.bailout2, live_b = m2b <= jp.bailout2
#define MANDEL_PAIR_STEP() PAIR_ORBIT_STEP(mandel_f, qa, qb, ca, cb, m2a, m2b, live_a, live_b, jp.bailout2)

/* mandel_level at two packets' points in one loop (march/refine.cl refine_bracket_pair) */
inline void mandel_level_pair(quat pa, quat pb, julia_params jp, lmask *inside_a, lmask *inside_b,
                              lreal *fa, lreal *fb)
{
    MANDEL_PAIR_START(pa, pb);
    lmask steps_a = 1, steps_b = 1;   /* q_1 = c: one iteration done */
    for (int n = 1; n < jp.max_iter && L_ANY(live_a | live_b); ++n) {
        steps_a = L_SEL(steps_a, steps_a + 1, live_a);
        steps_b = L_SEL(steps_b, steps_b + 1, live_b);
        MANDEL_PAIR_STEP();
    }
    *fa = level_value(m2a, steps_a, jp, inside_a);
    *fb = level_value(m2b, steps_b, jp, inside_b);
}
#define julia_level_pair mandel_level_pair

/* mandel_inside at two packets' points in one loop (march/refine.cl's bisection in pairs) */
inline void mandel_inside_pair(quat pa, quat pb, julia_params jp, lmask *inside_a, lmask *inside_b)
{
    MANDEL_PAIR_START(pa, pb);
    for (int n = 1; n < jp.max_iter && L_ANY(live_a | live_b); ++n)
        MANDEL_PAIR_STEP();
    *inside_a = live_a;
    *inside_b = live_b;
}
#define julia_inside_pair mandel_inside_pair
#endif

#ifdef ALG_HAS_DE
/* The distance estimate of Hart, Sandin & Kauffman 1989 §3.1 eq. 8, d = |q_n| ln|q_n| / (2 |q_n'|), with the
 * derivative taken with respect to c:  q'_1 = 1,  q'_{n+1} = f'(q_n) q'_n + 1.  Its norm is
 * carried as the bound |q'_{n+1}| <= |f'(q_n)| |q'_n| + 1 (|f'(q)| = sqrt(JULIA_DF2(|q|^2)),
 * the operator norm of q h + h q is at most 2 |q|): a larger |q'|, a smaller - safer - d.
 * dr = |q'| is kept as mantissa * 2^e (DE_GROW), so the + 1 is added as 2^-e. */
#define MANDEL_GROW(dr, e, factor, live) do { \
        DE_GROW(dr, e, factor, live); \
        dr = L_SEL(dr, dr + ldexp((lreal)1, L_INT(-(e))), live); \
    } while (0)

#ifndef ALG_SPLIT
inline lreal mandel_distance_formula(quat p, julia_params jp, lmask *escaped)
{
    quat c = ALG_IN(p);
    quat q = MANDEL_START(c);
    lreal m2 = ALG_NORM2(q);
    lreal dr = (lreal)1;
    lmask e = 0;                    /* dr is really dr * 2^e */
    lmask live = m2 <= jp.bailout2;
    int n = 1;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        MANDEL_GROW(dr, e, sqrt(JULIA_DF2(m2)), live);
        q = QSEL(q, mandel_f(q, c), live);
        m2 = ALG_NORM2(q);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n - 1);
    *escaped = m2 > jp.bailout2;
    return de_value(m2, dr * dr, e + e);
}

#ifdef PACKET_PAIRS
/* mandel_distance_formula at two packets' points in one loop (march/de.cl march_ray_pair) */
inline void mandel_distance_formula_pair(quat pa, quat pb, julia_params jp, lmask *escaped_a, lmask *escaped_b,
                                         lreal *da, lreal *db)
{
    MANDEL_PAIR_START(pa, pb);
    lreal dra = (lreal)1, drb = (lreal)1;
    lmask ea = 0, eb = 0;
    for (int n = 1; n < jp.max_iter && L_ANY(live_a | live_b); ++n) {
        MANDEL_GROW(dra, ea, sqrt(JULIA_DF2(m2a)), live_a);
        MANDEL_GROW(drb, eb, sqrt(JULIA_DF2(m2b)), live_b);
        MANDEL_PAIR_STEP();
    }
    *escaped_a = m2a > jp.bailout2;
    *escaped_b = m2b > jp.bailout2;
    *da = de_value(m2a, dra * dra, ea + ea);
    *db = de_value(m2b, drb * drb, eb + eb);
}
#endif
#else
/* The split algebra (algebra/hypercomplex.cl): c = c_a e1 + c_b e2 and the set is the product
 * M_a x M_b of two complex Mandelbrot sets, so, as for its Julia sets (iterate.cl),
 * d = sqrt(d_a^2 + d_b^2) / sqrt(2), each d_a the complex estimate above where the component
 * has provably escaped (|a_n| > 1 + |c_a|), else 0. */
/* the estimate from the orbit's end q, c and the components' derivative bounds da * 2^ea, db * 2^eb */
inline lreal mandel_split_value(quat q, quat c, lreal da, lmask ea, lreal db, lmask eb)
{
    lreal ma = q.x * q.x + q.y * q.y, mb = q.z * q.z + q.w * q.w;
    lreal ra = (real)1 + hypot(c.x, c.y), rb = (real)1 + hypot(c.z, c.w);
    lreal d_a = L_SEL((lreal)0, de_value(ma, da * da, ea + ea), ma > ra * ra);
    lreal d_b = L_SEL((lreal)0, de_value(mb, db * db, eb + eb), mb > rb * rb);
    return sqrt(d_a * d_a + d_b * d_b) * (real)0.70710678118654752;
}

inline lreal mandel_distance_formula(quat p, julia_params jp, lmask *escaped)
{
    quat c = ALG_IN(p);
    quat q = MANDEL_START(c);
    lreal m2 = ALG_NORM2(q);
    lreal da = (lreal)1, db = (lreal)1;
    lmask ea = 0, eb = 0;
    lmask live = m2 <= jp.bailout2;
    int n = 1;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        MANDEL_GROW(da, ea, sqrt(JULIA_DF2(q.x * q.x + q.y * q.y)), live);
        MANDEL_GROW(db, eb, sqrt(JULIA_DF2(q.z * q.z + q.w * q.w)), live);
        q = QSEL(q, mandel_f(q, c), live);
        m2 = ALG_NORM2(q);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n - 1);
    *escaped = m2 > jp.bailout2;
    return mandel_split_value(q, c, da, ea, db, eb);
}

#ifdef PACKET_PAIRS
/* mandel_distance_formula at two packets' points in one loop (march/de.cl march_ray_pair) */
inline void mandel_distance_formula_pair(quat pa, quat pb, julia_params jp, lmask *escaped_a, lmask *escaped_b,
                                         lreal *dpa, lreal *dpb)
{
    MANDEL_PAIR_START(pa, pb);
    lreal a0 = (lreal)1, b0 = (lreal)1, a1 = (lreal)1, b1 = (lreal)1;
    lmask ea0 = 0, eb0 = 0, ea1 = 0, eb1 = 0;
    for (int n = 1; n < jp.max_iter && L_ANY(live_a | live_b); ++n) {
        MANDEL_GROW(a0, ea0, sqrt(JULIA_DF2(qa.x * qa.x + qa.y * qa.y)), live_a);
        MANDEL_GROW(b0, eb0, sqrt(JULIA_DF2(qa.z * qa.z + qa.w * qa.w)), live_a);
        MANDEL_GROW(a1, ea1, sqrt(JULIA_DF2(qb.x * qb.x + qb.y * qb.y)), live_b);
        MANDEL_GROW(b1, eb1, sqrt(JULIA_DF2(qb.z * qb.z + qb.w * qb.w)), live_b);
        MANDEL_PAIR_STEP();
    }
    *escaped_a = m2a > jp.bailout2;
    *escaped_b = m2b > jp.bailout2;
    *dpa = mandel_split_value(qa, ca, a0, ea0, b0, eb0);
    *dpb = mandel_split_value(qb, cb, a1, ea1, b1, eb1);
}
#endif
#endif

inline lreal mandel_distance(quat p, julia_params jp)
{
    lmask escaped;
    lreal d = mandel_distance_formula(p, jp, &escaped);
    return L_SEL((lreal)0, d, escaped);
}
#define julia_distance_formula mandel_distance_formula
#define julia_distance mandel_distance
#ifdef PACKET_PAIRS
#define julia_distance_formula_pair mandel_distance_formula_pair
#endif
#endif  /* ALG_HAS_DE */

#define julia_inside mandel_inside
#define julia_level mandel_level

/* The kind's hooks for the pieces after it, which take the Julia set's own where a kind names
 * none.  The orbit a colour follows (shade/light.cl): that of v with c = p, from q_1 = v + c,
 * so its count starts at 1. */
#define KIND_ORBIT_START(p) quat oc_ = ALG_IN(p); quat q = MANDEL_START(oc_)
#define KIND_ORBIT_F(q) mandel_f(q, oc_)
#define KIND_ORBIT_N0 1

/* The Jacobian normal's (normals/jacobian.cl): the point is c, so q_1 = v + c, J_1 = dq_1/dp =
 * ALG_IN, and J_{n+1} = f'(q_n) J_n + ALG_IN, carried as J / s (s: the rescalings): the added
 * identity is kept at J's scale, unit = 1 / s; e0..e2 are each direction's added ALG_IN v. */
#define KIND_JVP_START(q, j0, j1, j2) \
    quat c = q; \
    q = MANDEL_START(c); \
    quat e0 = j0, e1 = j1, e2 = j2; \
    lreal unit = (lreal)1
#define KIND_JVP_FIRST 1
#define KIND_JVP_STEP(q, j0, j1, j2, live) do { \
        j0 = QSEL(j0, QADD(j0, QSCALE(unit, e0)), live); \
        j1 = QSEL(j1, QADD(j1, QSCALE(unit, e1)), live); \
        j2 = QSEL(j2, QADD(j2, QSCALE(unit, e2)), live); \
        q = QSEL(q, mandel_f(q, c), live); \
    } while (0)
#define KIND_JVP_RESCALE(inv, rescale) unit = L_SEL(unit, unit * (inv), rescale);   /* its own ';' */

