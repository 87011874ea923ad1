/* algebra/complex.cl: complex arithmetic and the elementary complex functions on the lane
 * type (common/lanes.cl: one value, or a packet), for the function pieces (function/<name>.cl).
 * Branch cuts are numpy's (C99's): log and sqrt principal (cut on the negative reals,
 * arg in (-pi, pi]); asin, acos, atanh cut on the reals outside [-1, 1]; asinh, atan on
 * the imaginary axis outside [-i, i]; acosh on the reals below 1; pwr through log.
 * The formulas avoid overflow and cancellation where an orbit can take them (|z| below
 * the bailout); the iteration's test treats inf and NaN as escaped (comparisons fail). */

typedef struct { lreal re, im; } cplx;

inline cplx C(lreal re, lreal im) { cplx z = {re, im}; return z; }
inline cplx c_add(cplx a, cplx b) { return C(a.re + b.re, a.im + b.im); }
inline cplx c_sub(cplx a, cplx b) { return C(a.re - b.re, a.im - b.im); }
inline cplx c_neg(cplx a) { return C(-a.re, -a.im); }
inline cplx c_mul(cplx a, cplx b) { return C(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re); }
inline cplx c_sqr(cplx a) { return C(a.re * a.re - a.im * a.im, (real)2 * a.re * a.im); }
inline cplx c_scale(lreal s, cplx a) { return C(s * a.re, s * a.im); }
inline cplx c_times_i(cplx a) { return C(-a.im, a.re); }        /* i a */
inline cplx c_times_minus_i(cplx a) { return C(a.im, -a.re); }  /* -i a */

/* 1/b = conj(b) / |b|^2, scaled by the larger component first (no overflow of |b|^2) */
inline cplx c_recip(cplx b)
{
    lreal s = fmax(fabs(b.re), fabs(b.im));
    lreal x = b.re / s, y = b.im / s;
    lreal d = s * (x * x + y * y);
    return C(x / d, -y / d);
}

inline cplx c_div(cplx a, cplx b) { return c_mul(a, c_recip(b)); }

/* e^z; the imaginary part is 0 for real z even where e^x overflows (inf * 0 is NaN) */
inline cplx c_exp(cplx z)
{
    lreal r = exp(z.re);
    return C(r * cos(z.im), L_SEL(r * sin(z.im), z.im, z.im == (real)0));
}

/* hypot on the lane type, without the vector library's hypot: Intel's CPU runtime ran a
 * packet's hypot 150 times slower where a lane held very large or very small values (a kernel
 * timing each case on the development machine), which enclosures and escaped lanes pass it:
 * the proven march of hypercomplex pwr spent 31 % of its time there.  sqrt(x^2 + y^2) where
 * that neither overflows nor underflows (1e-30 <= x^2 + y^2 < 1e38, or x = y = 0): the sum
 * within 2u of x^2 + y^2 (u = 2^-24, one rounding), the root within 2u of the length.
 * Elsewhere m sqrt(1 + (n/m)^2), m = max(|x|, |y|), n = min: within 3.25u, finite or
 * infinite, NaN kept (a NaN disc proves nothing: enclose/disc.cl).  Both inside the 4u =
 * 2^-22 the enclosures allow each operation (enclose/disc.cl ENC_ROUND).  Out of line, as
 * the library's hypot is: inlined at every call it made the transcendental functions'
 * programs build 1.1-1.7 times longer. */
__attribute__((noinline)) lreal lane_hypot(lreal x, lreal y)
{
    lreal s = fma(x, x, y * y);
    lmask plain = ((s >= (real)1e-30) & (s < (real)1e38)) | ((x == (real)0) & (y == (real)0));
    lreal r = sqrt(s);
    if (L_ANY(!plain)) {
        lreal ax = fabs(x), ay = fabs(y);
        lreal m = fmax(ax, ay), n = fmin(ax, ay);
        lreal q = n / m;
        lreal scaled = m * sqrt(fma(q, q, (real)1));
        scaled = L_SEL(scaled, m, (m == (real)0) | (m == (real)INFINITY));
        scaled = L_SEL(scaled, x + y, isnan(x) | isnan(y));
        r = L_SEL(scaled, r, plain);
    }
    return r;
}

inline cplx c_log(cplx z) { return C(log(lane_hypot(z.re, z.im)), atan2(z.im, z.re)); }

