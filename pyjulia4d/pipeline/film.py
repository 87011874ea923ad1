"""What a path-traced render states about its picture (RenderResult.film): each pixel's
samples, the variance of its mean colour, the standard error of its mean luminance (the
stated noise) and the colour its first hits saw (the denoiser's albedo guide).  Made from
the moments both executors accumulate sample by sample (kernels/path/path.cl path_film:
Welford's running mean and squared deviations), so it needs no OpenCL.

A pixel's mean of n independent samples x_k has the standard error sqrt(s^2 / n), s^2 =
sum (x_k - mean)^2 / (n - 1) the unbiased sample variance: the RMS distance of the mean
from the picture of infinitely many samples, which benchmarks/accuracy/path_noise.py
checks against a converged reference (tests/accuracy/test_path_light.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pyjulia4d.pipeline.backdrop import put_behind

LUMA = np.array([0.2126, 0.7152, 0.0722])   # linear Rec. 709 luminance (path/sample.cl path_lum)


@dataclass
class Film:
    """(H, W[, 3]) arrays of a path-traced render's statistics."""
    paths: np.ndarray      # int32: samples taken per pixel (fewer than image.samples where image.noise stopped it)
    variance: np.ndarray   # float32 (H, W, 3): the variance of the mean, per channel; inf below two samples
    noise: np.ndarray      # float32 (H, W): the standard error of the mean luminance (sqrt of its variance)
    albedo: np.ndarray     # float32 (H, W, 3): the mean colour of each pixel's first hits (0 on a miss)
    noisy: np.ndarray | None = None   # image.denoise: the picture before the denoiser (the result's colour is after)
    covered: np.ndarray | None = None   # bool (H, W): pixels the set covers (some sample hit); None: all
    normal: np.ndarray | None = None    # float32 (H, W, 3): the mean first-hit normal (camera coordinates), a guide

    @classmethod
    def from_moments(cls, m2: np.ndarray, albedo: np.ndarray, count: np.ndarray, coverage=None) -> "Film":
        """From the squared deviations (H, W, 4: r, g, b, luminance), the albedo, the counts
        and the mean coverage (None: not known)."""
        n = count.astype(np.float64)[..., None]
        with np.errstate(divide="ignore", invalid="ignore"):
            var = np.where(n > 1, np.maximum(m2, 0.0) / (n * (n - 1)), np.inf)
        return cls(paths=count.astype(np.int32), variance=var[..., :3].astype(np.float32),
                   noise=np.sqrt(var[..., 3]).astype(np.float32), albedo=np.asarray(albedo[..., :3], np.float32),
                   covered=None if coverage is None else np.asarray(coverage) > 0)

    def noise_stats(self) -> dict[str, float]:
        """p50 / p99 / max of the stated noise over the pixels the set covers (the background's
        is 0: one colour), or over every pixel where nothing is covered."""
        keep = np.isfinite(self.noise)
        if self.covered is not None and self.covered.any():
            keep &= self.covered
        v = self.noise[keep].astype(np.float64)
        if v.size == 0:
            return {"p50": float("nan"), "p99": float("nan"), "max": float("nan")}
        p50, p99 = np.percentile(v, [50, 99])
        return {"p50": float(p50), "p99": float(p99), "max": float(v.max())}

    def header(self) -> str:
        """The header's pyjulia4d.noise entry: the stated noise's p50 and p99, the samples."""
        st = self.noise_stats()
        return (f"standard error of the mean luminance over the set's pixels p50 {st['p50']:.3g} "
                f"p99 {st['p99']:.3g} max {st['max']:.3g}; paths per pixel {int(self.paths.min())}-{int(self.paths.max())}")


DENOISE_EXTRA = "pip install 'pyjulia4d[denoise]'"


def check_denoiser(scene) -> None:
    """image.denoise asks a path-traced render for Open Image Denoise: its extra must be
    installed (one line naming it, before any render).  A direct render has no noise: the
    key is the path tracer's, ignored there like its other keys."""
    if scene.image.denoise and scene.shading.integrator == "path":
        from pyjulia4d.resources import module_installed
        from pyjulia4d.scene.checks import SceneError
        if not module_installed("pyoidn"):
            raise SceneError("image.denoise", f"needs Intel's Open Image Denoise, which is not installed: {DENOISE_EXTRA}")


