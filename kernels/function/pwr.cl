/* function/pwr.cl: f(z) = z^p = exp(p log z), f'(z) = p z^(p-1) (seed 003_8ca5f9108f52d3d6.txt,
 * the julia_fractal function "pwr(x, y)"; p = x + iy is fractal.exponent, compiled in as
 * -D FUNC_EXPONENT_RE/IM), on a complex lane value (algebra/complex.cl).  An
 * algebra lifts it to 4D (algebra/hypercomplex.cl: on each idempotent component).
 */
#ifndef FUNC_EXPONENT_RE
#error "pwr needs -D FUNC_EXPONENT_RE and FUNC_EXPONENT_IM (build.fractal_defines)"
#endif
#define FUNC_EXPONENT C((lreal)(real)(FUNC_EXPONENT_RE), (lreal)(real)(FUNC_EXPONENT_IM))
inline cplx cfun(cplx z) { return c_pow(z, FUNC_EXPONENT); }
inline cplx cfun_d(cplx z) { return c_mul(FUNC_EXPONENT, c_pow(z, C((lreal)((real)(FUNC_EXPONENT_RE) - (real)1), (lreal)(real)(FUNC_EXPONENT_IM)))); }
