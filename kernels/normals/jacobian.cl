/* normals/jacobian.cl: the analytic normal (Quilez (n.d.) "method 3", Quilez 2002).
 * The surface is the level set |q_n|^2 = bailout^2, so the normal is
 *     grad |q_n|^2 = 2 J^T q_n,   J_{k+1} = f'(q_k) J_k,  J_0 = I.
 * The rays see only the 3D space spanned by the camera's right, up and forward, so only
 * the gradient's components along them are needed:
 *     grad |q_n|^2 . v = 2 q_n . (J v),   (J v)_{k+1} = f'(q_k) (J v)_k,  (J v)_0 = v,
 * three directional derivatives carried forward through julia_f_jvp() instead of J's four
 * columns (3/4 of the work; the float64 twin takes the whole gradient and projects it, so
 * the tests check the one against the other).  In the algebra's coordinates: (J v)_0 is
 * ALG_IN(v) (a linear map), and q . (J v) is ALG_DOT, the bilinear form of the algebra's
 * norm.  The derivatives are only needed up to a common scale, so they are rescaled
 * whenever they grow large: no overflow at any max_iter.  Returned as camera coordinates
 * (x right, y up, z towards the eye). */

#ifdef KIND_NORMAL
/* a kind with a normal of its own (kind/julia_stack.cl, kind/cubic_locus.cl: KIND_NORMAL names
 * its function, which returns the 4D gradient): its components along right, up, forward */
inline quat normal_along(quat p, julia_params jp, real4 right, real4 up, real4 forward, lmask *guard)
{
    quat g = KIND_NORMAL(p, jp, guard);
    return QUAT(QDOT_UNIFORM(g, right), QDOT_UNIFORM(g, up), QDOT_UNIFORM(g, forward), (lreal)0);
}
#else
#ifndef KIND_JVP_START   /* the Julia set's: q_0 = p, J_0 = I, q -> f(q) + c (a kind's piece may name its own) */
#define KIND_JVP_START(q, j0, j1, j2) real4 c = ALG_C(jp.c)
#define KIND_JVP_FIRST 0
#define KIND_JVP_STEP(q, j0, j1, j2, live) q = QSEL(q, julia_f(q, c), live)
#define KIND_JVP_RESCALE(inv, rescale)   /* nothing: a statement of its own where named (no ';' here) */
#endif
/* the gradient's components along right, up and forward, up to a common positive scale */
inline quat normal_along(quat p, julia_params jp, real4 right, real4 up, real4 forward, lmask *guard)
{
    quat q = ALG_IN(p);
    quat j0 = ALG_IN(QUAT_UNIFORM(right));     /* J right, J up, J forward */
    quat j1 = ALG_IN(QUAT_UNIFORM(up));
    quat j2 = ALG_IN(QUAT_UNIFORM(forward));
    KIND_JVP_START(q, j0, j1, j2);   /* the kind's orbit and derivative start, and its state */
    lmask live = L_TRUE;
    for (int n = KIND_JVP_FIRST; n < jp.max_iter && L_ANY(live); ++n) {
        lreal m2 = ALG_NORM2(q);
        live &= m2 <= jp.bailout2;
        /* Inside points of c = 0 go to 0 like p^(2^n): q underflows to exactly 0 within a
         * few dozen iterations (float32 and float64 alike) and grad |q_n|^2 = 2 J^T q_n
         * with it, a zero normal on a hit (measured: every fixed-scan hit of c = 0 at
         * max_iter 100).  Stop while the next |q|^2 = m2^2 is still above REAL_MIN; for
         * c = 0 every |q_k|^2 has the same (radial) level sets, so the normal is exact.
         * For c away from 0 this needs q^2 + c to cancel below sqrt(REAL_MIN), i.e. an
         * exact hit of the critical point 0.  Counted (GUARD_JACOBIAN_TINY). */
        lmask tiny = live & (m2 < sqrt(REAL_MIN));
        *guard |= L_SEL((lmask)0, (lmask)GUARD_JACOBIAN_TINY, tiny);
        live &= !tiny;
        if (!L_ANY(live))
            break;
        j0 = QSEL(j0, julia_f_jvp(q, j0), live);
        j1 = QSEL(j1, julia_f_jvp(q, j1), live);
        j2 = QSEL(j2, julia_f_jvp(q, j2), live);
        KIND_JVP_STEP(q, j0, j1, j2, live);
        /* the largest derivative's squared length (sqrt is monotonic: sqrt(s2) is the largest
         * length); rescale both ways: J shrinks geometrically on orbits drawn to an attracting
         * cycle (inside points at max_iter 1000+) and would underflow to 0 in float32 */
        lreal s2 = fmax(QNORM2(j0), fmax(QNORM2(j1), QNORM2(j2)));
        lmask rescale = L_RESCALE_DUE(live, s2);
        if (L_ANY(rescale)) {
            lreal inv = (real)1 / sqrt(s2);
            j0 = QSEL(j0, QSCALE(inv, j0), rescale);
            j1 = QSEL(j1, QSCALE(inv, j1), rescale);
            j2 = QSEL(j2, QSCALE(inv, j2), rescale);
            KIND_JVP_RESCALE(inv, rescale)
        }
    }
    return QUAT(ALG_DOT(q, j0), ALG_DOT(q, j1), ALG_DOT(q, j2), (lreal)0);
}
#endif  /* KIND_NORMAL */