def denoise(color: np.ndarray, albedo: np.ndarray, normal: np.ndarray | None) -> np.ndarray:
    """Open Image Denoise's "RT" filter (Afra, "Intel Open Image Denoise", 2024) over the whole
    picture, linear HDR colour guided by the first hits' mean colour and the centre normal
    (camera coordinates, 0 off the set); the guides are not clean (albedo is a mean of
    samples, the normal aliased), so the filter prefilters them."""
    import pyoidn

    c = np.ascontiguousarray(np.maximum(np.nan_to_num(color, nan=0.0, posinf=0.0), 0), np.float32)
    a = np.ascontiguousarray(np.clip(albedo, 0, 1), np.float32)
    n = None if normal is None else np.ascontiguousarray(np.clip(np.nan_to_num(normal), -1, 1), np.float32)
    return np.asarray(pyoidn.denoise(c, a, n, hdr=True, quality="high"), np.float32)


def guide_normal(result) -> np.ndarray | None:
    """The denoiser's normal guide: the film's mean first-hit normal (antialiased, like its
    albedo: guides that agree with each other and with the picture), else the centre normal."""
    return result.film.normal if result.film.normal is not None else result.normal


def finish(result, scene) -> None:
    """What a picture gets once it is whole (a render, or a cluster's joined tiles): a
    path-traced one with image.denoise the denoised colour, the picture before it kept in the
    film; then any picture its backdrop (backdrop.put_behind)."""
    if result.film is not None and scene.image.denoise and result.color is not None:
        result.film.noisy = result.color
        result.color = denoise(result.color, result.film.albedo, guide_normal(result))
    put_behind(result, scene)


def join(parts: dict, height: int, width: int) -> Film | None:
    """The films of a frame's tiles ((x0, y0, w, h) -> RenderResult) as one."""
    films = {r: p.film for r, p in parts.items()}
    if any(f is None for f in films.values()):
        return None
    out = Film(paths=np.zeros((height, width), np.int32), variance=np.zeros((height, width, 3), np.float32),
               noise=np.zeros((height, width), np.float32), albedo=np.zeros((height, width, 3), np.float32))
    covered = all(f.covered is not None for f in films.values())
    out.covered = np.zeros((height, width), bool) if covered else None
    normal = all(f.normal is not None for f in films.values())
    out.normal = np.zeros((height, width, 3), np.float32) if normal else None
    for (x0, y0, w, h), f in films.items():
        for name in ("paths", "variance", "noise", "albedo") + (("covered",) if covered else ()) + \
                    (("normal",) if normal else ()):
            getattr(out, name)[y0:y0 + h, x0:x0 + w] = getattr(f, name)
    return out


def merge(a: tuple, b: tuple) -> tuple:
    """Two batches of the same picture's paths, each (colour (H, W, 3), coverage (H, W),
    Film), as one: the pooled mean and squared deviations (Chan, Golub & LeVeque, "Algorithms
    for computing the sample variance", 1983, eq. 2.1b: M2 = M2a + M2b + d^2 na nb / n)."""
    (ca, aa, fa), (cb, ab, fb) = a, b
    na = fa.paths.astype(np.float64)[..., None]
    nb = fb.paths.astype(np.float64)[..., None]
    n = na + nb
    wa, wb = np.where(n > 0, na / np.maximum(n, 1), 0), np.where(n > 0, nb / np.maximum(n, 1), 0)

    def m2(var, k):
        return np.where(k > 1, np.nan_to_num(var.astype(np.float64), posinf=0.0) * k * (k - 1), 0.0)

    d = cb.astype(np.float64) - ca
    color = ca + d * wb
    m2c = m2(fa.variance, na) + m2(fb.variance, nb) + d * d * na * nb / np.maximum(n, 1)
    dl = d @ LUMA
    m2l = (m2(fa.noise[..., None] ** 2, na) + m2(fb.noise[..., None] ** 2, nb))[..., 0] + dl * dl * (na * nb / np.maximum(n, 1))[..., 0]
    alpha = aa * wa[..., 0] + ab * wb[..., 0]
    albedo = fa.albedo * wa + fb.albedo * wb
    film = Film.from_moments(np.concatenate([m2c, m2l[..., None]], axis=-1), albedo, n[..., 0].astype(np.int32),
                             alpha)
    if fa.normal is not None and fb.normal is not None:
        film.normal = (fa.normal * wa + fb.normal * wb).astype(np.float32)
    return color.astype(np.float32), alpha.astype(np.float32), film
