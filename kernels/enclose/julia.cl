/* enclose/julia.cl: the Julia set's orbit enclosures, after the algebra's enclosure piece
 * (enclose/ball.cl, enclose/split.cl), for march/proven.cl: the segment's points are q_0
 * (enc_segment), c is the scene's, and a point is outside when |q_n| > bailout at some
 * n = 0 .. max_iter (POV-Ray 3.6 documentation; iterate.cl julia_inside).  A kind with
 * orbits of its own has a piece of the same four names (enclose/mandelbrot.cl). */
#define ENC_STEPS(jp) ((jp).max_iter)

typedef real4 enc_param;

inline enclosure enc_start(quat o, quat d, lreal t0, lreal t1, julia_params jp, enc_param *p)
{
    *p = ALG_C(jp.c);
    return enc_segment(o, d, t0, t1);
}

inline enclosure enc_next(enclosure e, enc_param c, lmask live) { return enc_step(e, c, live); }