/* the gradient's components along (right, up, forward) -> camera coordinates (right, up,
 * -forward), normalised: (*nx, *ny, *nz).  Degenerate (zero: the orbit hit the critical point
 * 0 exactly, e.g. an eye at 0 inside the set; or non-finite): the view axis (0, 0, 1),
 * flagged GUARD_NORMAL_FALLBACK, never a zero normal on a hit. */
inline void to_camera_unit(quat a, lmask *guard, lreal *nx, lreal *ny, lreal *nz)
{
#if LANES == 1
    real4 n = (real4)(a.x, a.y, -a.z, 0);
    real l = length(n);
    int ok = l > (real)0 && isfinite(l);
    n = ok ? n / l : (real4)(0, 0, 1, 0);
    *nx = n.x, *ny = n.y, *nz = n.z;
#else
    lreal x = a.x, y = a.y, z = -a.z;
    lreal m = fmax(fabs(x), fmax(fabs(y), fabs(z)));   /* scaled first, as length() does */
    x /= m, y /= m, z /= m;
    lreal l = sqrt(x * x + y * y + z * z);
    lmask ok = (m > (real)0) & isfinite(m) & isfinite(l);
    *nx = select((lreal)0, x / l, ok);
    *ny = select((lreal)0, y / l, ok);
    *nz = select((lreal)1, z / l, ok);
#endif
    *guard |= L_SEL((lmask)GUARD_NORMAL_FALLBACK, (lmask)0, ok);
}

/* LANES hit points per work-item (common/lanes.cl), like the march.  Each hit's guard flags are
 * ORed into its flags word (the march's flags buffer, as the float64 twin's ``guard``): the
 * host counts them there, and reads no normal it does not keep. */
PACKET_KERNEL void normals_jacobian(const int n_items, __global const real4 *point, __global const int *status,
                               const real4 c, const int max_iter, const real bailout,
                               const real4 right, const real4 up, const real4 forward,
                               __global real4 *normal, __global int *flags)
{
    size_t i0 = get_global_id(0) * LANES;
    julia_params jp = { c, bailout * bailout, 0, max_iter };
#if LANES == 1
    HITS_ONLY(i0, n_items, status, normal[i0] = (real4)(0));
    int guard = 0;
    real nx, ny, nz;
    to_camera_unit(normal_along(point[i0], jp, right, up, forward, &guard), &guard, &nx, &ny, &nz);
    normal[i0] = (real4)(nx, ny, nz, 0);
    if (guard)
        flags[i0] |= guard;
#else
    if (i0 >= (size_t)n_items)
        return;
    quat p;
    int any_hit = 0;
    for (int k = 0; k < LANES; ++k) {  /* gather; a miss or a lane past the end takes point 0 */
        size_t i = min(i0 + k, (size_t)n_items - 1);
        int hit = status[i] == STATUS_HIT;
        any_hit |= hit;
        real4 pk = hit ? point[i] : (real4)(0);
        SET_LANE_QUAT(p, k, pk);
    }
    lmask guard = 0;
    lreal nx = 0, ny = 0, nz = 0;
    if (any_hit)
        to_camera_unit(normal_along(p, jp, right, up, forward, &guard), &guard, &nx, &ny, &nz);
    for (int k = 0; k < LANES && i0 + k < (size_t)n_items; ++k) {   /* scatter */
        size_t i = i0 + k;
        int hit = status[i] == STATUS_HIT;
        normal[i] = hit ? (real4)(LANE(nx, k), LANE(ny, k), LANE(nz, k), 0) : (real4)(0);
        int g = (int)MASK_LANE(guard, k);
        if (hit && g)
            flags[i] |= g;
    }
#endif
}
