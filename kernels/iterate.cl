/* iterate.cl: the escape-time iteration and the distance estimate, on a lane type
 * (common/lanes.cl: one ray, or a packet of rays whose finished lanes are frozen).
 *
 * A point p is inside when |q_n| <= bailout for n = 0 .. max_iter, with q_0 = p and
 * q_{n+1} = f(q_n) + c (POV-Ray 3.6 documentation: "none of the vectors in the sequence escapes";
 * Odegaard & Wennergren §2.1, eq. 5).  The algebra piece (algebra/<name>.cl) supplies the map, the
 * iterate's coordinates (ALG_IN, ALG_C) and its norm (ALG_NORM2). */

/* Where a lane whose ray has ended (a hit: an inside point; a miss; a shadow ray in shadow)
 * takes its estimate while the rest of its packet steps on: a point whose orbit leaves the
 * bailout ball at once.  Its own point would hold the packet's orbit loop to max_iter at every
 * later step (iterating an inside point), which the lanes still stepping rarely need: at
 * max_iter 20 the march took 0.89x its time (march/de.cl, march/cone.cl, march/refine.cl,
 * shade/light.cl; not the fixed scan, whose kernel took 1.4x its time with the select). */
#define ORBIT_AWAY(jp) QUAT((lreal)((real)4 * sqrt((jp).bailout2)), (lreal)0, (lreal)0, (lreal)0)

inline lmask julia_inside(quat p, julia_params jp)
{
    quat q = ALG_IN(p);
    real4 c = ALG_C(jp.c);
    lmask live = ALG_NORM2(q) <= jp.bailout2;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        q = QSEL(q, julia_f(q, c), live);
        live = ALG_NORM2(q) <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    return live;
}

/* two packets' orbits from the points pa, pb (the pair level and estimates below): declares their
 * iterates, |q|^2 and live lanes */
#define PAIR_ORBIT_START(pa, pb, qa, qb, m2a, m2b, live_a, live_b, bailout2) \
    quat qa = ALG_IN(pa), qb = ALG_IN(pb); \
    lreal m2a = ALG_NORM2(qa), m2b = ALG_NORM2(qb); \
    lmask live_a = m2a <= (bailout2), live_b = m2b <= (bailout2)

/* two packets' orbits one step on under q -> f(q, c) where live (the pair estimates below;
 * kind/mandelbrot.cl's with its own f and a c per packet) */
#define PAIR_ORBIT_STEP(f, qa, qb, ca, cb, m2a, m2b, live_a, live_b, bailout2) do { \
        qa = QSEL(qa, f(qa, ca), live_a); \
        qb = QSEL(qb, f(qb, cb), live_b); \
        m2a = ALG_NORM2(qa); \
        m2b = ALG_NORM2(qb); \
        live_a = m2a <= (bailout2); \
        live_b = m2b <= (bailout2); \
    } while (0)

/* one step of the level function's orbit where live, counting the steps done */
#define LEVEL_ORBIT_STEP(q, m2, steps, live, c, bailout2) do { \
        q = QSEL(q, julia_f(q, c), live); \
        m2 = ALG_NORM2(q); \
        steps = L_SEL(steps, steps + 1, live); \
        live = m2 <= (bailout2); \
    } while (0)

/* F and the inside flag from the orbit's last |q|^2 and the steps it took (julia_level) */
inline lreal level_value(lreal m2, lmask steps, julia_params jp, lmask *inside)
{
    *inside = m2 <= jp.bailout2;
    lmask k = jp.max_iter - steps;
#if JULIA_GROWTH == 2
    lreal e = ldexp(log(m2 / jp.bailout2), L_INT(min(k, 60)));
#else
    lreal e = log(m2 / jp.bailout2) * pow((lreal)JULIA_GROWTH, convert_lreal(min(k, 60)));
#endif
    lreal out = L_SEL(expm1(fmin(e, (real)69)), (lreal)1e30, (k > 60) | (e > (real)69));
    return L_SEL(out, m2 / jp.bailout2 - (real)1, *inside);
}

