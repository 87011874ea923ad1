// tests/kernels/test_default_kernels.py: the default scene's preprocessed kernels (see its docstring)
typedef float real;
typedef float4 real4;
typedef float3 real3;
typedef float2 real2;
typedef struct {
real4 c;
real bailout2;
real epsilon;
int max_iter;
} julia_params;
inline float3 UNIT3(float3 a, float3 fallback)
{
float aa = ((a).x * (a).x + (a).y * (a).y + (a).z * (a).z);
return aa > 0.0f && aa <= FLT_MAX ? a * rsqrt(aa) : fallback;
}
typedef real lreal;
typedef int lmask;
typedef int mask_t;
typedef int lint;
typedef real4 quat;
typedef struct { lreal re, im; } cplx;
inline cplx C(lreal re, lreal im) { cplx z = {re, im}; return z; }
inline cplx c_add(cplx a, cplx b) { return C(a.re + b.re, a.im + b.im); }
inline cplx c_sub(cplx a, cplx b) { return C(a.re - b.re, a.im - b.im); }
inline cplx c_neg(cplx a) { return C(-a.re, -a.im); }
inline cplx c_mul(cplx a, cplx b) { return C(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re); }
inline cplx c_sqr(cplx a) { return C(a.re * a.re - a.im * a.im, (real)2 * a.re * a.im); }
inline cplx c_scale(lreal s, cplx a) { return C(s * a.re, s * a.im); }
inline cplx c_times_i(cplx a) { return C(-a.im, a.re); }
inline cplx c_times_minus_i(cplx a) { return C(a.im, -a.re); }
inline cplx c_recip(cplx b)
{
lreal s = fmax(fabs(b.re), fabs(b.im));
lreal x = b.re / s, y = b.im / s;
lreal d = s * (x * x + y * y);
return C(x / d, -y / d);
}
inline cplx c_div(cplx a, cplx b) { return c_mul(a, c_recip(b)); }
inline cplx c_exp(cplx z)
{
lreal r = exp(z.re);
return C(r * cos(z.im), ((z.im == (real)0) ? (z.im) : (r * sin(z.im))));
}
__attribute__((noinline)) lreal lane_hypot(lreal x, lreal y)
{
lreal s = fma(x, x, y * y);
lmask plain = ((s >= (real)1e-30) & (s < (real)1e38)) | ((x == (real)0) & (y == (real)0));
lreal r = sqrt(s);
if ((!plain)) {
lreal ax = fabs(x), ay = fabs(y);
lreal m = fmax(ax, ay), n = fmin(ax, ay);
lreal q = n / m;
lreal scaled = m * sqrt(fma(q, q, (real)1));
scaled = (((m == (real)0) | (m == (real)INFINITY)) ? (m) : (scaled));
scaled = ((isnan(x) | isnan(y)) ? (x + y) : (scaled));
r = ((plain) ? (r) : (scaled));
}
return r;
}
inline cplx c_log(cplx z) { return C(log(lane_hypot(z.re, z.im)), atan2(z.im, z.re)); }
inline cplx c_sqrt(cplx z)
{
lreal t = sqrt((lane_hypot(z.re, z.im) + fabs(z.re)) * (real)0.5);
lreal u = ((z.re >= (real)0) ? (t) : (fabs(z.im) / ((real)2 * t)));
lreal v = ((z.re >= (real)0) ? (z.im / ((real)2 * t)) : (copysign(t, z.im)));
lmask zero = t == (real)0;
return C(((zero) ? ((lreal)0) : (u)), ((zero) ? (z.im) : (v)));
}
inline cplx c_sin(cplx z) { return C(sin(z.re) * cosh(z.im), cos(z.re) * sinh(z.im)); }
inline cplx c_cos(cplx z) { return C(cos(z.re) * cosh(z.im), -sin(z.re) * sinh(z.im)); }
inline cplx c_sinh(cplx z) { return C(sinh(z.re) * cos(z.im), cosh(z.re) * sin(z.im)); }
inline cplx c_cosh(cplx z) { return C(cosh(z.re) * cos(z.im), sinh(z.re) * sin(z.im)); }
inline cplx c_tanh(cplx z)
{
lreal d = cosh((real)2 * z.re) + cos((real)2 * z.im);
lmask far = fabs(z.re) > (real)20;
return C(((far) ? (copysign((lreal)1, z.re)) : (sinh((real)2 * z.re) / d)),
((far) ? ((lreal)0 * z.im) : (sin((real)2 * z.im) / d)));
}
inline cplx c_tan(cplx z) { return c_times_minus_i(c_tanh(c_times_i(z))); }
inline cplx c_asinh(cplx z)
{
lmask neg = z.re < (real)0;
cplx w = C(((neg) ? (-z.re) : (z.re)), ((neg) ? (-z.im) : (z.im)));
cplx r = c_log(c_add(w, c_sqrt(c_add(c_sqr(w), C((lreal)1, (lreal)0)))));
return C(((neg) ? (-r.re) : (r.re)), ((neg) ? (-r.im) : (r.im)));
}
inline cplx c_asin(cplx z) { return c_times_minus_i(c_asinh(c_times_i(z))); }
inline cplx c_acos(cplx z)
{
cplx a = c_asin(z);
return C((real)1.57079632679489661923 - a.re, -a.im);
}
inline cplx c_acosh(cplx z)
{
cplx p = c_mul(c_sqrt(C(z.re + (real)1, z.im)), c_sqrt(C(z.re - (real)1, z.im)));
return c_log(c_add(z, p));
}
inline cplx c_atanh(cplx z)
{
cplx d = c_sub(c_log(C((real)1 + z.re, z.im)), c_log(C((real)1 - z.re, -z.im)));
return c_scale((lreal)0.5, d);
}
inline cplx c_atan(cplx z) { return c_times_minus_i(c_atanh(c_times_i(z))); }
inline cplx c_pow(cplx z, cplx p)
{
cplx r = c_exp(c_mul(p, c_log(z)));
lmask zero = (z.re == (real)0) & (z.im == (real)0);
return C(((zero) ? ((lreal)0) : (r.re)), ((zero) ? ((lreal)0) : (r.im)));
}
inline cplx cfun(cplx z) { return c_sqr(z); }
inline cplx cfun_d(cplx z) { return c_scale((lreal)2, z); }
inline real4 alg_mul(real4 a, real4 b)
{
return (real4)(a.x * b.x - a.y * b.y - a.z * b.z - a.w * b.w,
a.x * b.y + a.y * b.x + a.z * b.w - a.w * b.z,
a.x * b.z - a.y * b.w + a.z * b.x + a.w * b.y,
a.x * b.w + a.y * b.z - a.z * b.y + a.w * b.x);
}
inline quat alg_sqr(quat q)
{
return ((real4)((q.x * q.x - q.y * q.y - q.z * q.z - q.w * q.w), ((real)2 * q.x * q.y), ((real)2 * q.x * q.z), ((real)2 * q.x * q.w)));
}
inline quat alg_sqr_jvp(quat q, quat h)
{
return ((real4)(((real)2 * (q.x * h.x - q.y * h.y - q.z * h.z - q.w * h.w)), ((real)2 * (q.x * h.y + h.x * q.y)), ((real)2 * (q.x * h.z + h.x * q.z)), ((real)2 * (q.x * h.w + h.x * q.w))));
}
inline quat alg_cube(quat q)
{
lreal v2 = q.y * q.y + q.z * q.z + q.w * q.w;
lreal s = (real)3 * q.x * q.x - v2;
return ((real4)((q.x * (q.x * q.x - (real)3 * v2)), (s * q.y), (s * q.z), (s * q.w)));
}
inline quat alg_cube_jvp(quat q, quat h)
{
lreal v2 = q.y * q.y + q.z * q.z + q.w * q.w;
lreal vu = q.y * h.y + q.z * h.z + q.w * h.w;
lreal s = (real)3 * q.x * q.x - v2;
lreal t = (real)6 * q.x * h.x - (real)2 * vu;
return ((real4)(((real)3 * (q.x * q.x * h.x - h.x * v2) - (real)6 * q.x * vu), (t * q.y + s * h.y), (t * q.z + s * h.z), (t * q.w + s * h.w)));
}
inline quat julia_f(quat q, real4 c) { return ((alg_sqr(q)) + (c)); }
inline quat julia_f_jvp(quat q, quat h) { return alg_sqr_jvp(q, h); }
inline lmask julia_inside(quat p, julia_params jp)
{
quat q = (p);
real4 c = (jp.c);
lmask live = (((q)).x * ((q)).x + ((q)).y * ((q)).y + ((q)).z * ((q)).z + ((q)).w * ((q)).w) <= jp.bailout2;
int n = 0;
for (; n < jp.max_iter && (live); ++n) {
q = ((live) ? (julia_f(q, c)) : (q));
live = (((q)).x * ((q)).x + ((q)).y * ((q)).y + ((q)).z * ((q)).z + ((q)).w * ((q)).w) <= jp.bailout2;
}
;
return live;
}
inline lreal level_value(lreal m2, lmask steps, julia_params jp, lmask *inside)
{
*inside = m2 <= jp.bailout2;
lmask k = jp.max_iter - steps;
lreal e = ldexp(log(m2 / jp.bailout2), (min(k, 60)));
lreal out = (((k > 60) | (e > (real)69)) ? ((lreal)1e30) : (expm1(fmin(e, (real)69))));
return ((*inside) ? (m2 / jp.bailout2 - (real)1) : (out));
}
inline lreal julia_level(quat p, julia_params jp, lmask *inside)
{
quat q = (p);
real4 c = (jp.c);
lreal m2 = (((q)).x * ((q)).x + ((q)).y * ((q)).y + ((q)).z * ((q)).z + ((q)).w * ((q)).w);
lmask live = m2 <= jp.bailout2;
lmask steps = 0;
int n = 0;
for (; n < jp.max_iter && (live); ++n)
do { q = ((live) ? (julia_f(q, c)) : (q)); m2 = (((q)).x * ((q)).x + ((q)).y * ((q)).y + ((q)).z * ((q)).z + ((q)).w * ((q)).w); steps = ((live) ? (steps + 1) : (steps)); live = m2 <= (jp.bailout2); } while (0);
;
return level_value(m2, steps, jp, inside);
}
inline lreal de_value(lreal m2, lreal dm2, lmask e)
{
lreal mq = fmax(m2, FLT_MIN);
lreal ratio = sqrt(mq / fmax(dm2, FLT_MIN));
if ((e != 0)) {
ratio = ldexp(ratio, (-e / 2));
ratio = (((e & 1) != 0) ? (ratio * (real)0.70710678118654752) : (ratio));
}
return ratio * log(mq) / (real)4;
}
inline lreal julia_distance_formula(quat p, julia_params jp, lmask *escaped)
{
quat q = (p);
real4 c = (jp.c);
lreal m2 = (((q)).x * ((q)).x + ((q)).y * ((q)).y + ((q)).z * ((q)).z + ((q)).w * ((q)).w);
lreal dm2 = (lreal)1;
lmask e = 0;
lmask live = m2 <= jp.bailout2;
int n = 0;
for (; n < jp.max_iter && (live); ++n)
do { do { dm2 = ((live) ? (dm2 * (((real)4 * (m2)))) : (dm2)); lmask big_ = (live) & (dm2 > (real)1e16); if ((big_)) do { lint k_; lreal mant_ = frexp(dm2, &k_); dm2 = ((big_) ? (mant_) : (dm2)); e = ((big_) ? (e + (k_)) : (e)); } while (0); } while (0); q = ((live) ? (julia_f(q, c)) : (q)); m2 = (((q)).x * ((q)).x + ((q)).y * ((q)).y + ((q)).z * ((q)).z + ((q)).w * ((q)).w); live = m2 <= (jp.bailout2); } while (0);
;
*escaped = m2 > jp.bailout2;
return de_value(m2, dm2, e);
}
inline lreal julia_distance(quat p, julia_params jp)
{
lmask escaped;
lreal d = julia_distance_formula(p, jp, &escaped);
return ((escaped) ? (d) : ((lreal)0));
}
typedef struct {
lreal a, b, ya, yb, eps, k1;
lmask live;
} itp_state;
inline itp_state itp_start(lreal a, lreal b, lreal fa, lreal fb, lmask todo, int steps)
{
itp_state s;
s.a = a;
s.b = b;
s.ya = -fmax(fa, FLT_MIN);
s.yb = -fmin(fb, (real)0);
lreal w0 = b - a;
s.eps = ldexp(w0, -(steps + 1));
s.k1 = (real)0.2 / w0;
s.live = todo & (b - a > (real)2 * s.eps);
return s;
}
inline lreal itp_point(itp_state *s, int j, int steps)
{
lreal a = s->a, b = s->b;
lreal xh = (real)0.5 * (a + b);
s->live &= (xh > a) & (xh < b);
lreal r = ldexp(s->eps, steps + 1 - j) - (real)0.5 * (b - a);
lreal delta = s->k1 * (b - a) * (b - a);
lreal xf = ((s->yb != s->ya) ? ((s->yb * a - s->ya * b) / (s->yb - s->ya)) : (xh));
lreal sigma = ((xh >= xf) ? ((lreal)1) : ((lreal)-1));
lreal xt = ((delta <= fabs(xh - xf)) ? (xf + sigma * delta) : (xh));
lreal x = ((fabs(xt - xh) <= r) ? (xt) : (xh - sigma * r));
return (((x > a) & (x < b)) ? (x) : (xh));
}
inline void itp_take(itp_state *s, lreal x, lreal f, lmask inside)
{
lreal y = -f;
lmask got_in = s->live & inside, got_out = s->live & !inside;
s->b = ((got_in) ? (x) : (s->b));
s->yb = ((got_in) ? (fmax(y, (real)0)) : (s->yb));
s->a = ((got_out) ? (x) : (s->a));
s->ya = ((got_out) ? (fmin(y, -FLT_MIN)) : (s->ya));
s->live &= s->b - s->a > (real)2 * s->eps;
}
inline lreal refine_bracket(quat o, quat d, lreal a, lreal b, lmask todo, int steps,
julia_params jp, lreal *width)
{
if (!(todo)) {
*width = b - a;
return a;
}
quat away = ((real4)(((lreal)((real)4 * sqrt((jp).bailout2))), ((lreal)0), ((lreal)0), ((lreal)0)));
lmask inside;
lreal fa = julia_level(((todo) ? (((o) + (a) * (d))) : (away)), jp, &inside);
lreal fb = julia_level(((todo) ? (((o) + (b) * (d))) : (away)), jp, &inside);
itp_state s = itp_start(a, b, fa, fb, todo, steps);
for (int j = 0; j <= steps && (s.live); ++j) {
lreal x = itp_point(&s, j, steps);
if (!(s.live))
break;
lreal f = julia_level(((s.live) ? (((o) + (x) * (d))) : (away)), jp, &inside);
itp_take(&s, x, f, inside);
}
a = s.a;
b = s.b;
*width = b - a;
return a;
}
typedef struct {
lreal t, t_prev, omega, step, r_prev;
lmask active, shell, hit, miss, first;
} de_march;
inline de_march de_start(lreal near, lmask live)
{
de_march m;
m.t = m.t_prev = near;
m.omega = (lreal)((real)1.2);
m.step = m.r_prev = (lreal)0;
m.active = live;
m.shell = m.hit = m.miss = m.first = (lmask)0;
return m;
}
inline void de_leave(de_march *m, int i, lreal far, lmask *samples)
{
lmask out = m->active & (m->t > far);
*samples = ((out) ? ((lmask)i) : (*samples));
m->miss |= out;
m->active &= !out;
}
inline void de_advance(de_march *m, int i, lreal dist, lmask escaped, real epsilon, lmask *samples,
lmask *flags)
{
lreal r = ((escaped) ? (dist) : ((lreal)0));
lmask gap = m->active & (m->omega > (real)1) & (r + m->r_prev < m->step);
lmask got = m->active & !escaped & !gap;
*samples = ((got) ? ((lmask)(i + 1)) : (*samples));
m->hit |= got;
if (i == 0)
m->first = got;
m->active &= !got;
m->shell |= m->active & !gap & (dist < epsilon);
m->step = ((gap) ? (m->step * ((real)1 - m->omega)) : (fmax(dist, epsilon) * m->omega));
m->omega = ((gap) ? ((lreal)1) : (m->omega));
m->r_prev = ((gap) ? (m->r_prev) : (r));
lreal next = m->t + m->step;
lmask stall = m->active & (next == m->t);
if ((stall)) {
next = ((stall) ? (nextafter(m->t, (lreal)INFINITY)) : (next));
*flags |= ((stall) ? ((lmask)4) : ((lmask)0));
}
m->t_prev = ((m->active & !gap) ? (m->t) : (m->t_prev));
m->t = ((m->active) ? (next) : (m->t));
}
inline lmask de_close(const de_march *m, lmask live, int max_steps, lmask *status, lmask *samples, lmask *flags)
{
*samples = ((m->active) ? ((lmask)max_steps) : (*samples));
*flags |= ((m->miss & m->shell) ? ((lmask)8) : ((lmask)0));
*status = ((live) ? (((m->hit) ? ((lmask)1) : (((m->miss) ? ((lmask)0) : ((lmask)2))))) : (*status));
return m->hit & !m->first;
}
inline lreal de_depth(const de_march *m, lreal a, lreal w, lreal near, lreal far, lmask live, lreal *width,
lreal *unresolved)
{
lmask hit = m->hit, refined = m->hit & !m->first;
*width = ((hit) ? (((refined) ? (w) : ((lreal)0))) : (*width));
lreal depth = ((hit) ? (((refined) ? (a) : (m->t))) : ((lreal)INFINITY));
*unresolved = ((live) ? (((hit) ? (depth - near) : (far - near))) : (*unresolved));
return depth;
}
inline lreal march_ray(quat o, quat d, lreal near, lreal far, lmask live, julia_params jp,
int z_resolution, int post_steps, int max_steps, lmask *status,
lmask *samples, lmask *flags, lreal *width, lreal *unresolved)
{
de_march m = de_start(near, live);
quat away = ((real4)(((lreal)((real)4 * sqrt((jp).bailout2))), ((lreal)0), ((lreal)0), ((lreal)0)));
for (int i = 0; i < max_steps && (m.active); ++i) {
de_leave(&m, i, far, samples);
lmask escaped;
lreal dist = julia_distance_formula(((m.active) ? (((o) + (m.t) * (d))) : (away)), jp, &escaped);
de_advance(&m, i, dist, escaped, jp.epsilon, samples, flags);
}
lmask todo = de_close(&m, live, max_steps, status, samples, flags);
lreal w;
lreal a = refine_bracket(o, d, m.t_prev, m.t, todo, post_steps, jp, &w);
return de_depth(&m, a, w, near, far, live, width, unresolved);
}
inline quat normal_along(quat p, julia_params jp, real4 right, real4 up, real4 forward, lmask *guard)
{
quat q = (p);
quat j0 = (((real4)(((lreal)((right).x)), ((lreal)((right).y)), ((lreal)((right).z)), ((lreal)((right).w)))));
quat j1 = (((real4)(((lreal)((up).x)), ((lreal)((up).y)), ((lreal)((up).z)), ((lreal)((up).w)))));
quat j2 = (((real4)(((lreal)((forward).x)), ((lreal)((forward).y)), ((lreal)((forward).z)), ((lreal)((forward).w)))));
real4 c = (jp.c);
lmask live = 1;
for (int n = 0; n < jp.max_iter && (live); ++n) {
lreal m2 = (((q)).x * ((q)).x + ((q)).y * ((q)).y + ((q)).z * ((q)).z + ((q)).w * ((q)).w);
live &= m2 <= jp.bailout2;
lmask tiny = live & (m2 < sqrt(FLT_MIN));
*guard |= ((tiny) ? ((lmask)2) : ((lmask)0));
live &= !tiny;
if (!(live))
break;
j0 = ((live) ? (julia_f_jvp(q, j0)) : (j0));
j1 = ((live) ? (julia_f_jvp(q, j1)) : (j1));
j2 = ((live) ? (julia_f_jvp(q, j2)) : (j2));
q = ((live) ? (julia_f(q, c)) : (q));
lreal s2 = fmax((((j0)).x * ((j0)).x + ((j0)).y * ((j0)).y + ((j0)).z * ((j0)).z + ((j0)).w * ((j0)).w), fmax((((j1)).x * ((j1)).x + ((j1)).y * ((j1)).y + ((j1)).z * ((j1)).z + ((j1)).w * ((j1)).w), (((j2)).x * ((j2)).x + ((j2)).y * ((j2)).y + ((j2)).z * ((j2)).z + ((j2)).w * ((j2)).w)));
lmask rescale = ((live) & (((s2) > (real)1e24) | (((s2) < (real)1e-24) & ((s2) > (real)0))));
if ((rescale)) {
lreal inv = (real)1 / sqrt(s2);
j0 = ((rescale) ? (((inv) * (j0))) : (j0));
j1 = ((rescale) ? (((inv) * (j1))) : (j1));
j2 = ((rescale) ? (((inv) * (j2))) : (j2));
}
}
return ((real4)(((((q)).x * ((j0)).x + ((q)).y * ((j0)).y + ((q)).z * ((j0)).z + ((q)).w * ((j0)).w)), ((((q)).x * ((j1)).x + ((q)).y * ((j1)).y + ((q)).z * ((j1)).z + ((q)).w * ((j1)).w)), ((((q)).x * ((j2)).x + ((q)).y * ((j2)).y + ((q)).z * ((j2)).z + ((q)).w * ((j2)).w)), ((lreal)0)));
}
inline void to_camera_unit(quat a, lmask *guard, lreal *nx, lreal *ny, lreal *nz)
{
real4 n = (real4)(a.x, a.y, -a.z, 0);
real l = length(n);
int ok = l > (real)0 && isfinite(l);
n = ok ? n / l : (real4)(0, 0, 1, 0);
*nx = n.x, *ny = n.y, *nz = n.z;
*guard |= ((ok) ? ((lmask)0) : ((lmask)1));
}
__kernel void normals_jacobian(const int n_items, __global const real4 *point, __global const int *status,
const real4 c, const int max_iter, const real bailout,
const real4 right, const real4 up, const real4 forward,
__global real4 *normal, __global int *flags)
{
size_t i0 = get_global_id(0) * 1;
julia_params jp = { c, bailout * bailout, 0, max_iter };
do { int hit_ = (i0) < (size_t)(n_items) && (status)[i0] == 1; if (!(hit_)) { if ((i0) < (size_t)(n_items)) normal[i0] = (real4)(0); return; } if ((i0) >= (size_t)(n_items)) return; if (!hit_) { normal[i0] = (real4)(0); return; } } while (0);
int guard = 0;
real nx, ny, nz;
to_camera_unit(normal_along(point[i0], jp, right, up, forward, &guard), &guard, &nx, &ny, &nz);
normal[i0] = (real4)(nx, ny, nz, 0);
if (guard)
flags[i0] |= guard;
}
