/* enclose/disc.cl: circular complex arithmetic (Gargantini and Henrici's discs) on the lane
 * type (common/lanes.cl), for proofs of empty space (march/proven.cl).  A disc {m, r}
 * holds every z with |z - m| <= r; each operation returns a disc that holds the image of
 * every point of its arguments' discs, so an orbit enclosure built from them holds the
 * orbits of all the points it started from.
 *
 * Rounding: the centre is computed in the working precision, so every radius is raised by
 * a bound on that rounding: ENC_ROUND (sums of products, 2^-22: 4 ulps of float32 times
 * the size the callers pass, which is at least twice the sum of the terms' sizes, against
 * the 0.5 ulp per operation - 3.5 ulps for a sum of four products - that they can lose)
 * or ENC_ROUND_FN (the elementary functions and the complex formulas made of two or three
 * of them, 2^-20: 16 ulps of the result, where OpenCL's full profile allows each function
 * 3-6 ulps, so a product of two 8.5; no -cl-fast-relaxed-math or native_ functions are
 * used), plus ENC_TINY for results that flush to zero.  Radii are multiplied by ENC_UP after each operation, so
 * rounding in the radius itself cannot shrink it.  Double precision (-D REAL_DOUBLE) has the
 * same bounds in its own ulps (2^-50, 2^-48, 2^-46).  They matter where the orbit stretches
 * its points apart fast: the float32 bound on the rounding of a point itself, amplified
 * over 12 iterations of the commutative square (some 5e6 times), outgrew what its last
 * iteration left beyond the bailout, so no segment there, however short, could be proven,
 * and its default view stated a p99 of 0.31; in double, 1.7e-4.
 *
 * Non-finite values: an operation that cannot bound its image (a pole inside the disc,
 * a disc that meets a branch cut where no better bound is known, overflow) gives an
 * infinite radius, and comparisons with NaN are false, so such a disc proves nothing. */

#ifdef REAL_DOUBLE
#define ENC_ROUND ((real)8.8817841970012523e-16)  /* 2^-50 */
#define ENC_ROUND_FN ((real)3.5527136788005009e-15) /* 2^-48 */
#define ENC_UP ((real)1.0000000000000142108547152020037)  /* 1 + 2^-46 */
#else
#define ENC_ROUND ((real)2.384185791015625e-7)  /* 2^-22 */
#define ENC_ROUND_FN ((real)9.5367431640625e-7) /* 2^-20 */
#define ENC_UP ((real)1.0000038146972656)       /* 1 + 2^-18 */
#endif
#define ENC_TINY ((real)1e-30)
#define ENC_PI ((real)3.14159274101257324)      /* float32 pi rounded up */

typedef struct { cplx m; lreal r; } cdisc;

inline cdisc D(cplx m, lreal r) { cdisc z = {m, r}; return z; }
inline lreal c_abs(cplx z) { return lane_hypot(z.re, z.im); }

/* a radius raised for its own rounding and for the rounding of a centre of size ``size`` */
inline lreal enc_radius(lreal r, lreal size, real rel)
{
    lreal out = r * ENC_UP + rel * size + ENC_TINY;
    return L_SEL(out, (lreal)INFINITY, isnan(out));
}

inline cdisc d_add_const(cdisc z, cplx k)
{
    cplx m = c_add(z.m, k);
    return D(m, enc_radius(z.r, c_abs(z.m) + c_abs(k), ENC_ROUND));
}

inline cdisc d_add(cdisc a, cdisc b)
{
    return D(c_add(a.m, b.m), enc_radius(a.r + b.r, c_abs(a.m) + c_abs(b.m), ENC_ROUND));
}

inline cdisc d_neg(cdisc a) { return D(c_neg(a.m), a.r); }
inline cdisc d_times_i(cdisc a) { return D(c_times_i(a.m), a.r); }
inline cdisc d_times_minus_i(cdisc a) { return D(c_times_minus_i(a.m), a.r); }

/* (ma + ea)(mb + eb) = ma mb + ma eb + mb ea + ea eb */
inline cdisc d_mul(cdisc a, cdisc b)
{
    lreal sa = c_abs(a.m), sb = c_abs(b.m);
    return D(c_mul(a.m, b.m), enc_radius(sa * b.r + sb * a.r + a.r * b.r, sa * sb, ENC_ROUND));
}

inline cdisc d_sqr(cdisc a)
{
    lreal s = c_abs(a.m);
    return D(c_sqr(a.m), enc_radius(((real)2 * s + a.r) * a.r, s * s, ENC_ROUND));
}

