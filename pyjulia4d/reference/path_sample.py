"""Twin of kernels/path/sample.cl in float64 numpy, over arrays of rays: the
counter-based random numbers (bit for bit the kernels'), the orthonormal basis, the disc
and cosine maps, GGX and its Fresnel, the lobe share and the power heuristic.  Vectors are
(n, 3) arrays in camera coordinates; the formulas are the .cl file's docstring's.
"""
from __future__ import annotations

import numpy as np

PI = np.pi
ALPHA_MIN = 0.002


def path_mix(x) -> np.ndarray:
    """Wellons' lowbias32 on uint32 arrays (path/sample.cl path_mix)."""
    x = np.asarray(x, np.uint32).copy()
    x ^= x >> np.uint32(16)
    x *= np.uint32(0x7FEB352D)
    x ^= x >> np.uint32(15)
    x *= np.uint32(0x846CA68B)
    x ^= x >> np.uint32(16)
    return x


def _reverse(x) -> np.ndarray:
    """The 32 bits of each uint32 in reverse order (path/sample.cl path_reverse)."""
    x = np.asarray(x, np.uint32).copy()
    for shift, mask in ((1, 0x55555555), (2, 0x33333333), (4, 0x0F0F0F0F), (8, 0x00FF00FF)):
        s, m = np.uint32(shift), np.uint32(mask)
        x = ((x >> s) & m) | ((x & m) << s)
    return (x >> np.uint32(16)) | (x << np.uint32(16))


def _owen(x, seed) -> np.ndarray:
    """Burley's nested uniform scramble (path/sample.cl path_owen)."""
    x = _reverse(x)
    x = x + np.asarray(seed, np.uint32)
    for k in (0x6C50B47C, 0xB82F1E52, 0xC7AFE638, 0x8D22F6E6):
        x ^= x * np.uint32(k)
    return _reverse(x)


def _sobol1(i) -> np.ndarray:
    """The second dimension of Sobol's sequence (path/sample.cl path_sobol1)."""
    i = np.asarray(i, np.uint32)
    r, v = np.zeros_like(i), 0x80000000
    for k in range(32):
        r ^= np.where((i >> np.uint32(k)) & np.uint32(1), np.uint32(v), np.uint32(0))
        v ^= v >> 1
    return r


def _seed(pixel, pair: int) -> np.ndarray:
    """The seed of a pair of a pixel's dimensions (path/sample.cl path_seed)."""
    return path_mix(np.asarray(pixel, np.uint32) ^ path_mix(np.uint32((pair + 0x9E3779B9) & 0xFFFFFFFF)))


def _coord(i, seed, odd: int) -> np.ndarray:
    """Coordinate ``odd`` of a pair's point at the shuffled index i (path/sample.cl path_coord)."""
    x = _sobol1(i) if odd else _reverse(i)
    x = _owen(x, path_mix(seed ^ np.uint32(0x68BC21EB if odd else 0x02E5BE93)))
    return (x >> np.uint32(8)).astype(np.float64) / 16777216.0


def _index(s, seed) -> np.ndarray:
    """The sample index shuffled (path/sample.cl: path_owen(s, seed))."""
    return _owen(np.broadcast_to(np.asarray(s, np.uint64).astype(np.uint32), seed.shape), seed)


def path_rand(pixel, s, dim) -> np.ndarray:
    """Dimension ``dim`` of sample ``s`` of pixel ``pixel``: [0, 1), 24 bits; a pair of
    dimensions (2j, 2j + 1) is Owen-scrambled Sobol' over the samples (path/sample.cl)."""
    dim = int(dim)
    with np.errstate(over="ignore"):
        seed = _seed(pixel, dim >> 1)
        return _coord(_index(s, seed), seed, dim & 1)


def path_rand2(pixel, s, dim) -> tuple[np.ndarray, np.ndarray]:
    """Dimensions ``dim`` and dim + 1 (dim even) at once: path_rand's two (path/sample.cl path_rand2)."""
    dim = int(dim)
    with np.errstate(over="ignore"):
        seed = _seed(pixel, dim >> 1)
        i = _index(s, seed)
        return _coord(i, seed, 0), _coord(i, seed, 1)


