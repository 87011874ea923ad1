"""float64 twin of kernels/enclose/disc.cl: circular complex arithmetic (Gargantini and
Henrici's discs).  A disc is a pair (m, r) of a complex array and a float array, and holds
every z with |z - m| <= r; each operation returns a disc holding the image of its
arguments' discs.  The radii are raised by the kernel's rounding bounds for its precision
(rounding(): ENC_ROUND, ENC_ROUND_FN, ENC_UP; ENC_TINY), which in float64 are only generous:
the single-precision ones unless ``precision(True)`` says the kernel it mirrors is double."""
from __future__ import annotations

import contextvars
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Rounding:
    """kernels/enclose/disc.cl's rounding bounds in one precision: ``sum`` (ENC_ROUND, sums of
    products), ``fn`` (ENC_ROUND_FN, elementary functions), ``up`` (ENC_UP, a radius's own)."""
    sum: float
    fn: float
    up: float


SINGLE = Rounding(2.0 ** -22, 2.0 ** -20, 1.0 + 2.0 ** -18)
DOUBLE = Rounding(2.0 ** -50, 2.0 ** -48, 1.0 + 2.0 ** -46)
_ROUNDING = contextvars.ContextVar("pyjulia4d_enclosure_rounding", default=SINGLE)
ENC_TINY = 1e-30


def rounding() -> Rounding:
    """The bounds of the precision the twin mirrors now (SINGLE unless in ``precision(True)``)."""
    return _ROUNDING.get()


@contextmanager
def precision(double: bool):
    """Mirror a double-precision kernel's proofs (render.float = "double") inside the block."""
    token = _ROUNDING.set(DOUBLE if double else SINGLE)
    try:
        yield
    finally:
        _ROUNDING.reset(token)
ENC_PI = 3.14159274101257324
_INF = np.inf


def _err():
    return np.errstate(all="ignore")


def enc_radius(r, size, rel):
    """A radius raised for its own rounding and that of a centre of size ``size``."""
    with _err():
        out = np.asarray(r * rounding().up + rel * size + ENC_TINY, np.float64)
    return np.where(np.isnan(out), _INF, out)


def d_add_const(z, k):
    m, r = z
    return m + k, enc_radius(r, np.abs(m) + np.abs(k), rounding().sum)


def d_add(a, b):
    return a[0] + b[0], enc_radius(a[1] + b[1], np.abs(a[0]) + np.abs(b[0]), rounding().sum)


def d_neg(a):
    return -a[0], a[1]


def d_times_i(a):
    return 1j * a[0], a[1]


def d_times_minus_i(a):
    return -1j * a[0], a[1]


def d_mul(a, b):
    with _err():
        sa, sb = np.abs(a[0]), np.abs(b[0])
        return a[0] * b[0], enc_radius(sa * b[1] + sb * a[1] + a[1] * b[1], sa * sb, rounding().sum)


def d_sqr(a):
    with _err():
        s = np.abs(a[0])
        return a[0] * a[0], enc_radius((2 * s + a[1]) * a[1], s * s, rounding().sum)


def d_scale(k, a):
    s = abs(k)
    with _err():
        return k * a[0], enc_radius(s * a[1], s * np.abs(a[0]), rounding().sum)


def d_mean_value_sized(fm, r, lip, size):
    """f(m) and r times a bound ``lip`` on |f'| over the disc (infinite or NaN: no bound)."""
    with _err():
        rr = r * lip * rounding().up
    rr = np.where(np.isnan(rr) | (lip < 0), _INF, rr)
    return fm, enc_radius(rr, size, rounding().fn)


def d_mean_value(fm, r, lip):
    return d_mean_value_sized(fm, r, lip, np.abs(fm))


def d_taylor(fm, d1, r, m2):
    """Second order: |f'(z)| <= |f'(m)| + r sup|f''|, ``m2`` that bound on |f''|."""
    with _err():
        lip = d1 * (1 + rounding().fn) + ENC_TINY + r * m2 * rounding().up
    return d_mean_value(fm, r, lip)