/* The level function of the truncated set (march/refine.cl): F = |q_N|^2 / bailout^2 - 1 at
 * N = max_iter, <= 0 exactly when the point is inside (*inside, the same test as
 * julia_inside).  With bailout >= the escape radius every |q_n| > bailout stays so, so
 * the set is {F <= 0} and its surface the level set F = 0 of a polynomial in the
 * point (Quilez 2002).  An orbit that escapes at n < N is not iterated
 * on (it would overflow); |q_N|^2 is extrapolated as (|q_n|^2)^(D^(N-n)), the growth of
 * q^D for large q (D = JULIA_GROWTH; 2 for functions that are no polynomial), and capped
 * at 1e30: only the interpolation uses the value, never the inside test. */
inline lreal julia_level(quat p, julia_params jp, lmask *inside)
{
    quat q = ALG_IN(p);
    real4 c = ALG_C(jp.c);
    lreal m2 = ALG_NORM2(q);
    lmask live = m2 <= jp.bailout2;
    lmask steps = 0;                /* iterations done, per lane */
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n)
        LEVEL_ORBIT_STEP(q, m2, steps, live, c, jp.bailout2);
    COUNT_ITER(jp, n);
    return level_value(m2, steps, jp, inside);
}

#ifdef PACKET_PAIRS
/* julia_level at two packets' points in one loop (march/refine.cl refine_bracket_pair) */
inline void julia_level_pair(quat pa, quat pb, julia_params jp, lmask *inside_a, lmask *inside_b,
                             lreal *fa, lreal *fb)
{
    real4 c = ALG_C(jp.c);
    PAIR_ORBIT_START(pa, pb, qa, qb, m2a, m2b, live_a, live_b, jp.bailout2);
    lmask steps_a = 0, steps_b = 0;
    for (int n = 0; n < jp.max_iter && L_ANY(live_a | live_b); ++n) {
        LEVEL_ORBIT_STEP(qa, m2a, steps_a, live_a, c, jp.bailout2);
        LEVEL_ORBIT_STEP(qb, m2b, steps_b, live_b, c, jp.bailout2);
    }
    *fa = level_value(m2a, steps_a, jp, inside_a);
    *fb = level_value(m2b, steps_b, jp, inside_b);
}

/* julia_inside at two packets' points in one loop (march/refine.cl's bisection in pairs) */
inline void julia_inside_pair(quat pa, quat pb, julia_params jp, lmask *inside_a, lmask *inside_b)
{
    real4 c = ALG_C(jp.c);
    PAIR_ORBIT_START(pa, pb, qa, qb, m2a, m2b, live_a, live_b, jp.bailout2);
    for (int n = 0; n < jp.max_iter && L_ANY(live_a | live_b); ++n)
        PAIR_ORBIT_STEP(julia_f, qa, qb, c, c, m2a, m2b, live_a, live_b, jp.bailout2);
    *inside_a = live_a;
    *inside_b = live_b;
}
#endif

#ifdef ALG_HAS_DE
/* Distance-estimate formula d = |q_n| ln|q_n| / (2 |q_n'|)  (Hart, Sandin & Kauffman 1989 §3.1, eq. 8)
 * evaluated at the last iterate, whether or not it escaped.  The derivative is
 * carried squared, so the loop needs no sqrt: |q'_{n+1}|^2 = 4 |q_n|^2 |q'_n|^2, and
 * d = sqrt(m2 / dm2) ln(m2) / 4.  Where |q'| would overflow, it is carried as a
 * mantissa times 2^e (ldexp), so the estimate stays finite at any max_iter.
 * Sets *escaped.  This is the smooth field the gradient normal differentiates. */
/* d = |q| ln|q| / (2 |q'|) from m2 = |q|^2 and the squared derivative dm2 * 2^e */
inline lreal de_value(lreal m2, lreal dm2, lmask e)
{
    /* q_n = 0 exactly makes ln -> -inf; the smallest normal number keeps it finite */
    lreal mq = fmax(m2, REAL_MIN);
    lreal ratio = sqrt(mq / fmax(dm2, REAL_MIN));
    if (L_ANY(e != 0)) {   /* rescaled only past 1e16: a packet's ldexp costs an SVML call */
        ratio = ldexp(ratio, L_INT(-e / 2));
        ratio = L_SEL(ratio, ratio * (real)0.70710678118654752, (e & 1) != 0);
    }
    /* the 1/2 of the lower bound G / (2 |G'|) (Koebe), whatever the degree */
    return ratio * log(mq) / (real)4;
}