def dot(a, b) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def unit(a) -> np.ndarray:
    aa = dot(a, a)
    ok = aa > 0
    return np.where(ok[..., None], a / np.sqrt(np.where(ok, aa, 1.0))[..., None], np.array([0.0, 0.0, 1.0]))


def basis(n):
    """path_basis: t, b with (t, b, n) orthonormal (Duff et al. 2017)."""
    sgn = np.where(n[:, 2] >= 0, 1.0, -1.0)
    a = -1.0 / (sgn + n[:, 2])
    c = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sgn * n[:, 0] ** 2 * a, sgn * c, -sgn * n[:, 0]], axis=-1)
    b = np.stack([c, sgn + n[:, 1] ** 2 * a, -n[:, 1]], axis=-1)
    return t, b


def local(n, x, y, z):
    t, b = basis(n)
    return x[:, None] * t + y[:, None] * b + z[:, None] * n


def disc(u1, u2):
    """Shirley & Chiu's concentric map (path_disc): (n, 2)."""
    a, b = 2 * u1 - 1, 2 * u2 - 1
    with np.errstate(divide="ignore", invalid="ignore"):
        wide = np.abs(a) > np.abs(b)
        r = np.where(wide, a, b)
        phi = np.where(wide, PI / 4 * (b / a), PI / 2 - PI / 4 * (a / b))
    zero = (a == 0) & (b == 0)
    return np.where(zero[:, None], 0.0, np.stack([r * np.cos(phi), r * np.sin(phi)], axis=-1))


def cosine(n, u1, u2):
    r, phi = np.sqrt(u1), 2 * PI * u2
    return local(n, r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1 - u1, 0)))


def ggx_d(nh, a2):
    k = nh * nh * (a2 - 1) + 1
    return a2 / (PI * k * k)


def ggx_g1(nx, a2):
    return 2 * nx / (nx + np.sqrt(a2 + (1 - a2) * nx * nx))


def schlick(f0, u):
    m = 1 - np.clip(u, 0, 1)
    return f0 + (1 - f0) * m ** 5


def ggx_half(n, a2, u1, u2):
    ct = np.sqrt((1 - u1) / (1 + (a2 - 1) * u1))
    st = np.sqrt(np.maximum(1 - ct * ct, 0))
    phi = 2 * PI * u2
    return local(n, st * np.cos(phi), st * np.sin(phi), ct)


def lum(c):
    return 0.2126 * c[..., 0] + 0.7152 * c[..., 1] + 0.0722 * c[..., 2]


def fresnel(base, metallic, f0s, u):
    """path/sample.cl fresnel: (n, 3), u (n,)."""
    fd = np.minimum(f0s * 25 * schlick(0.04, u), 1.0)[:, None]
    fm = schlick(base, u[:, None])
    return fd + (fm - fd) * metallic


def spec_share(base, metallic, f0s, nv):
    ks = lum(fresnel(base, metallic, f0s, nv))
    kd = (1 - metallic) * lum(base)
    with np.errstate(divide="ignore", invalid="ignore"):
        mid = np.clip(ks / (ks + kd), 0.1, 0.9)
    return np.where(kd <= 0, 1.0, np.where(ks <= 0, 0.0, mid))


def bsdf_eval(n, v, l, base, metallic, f0s, a2, p_spec):
    """(f cos, pdf): (n, 3) and (n,) (path/sample.cl bsdf_eval)."""
    nl, nv = dot(n, l), dot(n, v)
    ok = (nl > 0) & (nv > 0)
    f = (1 - metallic) * base / PI
    pdf = (1 - p_spec) * nl / PI
    h = unit(v + l)
    nh = np.maximum(dot(n, h), 0)
    vh = np.maximum(dot(v, h), 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = ggx_d(nh, a2)
        fr = fresnel(base, metallic, f0s, vh)
        spec = fr * (d * ggx_g1(nv, a2) * ggx_g1(nl, a2) / (4 * nv * nl))[:, None]
        f = f + np.where((p_spec > 0)[:, None], spec, 0.0)
        pdf = pdf + np.where(p_spec > 0, p_spec * d * nh / (4 * vh), 0.0)
    fc = np.where(ok[:, None], f * nl[:, None], 0.0)
    return fc, np.where(ok, pdf, 0.0)


def power_weight(a, b):
    a2, b2 = a * a, b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a2 + b2 > 0, a2 / (a2 + b2), 0.0)