def least_norm(m, v):
    """min |m + s v| over s in [-1, 1]."""
    vv = np.sum(v * v, axis=-1)
    with np.errstate(all="ignore"):
        s = np.clip(np.where(vv == 0, 0.0, -np.sum(m * v, axis=-1) / vv), -1, 1)
    return np.sqrt(np.sum((m + s[..., None] * v) ** 2, axis=-1))


PREFIX_DRAW = 2.0 ** -12   # the root drawn in towards -1 by this share of its distance (enclose/disc.cl)


def prefix_of(m, v, mm, reach):
    """The largest s in [-1, 1] with |m + s' v| (1 - ENC_ROUND) > reach for every s' in
    [-1, s] (a partial proof), -1 where none is found (kernels/enclose/disc.cl enc_prefix_of):
    the smaller root of |m + s v| = reach / (1 - ENC_ROUND), drawn in by PREFIX_DRAW, where
    the segment's start is outside, checked at s before the least's s."""
    vv, mv = np.sum(v * v, axis=-1), np.sum(m * v, axis=-1)
    with np.errstate(all="ignore"):
        rho2 = (reach / (1 - rounding().sum)) ** 2
        go = mm - 2 * mv + vv > rho2
        disc = mv * mv - vv * (mm - rho2)
        root = (-mv - np.sqrt(np.maximum(disc, 0.0))) / np.maximum(vv, np.finfo(np.float64).tiny)
        s = np.where((disc < 0) | (vv == 0), 1.0, np.fmin(np.fmax(root, -1.0), 1.0))
        s = -1 + (s + 1) * (1 - PREFIX_DRAW)
        lo = np.sqrt(np.sum((m + s[..., None] * v) ** 2, axis=-1)) * (1 - rounding().sum)
        return np.where(go & (s * vv <= -mv) & (lo > reach) & (s > -1), s, -1.0)


def taylor_disc(cfun, cfun_d, m2):
    """The disc enclosure of a function with a bound ``m2(m, rho)`` on |f''| over a disc:
    d_taylor with its own f and f' (kernels/enclose/disc.cl D_TAYLOR_OF)."""
    def cfun_disc(z):
        with _err():
            return d_taylor(cfun(z[0]), np.abs(cfun_d(z[0])), z[1], m2(z[0], z[1]))
    return cfun_disc


def d_exp(z):
    m, r = z
    with _err():
        return d_mean_value(np.exp(m), r, np.exp(m.real + r) * rounding().up)


def d_recip(z):
    """1/z: |1/z - 1/m| <= r / (|m| (|m| - r)) (a Moebius map); unbounded where 0 is in it."""
    m, r = z
    with _err():
        s = np.abs(m)
        gap = s - r * rounding().up
        rr = r / (s * gap) * rounding().up
        return 1 / m, enc_radius(np.where(gap > 0, rr, _INF), 1 / s, rounding().fn)


def d_meets_cut(z):
    """Whether the disc may meet the reals <= 0 (the principal log's and sqrt's cut)."""
    m, r = z
    return ((m.real <= r) & (np.abs(m.imag) <= r * rounding().up + ENC_TINY)) | (np.abs(m) <= r * rounding().up)


def d_log(z):
    """Principal log: |log'| <= 1 / (|m| - r); across the cut, the disc around Re in
    [ln(|m| - r), ln(|m| + r)], Im in [-pi, pi]."""
    m, r = z
    with _err():
        s = np.abs(m)
        gap = s - r * rounding().up
        lm = np.log(m)
        sm, sr = d_mean_value_sized(lm, r, 1 / gap, np.abs(lm) + 1)
        lo = np.log(gap) - rounding().fn * np.abs(np.log(gap))
        hi = np.log(s + r * rounding().up) + rounding().fn * np.abs(np.log(s + r))
        mid, hw = 0.5 * (lo + hi), 0.5 * (hi - lo)
        cr = enc_radius(np.hypot(hw, ENC_PI), np.abs(mid), rounding().fn)
    meets = d_meets_cut(z)
    out_r = np.where(meets, cr, sr)
    out_r = np.where(gap <= 0, _INF, out_r)
    return np.where(meets, mid + 0j, sm), out_r