inline cdisc d_scale(cplx k, cdisc a)
{
    lreal s = c_abs(k);
    return D(c_mul(k, a.m), enc_radius(s * a.r, s * c_abs(a.m), ENC_ROUND));
}

/* f on a disc by the mean-value theorem: f(m) and r times a bound ``lip`` on |f'| over
 * the disc (an infinite or NaN ``lip``: no bound) */
inline cdisc d_mean_value_sized(cplx fm, lreal r, lreal lip, lreal size)
{
    lreal rr = r * lip * ENC_UP;
    return D(fm, enc_radius(L_SEL(rr, (lreal)INFINITY, isnan(rr) | (lip < (real)0)), size, ENC_ROUND_FN));
}

inline cdisc d_mean_value(cplx fm, lreal r, lreal lip) { return d_mean_value_sized(fm, r, lip, c_abs(fm)); }

/* f on a disc to second order: |f'(z)| <= |f'(m)| + r sup|f''| on the disc, so f(z) lies
 * within r (|f'(m)| + r ``m2``) of f(m), ``m2`` a bound on |f''| over the disc (far
 * tighter than a bound on |f'| alone where f'(m) is small: near f's critical points, where
 * the orbits of the set's surface go).  ``d1`` = |f'(m)| is computed, so it is raised by
 * the functions' rounding. */
inline cdisc d_taylor(cplx fm, lreal d1, lreal r, lreal m2)
{
    return d_mean_value(fm, r, d1 * ((real)1 + ENC_ROUND_FN) + ENC_TINY + r * m2 * ENC_UP);
}

/* the least |m + s v| over s in [-1, 1] (an affine form's centre and tangent, enclose/ball.cl
 * and enclose/split.cl): the distance from 0 to the segment */
inline lreal enc_least_norm(quat m, quat v)
{
    lreal vv = QNORM2(v);
    lreal s = clamp(L_SEL(-QDOT(m, v) / vv, (lreal)0, vv == (real)0), (lreal)-1, (lreal)1);
    return QLEN(QADD(m, QSCALE(s, v)));
}

/* A partial proof (march/proven.cl): where a form does not keep all of its segment outside
 * the bailout, it may keep a part [-1, s] in front.  Given |m|^2 (mm), returns the largest s
 * in [-1, 1] with |m + s' v| (1 - ENC_ROUND) > reach for every s' in [-1, s], -1 where none
 * is found.  Only where the segment's start is outside (|m - v| past reach: the iterations
 * about its own escape; the rest return -1 at once) is the smaller root of |v|^2 s^2 +
 * 2 (m . v) s + |m|^2 - rho^2 taken (1 where there is none), drawn in towards -1 by
 * PREFIX_DRAW of its distance, and checked: |m + s v| falls on [-1, s] (s before the
 * least's s = -(m . v) / |v|^2), so its value at s is its least there, tested as the
 * enclosure piece tests the whole.  Rounding in the root costs a shorter part, never a
 * wrong one. */
#define PREFIX_DRAW ((real)2.44140625e-4)   /* 2^-12 */

inline lreal enc_prefix_of(quat m, quat v, lreal mm, lreal reach, lmask live)
{
    lreal vv = QNORM2(v), mv = QDOT(m, v);
    lreal rho = reach / ((real)1 - ENC_ROUND);
    lreal rho2 = rho * rho;
    lmask go = live & (mm - (real)2 * mv + vv > rho2);
    if (!L_ANY(go))
        return (lreal)-1;
    lreal disc = mv * mv - vv * (mm - rho2);
    lreal root = (-mv - sqrt(fmax(disc, (lreal)0))) / fmax(vv, (lreal)REAL_MIN);
    lreal s = L_SEL(fmin(fmax(root, (lreal)-1), (lreal)1), (lreal)1, (disc < (real)0) | (vv == (real)0));
    s = (real)-1 + (s + (real)1) * ((real)1 - PREFIX_DRAW);
    lreal l = QLEN(QADD(m, QSCALE(s, v))) * ((real)1 - ENC_ROUND);
    return L_SEL((lreal)-1, s, go & (s * vv <= -mv) & (l > reach) & (s > (real)-1));
}

/* The disc of a function piece that states FUNC_M2 (its bound on |f''|): d_taylor with its
 * own cfun, cfun_d and that bound, expanded where the piece uses it */
#define D_TAYLOR_OF(z) d_taylor(cfun((z).m), c_abs(cfun_d((z).m)), (z).r, FUNC_M2((z).m, (z).r))

