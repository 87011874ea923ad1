"""float64 twin of kernels/enclose/split.cl: orbit enclosures of a ray segment in a split
algebra (the hypercomplex numbers), an affine form m + s v + B(r) (complex m, v; s in
[-1, 1]) for each idempotent component, pushed through f by Taylor's theorem (the powers by
products of forms, reference/enclose/caff.py caff_mul; the functions with f'' = +-f to second
order, FUNC_D2_SIGN),
    f(m + d) = f(m) + s f'(m) v + f'(m) e + R,  |R| <= rho^2 / 2 sup|f''|  (rho = |v| + r),
with the function's FUNC_M2 bound on |f''| over the disc of radius rho; where there is none
(the piece has no bound, or a pole or cut is in the disc), through cfun_disc on the
form's disc, tangent 0."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.enclose.caff import caff_add, caff_margin, caff_mul, caff_outside, caff_prefix
from pyjulia4d.reference.enclose.disc import enc_radius, least_norm, prefix_of, rounding


def caff_f(z, fn):
    power = getattr(fn, "FUNC_POWER", None)
    if power:   # the powers by products of forms, half of each s^2 term in the centre (enclose/split.cl)
        sq = caff_mul(z, z)
        return sq if power == 2 else caff_mul(sq, z)
    m, v, r = z
    with np.errstate(all="ignore"):
        rho = np.abs(v) + r
        if fn.FUNC_M2 is not None:
            fm, d1 = fn.cfun(m), fn.cfun_d(m)
            vn = d1 * v
            if fn.FUNC_D2_SIGN is not None:   # f'' = sign f: second order kept, s^2 split (enclose/split.cl)
                fa, va = np.abs(fm), np.abs(v)
                rn = np.abs(d1) * r * rounding().up + (
                    fa * (0.25 * va * va + (va + 0.5 * r) * r) + rho ** 3 * fn.FUNC_M2(m, rho) / 6) * rounding().up
                size = fa * (1 + va * va) + 4 * np.abs(vn)
                fm = fm + 0.25 * fn.FUNC_D2_SIGN * fm * (v * v)
            else:
                rn = np.abs(d1) * r * rounding().up + 0.5 * rho * rho * fn.FUNC_M2(m, rho) * rounding().up
                size = np.abs(fm) + 4 * np.abs(vn)
            if fn.FUNC_ROUND_GAIN is not None:
                size = size * fn.FUNC_ROUND_GAIN(m)
            rn = enc_radius(np.where(np.isnan(rn) | np.isnan(size), np.inf, rn), size, rounding().fn)
            bad = ~(rn < np.inf)
        else:
            fm, vn, rn = m, v, r
            bad = np.ones(np.shape(m), bool)
        if not bad.any():
            return fm, vn, rn
        wm, wr = fn.cfun_disc((m, enc_radius(rho, 0.0, rounding().sum)))
    return np.where(bad, wm, fm), np.where(bad, 0j, vn), np.where(bad, wr, rn)


def enc_add(x, y):
    """The sum of two forms in the same s, per component (enclose/split.cl)."""
    return tuple(caff_add(a, b) for a, b in zip(x, y))


def enc_shift(e, k):
    """The form plus a constant k in the algebra's coordinates (the components' (x, y), (z, w))."""
    out = []
    for (m, v, r), kk in zip(e, (complex(k[0], k[1]), complex(k[2], k[3]))):
        out.append((m + kk, v, enc_radius(r, np.abs(m) + abs(kk), rounding().sum)))
    return tuple(out)


def enc_segment(o, d, t0, t1, F):
    tm, hw = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    q = F.ALG_IN(o + tm[:, None] * d)
    v = F.ALG_IN(hw[:, None] * d)
    r = enc_radius(0.0, 2 * (np.linalg.norm(o, axis=-1) + np.abs(tm) * np.linalg.norm(d, axis=-1)), rounding().sum)
    return ((q[:, 0] + 1j * q[:, 1], v[:, 0] + 1j * v[:, 1], r), (q[:, 2] + 1j * q[:, 3], v[:, 2] + 1j * v[:, 3], r))


def enc_step(e, c, F):
    out = []
    for z, ck in zip(e, (complex(c[0], c[1]), complex(c[2], c[3]))):
        m, v, r = caff_f(z, F.fn)
        out.append((m + ck, v, enc_radius(r, np.abs(m) + abs(ck), rounding().sum)))
    return tuple(out)


def _joined(e):
    (am, av, ar), (bm, bv, br) = e
    m = np.stack([am.real, am.imag, bm.real, bm.imag], axis=-1)
    v = np.stack([av.real, av.imag, bv.real, bv.imag], axis=-1)
    return m, v, ar, br


def enc_outside(e, bailout2):
    m, v, ar, br = _joined(e)
    with np.errstate(all="ignore"):
        lo = least_norm(m, v) * (1 - rounding().sum) - np.hypot(ar, br)
        return (lo > 0) & (0.5 * lo * lo > bailout2)


def enc_prefix(e, bailout):
    """The part [-1, s] of the segment the forms keep outside the bailout (-1: none;
    kernels/enclose/split.cl)."""
    m, v, ar, br = _joined(e)
    return prefix_of(m, v, np.sum(m * m, axis=-1), np.sqrt(2.0) * bailout + np.hypot(ar, br))


def _centre_norm_extent(e):
    (am, av, ar), (bm, bv, br) = e
    with np.errstate(all="ignore"):
        hm = np.sqrt(0.5 * (np.abs(am) ** 2 + np.abs(bm) ** 2))
        ext = np.hypot(np.abs(av) + ar, np.abs(bv) + br) * 0.70710678118654752
    return hm, ext


def enc_margin(e, bailout):
    hm, ext = _centre_norm_extent(e)
    with np.errstate(all="ignore"):
        return (hm - bailout) / ext


def enc_gate(e, bailout):
    """Whether the forms may pass a test (kernels/enclose/split.cl enc_gate)."""
    hm, _ = _centre_norm_extent(e)
    m, v, ar, br = _joined(e)
    with np.errstate(all="ignore"):
        return (hm > bailout) | (np.sqrt(2.0) * (hm - bailout) + np.sqrt(np.sum(v * v, axis=-1)) > np.hypot(ar, br))


def enc_gate_parts(e, ta, tb):
    """Each component on its own (kernels/enclose/split.cl): |h| >= |a| / sqrt(2), so a form
    whose a-part clears ta (the ladder's radius for the iterations left) proves its points."""
    (am, _, _), (bm, _, _) = e
    return (np.abs(am) > ta) | (np.abs(bm) > tb)


def enc_outside_parts(e, ta2, tb2):
    return caff_outside(e[0], ta2) | caff_outside(e[1], tb2)


def enc_margin_parts(e, ta, tb):
    return np.fmax(caff_margin(e[0], ta), caff_margin(e[1], tb))


def enc_prefix_parts(e, ta, tb):
    return np.fmax(caff_prefix(e[0], ta), caff_prefix(e[1], tb))


def enc_hopeful(e, bailout):
    hm, ext = _centre_norm_extent(e)
    with np.errstate(all="ignore"):
        return ext < 2 * (hm + bailout)