/* dm2 = mantissa * 2^e where big */
#define DE_RESCALE(dm2, e, big) do { \
        lint k_; \
        lreal mant_ = frexp(dm2, &k_); \
        dm2 = L_SEL(dm2, mant_, big); \
        e = L_SEL(e, e + L_MASK(k_), big); \
    } while (0)

/* dm2 *= factor where live, rescaled as mantissa * 2^e long before float32 overflows */
#define DE_GROW(dm2, e, factor, live) do { \
        dm2 = L_SEL(dm2, dm2 * (factor), live); \
        lmask big_ = (live) & (dm2 > (real)1e16); \
        if (L_ANY(big_)) \
            DE_RESCALE(dm2, e, big_); \
    } while (0)

#ifndef ALG_SPLIT
/* one step of the estimate's orbit where live: q <- f(q) + c, |q'|^2 (dm2 * 2^e) grown */
#define DE_ORBIT_STEP(q, m2, dm2, e, live, c, bailout2) do { \
        DE_GROW(dm2, e, JULIA_DF2(m2), live); \
        q = QSEL(q, julia_f(q, c), live); \
        m2 = ALG_NORM2(q); \
        live = m2 <= (bailout2); \
    } while (0)

inline lreal julia_distance_formula(quat p, julia_params jp, lmask *escaped)
{
    quat q = ALG_IN(p);
    real4 c = ALG_C(jp.c);
    lreal m2 = ALG_NORM2(q);
    lreal dm2 = (lreal)1;
    lmask e = 0;                    /* dm2 is really dm2 * 2^e */
    lmask live = m2 <= jp.bailout2;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n)
        DE_ORBIT_STEP(q, m2, dm2, e, live, c, jp.bailout2);
    COUNT_ITER(jp, n);
    *escaped = m2 > jp.bailout2;
    return de_value(m2, dm2, e);
}

#ifdef PACKET_PAIRS
/* The estimates of two packets (march/de.cl march_ray_pair) in one loop, lane for lane the
 * values julia_distance_formula gives.  Each orbit is a chain of dependent operations that
 * leaves most of a CPU's vector units idle while it waits on the last result; two chains
 * side by side fill them (kernels/march/march.cl, PACKET_PAIRS). */
inline void julia_distance_formula_pair(quat pa, quat pb, julia_params jp, lmask *escaped_a, lmask *escaped_b,
                                        lreal *da, lreal *db)
{
    real4 c = ALG_C(jp.c);
    PAIR_ORBIT_START(pa, pb, qa, qb, m2a, m2b, live_a, live_b, jp.bailout2);
    lreal dm2a = (lreal)1, dm2b = (lreal)1;
    lmask ea = 0, eb = 0;
    for (int n = 0; n < jp.max_iter && L_ANY(live_a | live_b); ++n) {
        dm2a = L_SEL(dm2a, dm2a * JULIA_DF2(m2a), live_a);
        dm2b = L_SEL(dm2b, dm2b * JULIA_DF2(m2b), live_b);
        lmask big_a = live_a & (dm2a > (real)1e16), big_b = live_b & (dm2b > (real)1e16);
        if (L_ANY(big_a | big_b)) {
            DE_RESCALE(dm2a, ea, big_a);
            DE_RESCALE(dm2b, eb, big_b);
        }
        PAIR_ORBIT_STEP(julia_f, qa, qb, c, c, m2a, m2b, live_a, live_b, jp.bailout2);
    }
    *escaped_a = m2a > jp.bailout2;
    *escaped_b = m2b > jp.bailout2;
    *da = de_value(m2a, dm2a, ea);
    *db = de_value(m2b, dm2b, eb);
}
#endif
#else
/* A split algebra (algebra/hypercomplex.cl): h = a e1 + b e2, and the Julia set of a
 * polynomial is the product K_a x K_b of the two complex filled Julia sets.  In C^2 the
 * distance to a product is sqrt(dist(a, K_a)^2 + dist(b, K_b)^2), and the split scales 4D
 * lengths by sqrt(2) (|a|^2 + |b|^2 = 2 |h|^2), so
 *     d = sqrt(d_a^2 + d_b^2) / sqrt(2),
 * each d_a = |a_n| ln|a_n| / (2 |a_n'|) the complex estimate of Hart, Sandin & Kauffman 1989 §3.1 (eq. 8;
 * |a'_{n+1}| = D |a_n|^(D-1) |a'_n|) where the component has provably escaped, |a_n| > 1 +
 * |c_a| (then |a^D + c_a| > |a|), and 0 where it has not (an under-estimate: safe steps).
 * The loop is the set test's (|h_n| <= bailout); *escaped is that test's. */
