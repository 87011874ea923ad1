/* kind/level.cl: the level of an orbit that escaped before max_iter, for the level functions of
 * the kinds of set (kind/mandelbrot.cl, kind/julia_stack.cl, kind/cubic_locus.cl; iterate.cl
 * julia_level does the same for the default Julia set, its kernels left as they were): the
 * orbit's |q_n|^2 / b^2 = m2 / bailout2 carried on the k = max_iter - n steps it was not
 * iterated as (m2 / bailout2)^(D^k) - 1, D the map's growth, capped at 1e30 (k > 60 or an
 * exponent above 69: only the interpolation uses the value, never the inside test). */
inline lreal kind_level(lreal m2, real bailout2, lmask k, int growth)
{
    lreal e;
    if (growth == 2)   /* exact: a power of two */
        e = ldexp(log(m2 / bailout2), L_INT(min(k, 60)));
    else
        e = log(m2 / bailout2) * pow((lreal)growth, convert_lreal(min(k, 60)));
    return L_SEL(expm1(fmin(e, (real)69)), (lreal)1e30, (k > 60) | (e > (real)69));
}