/* exp: |exp'| = e^Re z <= e^(Re m + r) */
inline cdisc d_exp(cdisc z) { return d_mean_value(c_exp(z.m), z.r, exp(z.m.re + z.r) * ENC_UP); }

/* 1/z: the image of the disc is the disc of centre conj(m) / (|m|^2 - r^2), so
 * |1/z - 1/m| <= r / (|m| (|m| - r)) exactly (a Moebius map); unbounded if 0 is in it */
inline cdisc d_recip(cdisc z)
{
    lreal s = c_abs(z.m);
    lreal gap = s - z.r * ENC_UP;
    lreal rr = z.r / (s * gap) * ENC_UP;
    return D(c_recip(z.m), enc_radius(L_SEL((lreal)INFINITY, rr, gap > (real)0), (lreal)1 / s, ENC_ROUND_FN));
}

/* whether the disc meets the cut of the principal log and sqrt: the reals <= 0 */
inline lmask d_meets_cut(cdisc z)
{
    return ((z.m.re <= z.r) & (fabs(z.m.im) <= z.r * ENC_UP + ENC_TINY)) | (c_abs(z.m) <= z.r * ENC_UP);
}

/* principal log: |log'| = 1 / |z| <= 1 / (|m| - r).  A disc that meets the cut holds
 * values on both sides of it: Re in [ln(|m| - r), ln(|m| + r)], Im in [-pi, pi], the
 * disc around that rectangle */
inline cdisc d_log(cdisc z)
{
    lreal s = c_abs(z.m);
    lreal gap = s - z.r * ENC_UP;
    /* log|m| near |m| = 1 is small with an absolute error: the rounding bound gets + 1 */
    cplx lm = c_log(z.m);
    cdisc smooth = d_mean_value_sized(lm, z.r, (lreal)1 / gap, c_abs(lm) + (real)1);
    lreal lo = log(gap) - ENC_ROUND_FN * fabs(log(gap)), hi = log(s + z.r * ENC_UP) + ENC_ROUND_FN * fabs(log(s + z.r));
    lreal mid = (real)0.5 * (lo + hi), hw = (real)0.5 * (hi - lo);
    cdisc cut = D(C(mid, (lreal)0), enc_radius(lane_hypot(hw, (lreal)ENC_PI), fabs(mid), ENC_ROUND_FN));
    lmask meets = d_meets_cut(z);
    lreal r = L_SEL(smooth.r, cut.r, meets);
    r = L_SEL(r, (lreal)INFINITY, gap <= (real)0);
    return D(C(L_SEL(smooth.m.re, cut.m.re, meets), L_SEL(smooth.m.im, cut.m.im, meets)), r);
}

/* principal sqrt: |sqrt'| = 1 / (2 sqrt|z|) <= 1 / (2 sqrt(|m| - r)); across the cut (or
 * around 0) every value has |sqrt z| <= sqrt(|m| + r): the disc of that radius around 0 */
inline cdisc d_sqrt(cdisc z)
{
    lreal s = c_abs(z.m);
    lreal gap = s - z.r * ENC_UP;
    cdisc smooth = d_mean_value(c_sqrt(z.m), z.r, (real)0.5 / sqrt(gap));
    lmask meets = d_meets_cut(z) | (gap <= (real)0);
    lreal big = enc_radius(sqrt(s + z.r), (lreal)0, ENC_ROUND_FN) * ENC_UP;
    return D(C(L_SEL(smooth.m.re, (lreal)0, meets), L_SEL(smooth.m.im, (lreal)0, meets)),
             L_SEL(smooth.r, big, meets));
}

/* z^p = exp(p log z) with the principal log.  A disc that meets the cut holds points on both
 * sides of it, whose values are exp(p L) and exp(p (L - 2 pi i)), L = log(-z) + i pi the log
 * cut along the positive reals instead: the image is the union of the two discs that
 * L gives, one turned by e^(-2 pi i p) (the same disc for an integer p, where z^p is
 * continuous), held by the disc around both. */
