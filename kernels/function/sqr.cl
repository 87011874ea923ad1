/* function_sqr.cl: the iterated function f(q) = q^2 + c (seed 000, eq. 1 and 4;
 * seed 003's "sqr").  An iterated function supplies three things:
 *   julia_f(q, c)      the map,
 *   julia_f_jvp(q, h)  its derivative along h (for the analytic Jacobian normal),
 *   JULIA_DF2(m2)      |f'(q)|^2 as a function of m2 = |q|^2, for the running
 *                      derivative of the distance estimate: |q'_{n+1}| = 2 |q_n| |q'_n|
 *                      because the quaternion norm is multiplicative. */

inline quat julia_f(quat q, real4 c) { return QADD_UNIFORM(alg_sqr(q), c); }

inline quat julia_f_jvp(quat q, quat h) { return alg_sqr_jvp(q, h); }

#define JULIA_DF2(m2) ((real)4 * (m2))
/* d = |q| ln|q| / (DEGREE |q'|) is seed 001's eq. 8 with the factor for degree 2. */
#define JULIA_DEGREE ((real)2)