/* principal square root (C99 csqrt): t = sqrt((|z| + |x|) / 2) */
inline cplx c_sqrt(cplx z)
{
    lreal t = sqrt((lane_hypot(z.re, z.im) + fabs(z.re)) * (real)0.5);
    lreal u = L_SEL(fabs(z.im) / ((real)2 * t), t, z.re >= (real)0);
    lreal v = L_SEL(copysign(t, z.im), z.im / ((real)2 * t), z.re >= (real)0);
    lmask zero = t == (real)0;
    return C(L_SEL(u, (lreal)0, zero), L_SEL(v, z.im, zero));
}

inline cplx c_sin(cplx z) { return C(sin(z.re) * cosh(z.im), cos(z.re) * sinh(z.im)); }
inline cplx c_cos(cplx z) { return C(cos(z.re) * cosh(z.im), -sin(z.re) * sinh(z.im)); }
inline cplx c_sinh(cplx z) { return C(sinh(z.re) * cos(z.im), cosh(z.re) * sin(z.im)); }
inline cplx c_cosh(cplx z) { return C(cosh(z.re) * cos(z.im), sinh(z.re) * sin(z.im)); }

/* tanh z = (sinh 2x + i sin 2y) / (cosh 2x + cos 2y); past |x| = 20 it is sign(x) + 0 i to
 * float64's precision, and cosh 2x would overflow (inf / inf) */
inline cplx c_tanh(cplx z)
{
    lreal d = cosh((real)2 * z.re) + cos((real)2 * z.im);
    lmask far = fabs(z.re) > (real)20;
    return C(L_SEL(sinh((real)2 * z.re) / d, copysign((lreal)1, z.re), far),
             L_SEL(sin((real)2 * z.im) / d, (lreal)0 * z.im, far));
}

/* tan z = -i tanh(i z) */
inline cplx c_tan(cplx z) { return c_times_minus_i(c_tanh(c_times_i(z))); }

/* asinh z = log(z + sqrt(z^2 + 1)), taken on the right half-plane (odd symmetry) so the
 * sum never cancels */
inline cplx c_asinh(cplx z)
{
    lmask neg = z.re < (real)0;
    cplx w = C(L_SEL(z.re, -z.re, neg), L_SEL(z.im, -z.im, neg));
    cplx r = c_log(c_add(w, c_sqrt(c_add(c_sqr(w), C((lreal)1, (lreal)0)))));
    return C(L_SEL(r.re, -r.re, neg), L_SEL(r.im, -r.im, neg));
}

inline cplx c_asin(cplx z) { return c_times_minus_i(c_asinh(c_times_i(z))); }   /* -i asinh(i z) */

inline cplx c_acos(cplx z)                                                       /* pi/2 - asin z */
{
    cplx a = c_asin(z);
    return C((real)1.57079632679489661923 - a.re, -a.im);
}

/* acosh z = log(z + sqrt(z + 1) sqrt(z - 1)) (Kahan's form, C99's cut) */
inline cplx c_acosh(cplx z)
{
    cplx p = c_mul(c_sqrt(C(z.re + (real)1, z.im)), c_sqrt(C(z.re - (real)1, z.im)));
    return c_log(c_add(z, p));
}

/* atanh z = (log(1 + z) - log(1 - z)) / 2; 1 - z as (1 - x, -y), so that a real z > 1
 * takes the sign of its zero imaginary part as C99 does */
inline cplx c_atanh(cplx z)
{
    cplx d = c_sub(c_log(C((real)1 + z.re, z.im)), c_log(C((real)1 - z.re, -z.im)));
    return c_scale((lreal)0.5, d);
}

inline cplx c_atan(cplx z) { return c_times_minus_i(c_atanh(c_times_i(z))); }   /* -i atanh(i z) */

/* z^p = exp(p log z); 0^p = 0 (p != 0 here: pwr's exponent with a positive real part is
 * the useful case, and numpy's nan at 0 would poison the orbit) */
inline cplx c_pow(cplx z, cplx p)
{
    cplx r = c_exp(c_mul(p, c_log(z)));
    lmask zero = (z.re == (real)0) & (z.im == (real)0);
    return C(L_SEL(r.re, (lreal)0, zero), L_SEL(r.im, (lreal)0, zero));
}
