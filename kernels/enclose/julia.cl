/* enclose/julia.cl: the Julia set's orbit enclosures, after the algebra's enclosure piece
 * (enclose/ball.cl, enclose/split.cl), for march/proven.cl: the segment's points are q_0
 * (enc_segment), c is the scene's, and a point is outside when |q_n| > bailout at some
 * n = 0 .. max_iter (POV-Ray 3.6 documentation; iterate.cl julia_inside).  A kind with
 * orbits of its own has a piece of the same four names (enclose/mandelbrot.cl). */
#define ENC_STEPS(jp) ((jp).max_iter)

/* The escape ladder (march/proven.cl enc_ladder_of): where the map keeps norms to a power,
 * |f(q)| = |q|^D (quaternions, whose norm is multiplicative; the rotated map too), |f(q) + c|
 * >= |q|^D - |c|, so a point with |q_k| > rho_j, rho_0 = bailout and rho_j = (rho_{j-1} +
 * |c|)^(1/D), has |q_(k+j)| > bailout: an enclosure at iteration k that lies beyond
 * rho_(max_iter - k) proves its segment outside the truncated set there, iterations before
 * it would pass the bailout itself (the escape-radius argument of Douady and Hubbard's
 * dynamics of polynomials, counted in iterations). */
#if defined(ALG_LBOUND_IS_LEN) && defined(FUNC_POWER)
#define ENC_LADDER_POWER FUNC_POWER
#endif
/* A split algebra's components are complex orbits of their own, |a^D + c_a| >= |a|^D - |c_a|,
 * and |h| >= |a| / sqrt(2): a ladder per component from sqrt(2) bailout (enclose/split.cl
 * enc_outside_parts) */
#if defined(ALG_SPLIT) && defined(FUNC_POWER)
#define ENC_PART_LADDER_POWER FUNC_POWER
#endif

typedef real4 enc_param;

inline enclosure enc_start(quat o, quat d, lreal t0, lreal t1, julia_params jp, enc_param *p)
{
    *p = ALG_C(jp.c);
    return enc_segment(o, d, t0, t1);
}

inline enclosure enc_next(enclosure e, enc_param c, lmask live) { return enc_step(e, c, live); }
