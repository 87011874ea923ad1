/* enclose/mandelbrot.cl (-D KIND_MANDELBROT with march.method = "proven"): the orbit
 * enclosures of a ray segment for the Mandelbrot kind (kind/mandelbrot.cl), after the
 * algebra's enclosure piece (enclose/ball.cl, enclose/split.cl), for march/proven.cl.
 *
 * The segment's points are the parameters c(s) = m + s v (in the algebra's coordinates,
 * enc_segment), and the orbit of each starts at q_1 = V + c(s) (V the critical or asymptotic
 * value, MANDEL_V_*; 0 for the powers), then q_{n+1} = f(q_n) + c(s).  So the form of c(s)
 * is kept beside the orbit's and added at every step (enc_add: the two share the symbol s,
 * so the orbit's tangent carries d q_n / ds in full), and f is pushed through the algebra's
 * own step at c = 0.  A point is outside when |q_n| > bailout at some n = 1 .. max_iter
 * (q_0 = 0 always is inside): ENC_STEPS, one fewer step than the Julia set's
 * (enclose/julia.cl, whose four names this piece gives instead). */
#define ENC_STEPS(jp) ((jp).max_iter - 1)

typedef enclosure enc_param;

inline enclosure enc_start(quat o, quat d, lreal t0, lreal t1, julia_params jp, enc_param *p)
{
    *p = enc_segment(o, d, t0, t1);
#ifdef MANDEL_V_X
    return enc_shift(*p, ALG_C((real4)((real)MANDEL_V_X, (real)MANDEL_V_Y, (real)MANDEL_V_Z, (real)MANDEL_V_W)));
#else
    return *p;
#endif
}

inline enclosure enc_next(enclosure e, enc_param p, lmask live)
{
    return enc_add(enc_step(e, (real4)(0), live), p);
}