inline cdisc d_pwr(cdisc z, cplx p)
{
    cdisc plain = d_exp(d_scale(p, d_log(z)));
    lmask cut = d_meets_cut(z);
    if (!L_ANY(cut))
        return plain;
    cdisc w = d_log(d_neg(z));                       /* log(-z): its cut is the positive reals */
    w = D(C(w.m.re, w.m.im + ENC_PI), enc_radius(w.r, (lreal)ENC_PI, ENC_ROUND));
    cdisc d1 = d_exp(d_scale(p, w));
    cplx turn = c_exp(C((real)2 * ENC_PI * p.im, (real)-2 * ENC_PI * p.re));   /* e^(-2 pi i p) */
    cdisc d2 = d_scale(turn, d1);
    d2.r = enc_radius(d2.r, c_abs(d2.m), ENC_ROUND_FN);   /* the rounding of the turn itself */
    cplx mid = c_scale((lreal)0.5, c_add(d1.m, d2.m));
    lreal r = (real)0.5 * c_abs(c_sub(d1.m, d2.m)) + fmax(d1.r, d2.r);
    cdisc both = D(mid, enc_radius(r, c_abs(d1.m) + c_abs(d2.m), ENC_ROUND));
    return D(C(L_SEL(plain.m.re, both.m.re, cut), L_SEL(plain.m.im, both.m.im, cut)), L_SEL(plain.r, both.r, cut));
}

/* the least of cos^2 over [a, b]: 0 where the interval holds a zero of cos (k + 1/2) pi
 * (decided with a margin, so a rounding can only lower it), else the smaller end */
inline lreal least_cos2(lreal a, lreal b)
{
    lreal k = ceil((a - (real)1.5707963267948966) * (real)0.31830988618379067 - (real)1e-4);
    lmask zero = (k * ENC_PI + (real)1.5707963267948966 <= b + (real)1e-4 * (fabs(b) + (real)1))
                 | (b - a >= (real)3.1415926);
    lreal ca = cos(a), cb = cos(b);
    lreal m = fmin(ca * ca, cb * cb) * ((real)1 - ENC_ROUND_FN) - ENC_ROUND_FN;
    return L_SEL(fmax(m, (lreal)0), (lreal)0, zero);
}

/* the least of sinh^2 over [a, b] */
inline lreal least_sinh2(lreal a, lreal b)
{
    lreal x = L_SEL(fmin(fabs(a), fabs(b)), (lreal)0, (a <= (real)0) & (b >= (real)0));
    lreal s = sinh(x);
    return s * s * ((real)1 - ENC_ROUND_FN);
}

/* tan and tanh, whose centre values lose relative accuracy near a pole: there the
 * denominator cosh 2x + cos 2y cancels, so the rounding bound is scaled by
 * (cosh 2x + 1) / |cosh 2x + cos 2y|.  |tanh'| = 1 / |cosh z|^2 and |cosh z|^2 = sinh^2 x +
 * cos^2 y, least over the disc's square; a square that holds a pole (i (k + 1/2) pi)
 * gets no bound. */
inline cdisc d_tanh(cdisc z)
{
    lreal lip = (lreal)1 / (least_sinh2(z.m.re - z.r, z.m.re + z.r) + least_cos2(z.m.im - z.r, z.m.im + z.r));
    lreal den = fabs(cosh((real)2 * z.m.re) + cos((real)2 * z.m.im));
    lreal gain = (cosh((real)2 * z.m.re) + (real)1) / den;
    cplx fm = c_tanh(z.m);
    lreal rr = z.r * lip * ENC_UP;
    rr = L_SEL(rr, (lreal)INFINITY, isnan(rr) | !(gain < (real)1e6));
    return D(fm, enc_radius(rr, c_abs(fm) * gain + (real)1, ENC_ROUND_FN));
}

inline cdisc d_tan(cdisc z) { return d_times_minus_i(d_tanh(d_times_i(z))); }   /* -i tanh(i z) */

/* asinh z = log(z + sqrt(z^2 + 1)) on the right half-plane (odd symmetry, as c_asinh):
 * no cancellation in the sum */
inline cdisc d_asinh(cdisc z)
{
    lmask neg = z.m.re < (real)0;
    cdisc w = D(C(L_SEL(z.m.re, -z.m.re, neg), L_SEL(z.m.im, -z.m.im, neg)), z.r);
    cdisc s = d_sqrt(d_add_const(d_sqr(w), C((lreal)1, (lreal)0)));
    cdisc r = d_log(d_add(w, s));
    return D(C(L_SEL(r.m.re, -r.m.re, neg), L_SEL(r.m.im, -r.m.im, neg)), r.r);
}

/* atanh z = (log(1 + z) - log(1 - z)) / 2 */
inline cdisc d_atanh(cdisc z)
{
    cdisc a = d_log(d_add_const(z, C((lreal)1, (lreal)0)));
    cdisc b = d_log(d_add_const(d_neg(z), C((lreal)1, (lreal)0)));
    return d_scale(C((lreal)0.5, (lreal)0), d_add(a, d_neg(b)));
}