def d_sqrt(z):
    """Principal sqrt: |sqrt'| <= 1 / (2 sqrt(|m| - r)); across the cut, the disc of
    radius sqrt(|m| + r) around 0."""
    m, r = z
    with _err():
        s = np.abs(m)
        gap = s - r * rounding().up
        sm, sr = d_mean_value(np.sqrt(m), r, 0.5 / np.sqrt(gap))
        big = enc_radius(np.sqrt(s + r), 0.0, rounding().fn) * rounding().up
    meets = d_meets_cut(z) | (gap <= 0)
    return np.where(meets, 0j, sm), np.where(meets, big, sr)


def d_pwr(z, p):
    """z^p = exp(p log z); a disc that meets the cut: the disc around both branches' images,
    exp(p L) and its turn by e^(-2 pi i p), L = log(-z) + i pi."""
    plain = d_exp(d_scale(p, d_log(z)))
    cut = d_meets_cut(z)
    if not cut.any():
        return plain
    wm, wr = d_log(d_neg(z))
    w = (wm + 1j * ENC_PI, enc_radius(wr, ENC_PI, rounding().sum))
    d1 = d_exp(d_scale(p, w))
    with _err():
        turn = np.exp(complex(2 * ENC_PI * p.imag, -2 * ENC_PI * p.real))
        m2, r2 = d_scale(turn, d1)
        r2 = enc_radius(r2, np.abs(m2), rounding().fn)
        mid = 0.5 * (d1[0] + m2)
        r = 0.5 * np.abs(d1[0] - m2) + np.maximum(d1[1], r2)
        both_r = enc_radius(r, np.abs(d1[0]) + np.abs(m2), rounding().sum)
    return np.where(cut, mid, plain[0]), np.where(cut, both_r, plain[1])


def least_cos2(a, b):
    """The least of cos^2 over [a, b] (0 where it may hold a zero of cos)."""
    with _err():
        k = np.ceil((a - 1.5707963267948966) * 0.31830988618379067 - 1e-4)
        zero = (k * ENC_PI + 1.5707963267948966 <= b + 1e-4 * (np.abs(b) + 1)) | (b - a >= 3.1415926)
        m = np.minimum(np.cos(a) ** 2, np.cos(b) ** 2) * (1 - rounding().fn) - rounding().fn
    return np.where(zero, 0.0, np.maximum(m, 0.0))


def least_sinh2(a, b):
    x = np.where((a <= 0) & (b >= 0), 0.0, np.minimum(np.abs(a), np.abs(b)))
    with _err():
        return np.sinh(x) ** 2 * (1 - rounding().fn)


def d_tanh(z):
    """|tanh'| = 1 / |cosh z|^2, |cosh z|^2 = sinh^2 x + cos^2 y, least over the disc's square;
    the centre's rounding scaled by (cosh 2x + 1) / |cosh 2x + cos 2y| near a pole."""
    m, r = z
    with _err():
        lip = 1 / (least_sinh2(m.real - r, m.real + r) + least_cos2(m.imag - r, m.imag + r))
        den = np.abs(np.cosh(2 * m.real) + np.cos(2 * m.imag))
        gain = (np.cosh(2 * m.real) + 1) / den
        fm = np.tanh(m)
        rr = r * lip * rounding().up
    rr = np.where(np.isnan(rr) | ~(gain < 1e6), _INF, rr)
    return fm, enc_radius(rr, np.abs(fm) * gain + 1, rounding().fn)


def d_tan(z):
    return d_times_minus_i(d_tanh(d_times_i(z)))


def d_asinh(z):
    """log(z + sqrt(z^2 + 1)) on the right half-plane (odd symmetry)."""
    m, r = z
    neg = m.real < 0
    w = (np.where(neg, -m, m), r)
    s = d_sqrt(d_add_const(d_sqr(w), 1.0))
    lm, lr = d_log(d_add(w, s))
    return np.where(neg, -lm, lm), lr


def d_atanh(z):
    a = d_log(d_add_const(z, 1.0))
    b = d_log(d_add_const(d_neg(z), 1.0))
    return d_scale(0.5, d_add(a, d_neg(b)))