/* the estimate from the orbit's end q and the components' squared derivatives da * 2^ea, db * 2^eb */
inline lreal split_value(quat q, real4 c, lreal da, lmask ea, lreal db, lmask eb)
{
    lreal ma = q.x * q.x + q.y * q.y, mb = q.z * q.z + q.w * q.w;
    real ra = (real)1 + hypot(c.x, c.y), rb = (real)1 + hypot(c.z, c.w);
    lreal d_a = L_SEL((lreal)0, de_value(ma, da, ea), ma > ra * ra);
    lreal d_b = L_SEL((lreal)0, de_value(mb, db, eb), mb > rb * rb);
    return sqrt(d_a * d_a + d_b * d_b) * (real)0.70710678118654752;
}

inline lreal julia_distance_formula(quat p, julia_params jp, lmask *escaped)
{
    quat q = ALG_IN(p);
    real4 c = ALG_C(jp.c);
    lreal m2 = ALG_NORM2(q);
    lreal da = (lreal)1, db = (lreal)1;
    lmask ea = 0, eb = 0;
    lmask live = m2 <= jp.bailout2;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        DE_GROW(da, ea, JULIA_DF2(q.x * q.x + q.y * q.y), live);
        DE_GROW(db, eb, JULIA_DF2(q.z * q.z + q.w * q.w), live);
        q = QSEL(q, julia_f(q, c), live);
        m2 = ALG_NORM2(q);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    *escaped = m2 > jp.bailout2;
    return split_value(q, c, da, ea, db, eb);
}

#ifdef PACKET_PAIRS
/* The estimates of two packets (march/de.cl march_ray_pair) in one loop, lane for lane the
 * values julia_distance_formula gives; one test for the four derivatives' rescaling. */
inline void julia_distance_formula_pair(quat pa, quat pb, julia_params jp, lmask *escaped_a, lmask *escaped_b,
                                        lreal *dpa, lreal *dpb)
{
    real4 c = ALG_C(jp.c);
    PAIR_ORBIT_START(pa, pb, q0, q1, m0, m1, live0, live1, jp.bailout2);
    lreal a0 = (lreal)1, b0 = (lreal)1, a1 = (lreal)1, b1 = (lreal)1;
    lmask ea0 = 0, eb0 = 0, ea1 = 0, eb1 = 0;
    for (int n = 0; n < jp.max_iter && L_ANY(live0 | live1); ++n) {
        a0 = L_SEL(a0, a0 * JULIA_DF2(q0.x * q0.x + q0.y * q0.y), live0);
        b0 = L_SEL(b0, b0 * JULIA_DF2(q0.z * q0.z + q0.w * q0.w), live0);
        a1 = L_SEL(a1, a1 * JULIA_DF2(q1.x * q1.x + q1.y * q1.y), live1);
        b1 = L_SEL(b1, b1 * JULIA_DF2(q1.z * q1.z + q1.w * q1.w), live1);
        lmask ga0 = live0 & (a0 > (real)1e16), gb0 = live0 & (b0 > (real)1e16);
        lmask ga1 = live1 & (a1 > (real)1e16), gb1 = live1 & (b1 > (real)1e16);
        if (L_ANY(ga0 | gb0 | ga1 | gb1)) {
            DE_RESCALE(a0, ea0, ga0);
            DE_RESCALE(b0, eb0, gb0);
            DE_RESCALE(a1, ea1, ga1);
            DE_RESCALE(b1, eb1, gb1);
        }
        PAIR_ORBIT_STEP(julia_f, q0, q1, c, c, m0, m1, live0, live1, jp.bailout2);
    }
    *escaped_a = m0 > jp.bailout2;
    *escaped_b = m1 > jp.bailout2;
    *dpa = split_value(q0, c, a0, ea0, b0, eb0);
    *dpb = split_value(q1, c, a1, ea1, b1, eb1);
}
#endif
#endif

/* The distance estimate the march steps by: 0 inside (the point never escaped). */
inline lreal julia_distance(quat p, julia_params jp)
{
    lmask escaped;
    lreal d = julia_distance_formula(p, jp, &escaped);
    return L_SEL((lreal)0, d, escaped);
}
#endif  /* ALG_HAS_DE */
