/* normals_jacobian.cl: the analytic normal (seed 004 "method 3", seed 002).
 * The surface is the level set |q_n|^2 = bailout^2, so the normal is
 *     grad |q_n|^2 = 2 J^T q_n,   J_{k+1} = f'(q_k) J_k,  J_0 = I,
 * with J carried column by column through julia_f_jvp().  The gradient is only
 * needed up to scale, so J is rescaled whenever it grows large: no overflow at
 * any max_iter.  The 4D gradient is projected onto the 3D space the rays span
 * and returned in camera coordinates (x right, y up, z towards the eye). */

inline real4 normal_jacobian(real4 p, julia_params jp, int *guard)
{
    real4 q = p;
    real4 j0 = (real4)(1, 0, 0, 0), j1 = (real4)(0, 1, 0, 0);
    real4 j2 = (real4)(0, 0, 1, 0), j3 = (real4)(0, 0, 0, 1);
    for (int n = 0; n < jp.max_iter; ++n) {
        real m2 = dot(q, q);
        if (m2 > jp.bailout2)
            break;
        /* Inside points of c = 0 go to 0 like p^(2^n): q underflows to exactly 0 within a
         * few dozen iterations (float32 and float64 alike) and grad |q_n|^2 = 2 J^T q_n
         * with it, a zero normal on a hit (measured: every fixed-scan hit of c = 0 at
         * max_iter 100).  Stop while the next |q|^2 = m2^2 is still above REAL_MIN; for
         * c = 0 every |q_k|^2 has the same (radial) level sets, so the normal is exact.
         * For c away from 0 this needs q^2 + c to cancel below sqrt(REAL_MIN), i.e. an
         * exact hit of the critical point 0.  Counted (GUARD_JACOBIAN_TINY). */
        if (m2 < sqrt(REAL_MIN)) {
            *guard |= GUARD_JACOBIAN_TINY;
            break;
        }
        j0 = julia_f_jvp(q, j0);
        j1 = julia_f_jvp(q, j1);
        j2 = julia_f_jvp(q, j2);
        j3 = julia_f_jvp(q, j3);
        q = julia_f(q, jp.c);
        real s = fmax(fmax(length(j0), length(j1)), fmax(length(j2), length(j3)));
        /* rescale both ways: J shrinks geometrically on orbits drawn to an attracting
         * cycle (inside points at max_iter 1000+) and would underflow to 0 in float32 */
        if (s > (real)1e12 || (s < (real)1e-12 && s > (real)0)) {
            s = (real)1 / s;
            j0 *= s; j1 *= s; j2 *= s; j3 *= s;
        }
    }
    return (real4)(dot(q, j0), dot(q, j1), dot(q, j2), dot(q, j3));
}

/* 4D vector -> camera coordinates (right, up, -forward), normalised.  Degenerate (zero:
 * the orbit hit the critical point 0 exactly, e.g. an eye at 0 inside the set; or
 * non-finite): the view axis (0, 0, 1), flagged GUARD_NORMAL_FALLBACK, never a zero
 * normal on a hit. */
inline real4 to_camera_unit(real4 g, real4 right, real4 up, real4 forward, int *guard)
{
    real4 n = (real4)(dot(g, right), dot(g, up), -dot(g, forward), 0);
    real l = length(n);
    if (l > (real)0 && isfinite(l))
        return n / l;
    *guard |= GUARD_NORMAL_FALLBACK;
    return (real4)(0, 0, 1, 0);
}

__kernel void normals_jacobian(const int n_items, __global const real4 *point, __global const int *status,
                               const real4 c, const int max_iter, const real bailout,
                               const real4 right, const real4 up, const real4 forward,
                               __global real4 *normal)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    if (status[i] != STATUS_HIT) {
        normal[i] = (real4)(0);
        return;
    }
    julia_params jp = { c, bailout * bailout, 0, max_iter };
    int guard = 0;
    real4 n = to_camera_unit(normal_jacobian(point[i], jp, &guard), right, up, forward, &guard);
    n.w = (real)guard;                /* guard flags ride in the unused w (real.cl) */
    normal[i] = n;
}
