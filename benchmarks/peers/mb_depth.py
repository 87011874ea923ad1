"""Mandelbulber2's depth per pixel, read from its 16-bit z-buffer PNG, for peer_error.py.

Debian's Mandelbulber2 2.20 writes its z-buffer only as a 16-bit PNG (it is built without
OpenEXR and TIFF), and there as v = floor(60000 ln(z / zmin) / ln(zmax / zmin)), 65535 for a
miss, where zmin and zmax are the image's own nearest and farthest depths and are not written
anywhere (its src/file_image.cpp, ImageFileSavePNG::SavePNG).  z is the distance along the
ray from the camera (opencl/engines/ray_recursion.cl RayMarching: ``depth = scan`` over a unit
direction).  So this module puts two objects of known depth into the scene:

* a small sphere whose nearest point lies at T_NEAR of the camera's distance to the set's
  bounding ball, centred on pixel (0, 0)'s ray: nearer than any point of the set, so it
  makes zmin;
* an empty sphere centred at the camera, of radius the camera's distance to the ball plus
  the ball's diameter and a margin: every ray that misses the set ends on it, at the same
  depth, which makes zmax.  Its distance inside is R - |p - camera|, far above the set's
  estimate wherever that is small, so it changes no ray's march to the set.

Where each ray stops on them is known: Mandelbulber2 marches until the estimate falls below
its threshold, then bisects to a point whose estimate lies in (0.999 thr, thr) (RayMarching's
final binary search, searchLimit = 1 - 0.001 detail_level).  A sphere's distance is exact, and
pixel (0, 0)'s ray meets its sphere head-on as the empty sphere's rays meet theirs, so each
stops at t with |surface - t| = thr(t): at t = T / (1 + q) with the default threshold
thr = |p - camera| fov / (height detail_level) (opencl/engines/calculate_distance.cl
CalcDistThresh, q = fov / (height detail_level)), at t = T - thr with a constant one, to
within 5e-4 thr.  Decoding takes each pixel's v at the middle of its step, (v + 0.5) / 60000,
a relative error of at most ln(zmax / zmin) / 120000 (about 2e-5 here, 0.01 of a pixel's
footprint).  Pixels on the two spheres are misses.

Mandelbulber2's pixel (x, y) looks along screen point (x / width - 0.5, y / height - 0.5)
(opencl/engines/full_engine.cl), half a pixel up and left of the pixel centres pyjulia4d and
POV-Ray trace, so its depths are compared with the truth along its own rays (``mb_rays``).

``check`` renders a third sphere, in the set's depth range, and compares every pixel on it
with the exact depth where a ray meets that sphere grown by the threshold: it tests the
decoding, the rays and the stop rule together; peer_error.py runs it before it trusts a row.
"""
from __future__ import annotations

import math
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from benchmarks.peers import peers

# Mandelbulber2's OpenCL path (PoCL) at its default threshold (detail_level 1: one pixel's
# footprint), finer and coarser ones, and constants from 1e-3 (pyjulia4d's march.epsilon) down:
# it stops where its estimate falls below the threshold, which on these scenes lies several
# thresholds in front of the truncated set's surface (its estimate is low there by about 5x);
# name -> (detail_level, constant threshold or None)
ROWS = {"Mandelbulber2 OpenCL, detail 0.5": (0.5, None),
        "Mandelbulber2 OpenCL, detail 1 (default)": (1.0, None),
        "Mandelbulber2 OpenCL, detail 2": (2.0, None),
        "Mandelbulber2 OpenCL, detail 4": (4.0, None),
        "Mandelbulber2 OpenCL, threshold 1e-3": (1.0, 1e-3),
        "Mandelbulber2 OpenCL, threshold 1e-4": (1.0, 1e-4),
        "Mandelbulber2 OpenCL, threshold 1e-5": (1.0, 1e-5)}
# Mandelbulber2 renders pyjulia4d's scene (peers.mb_settings: N and bailout are its max_iter and
# escape radius), not POV-Ray's (whose import keeps POV-Ray's own iteration count and bailout):
# these scenes are pyjulia4d's matched scene, with these overrides, and pyjulia4d's rows are
# rendered again on them (no comma in a name: peer_error.py's --scenes is split at commas)
SCENES = {"matched (Mandelbulber2's set)": [], "max_iter 20 (Mandelbulber2's set)": ["fractal.max_iter=20"]}

T_NEAR = 0.75       # the near sphere's front, as a share of the camera's distance to the ball
R_NEAR = 1e-3       # its radius, as a share of that distance: a pixel or two on screen
STOP = 0.9995       # the stop's estimate, as a share of the threshold: the middle of (0.999, 1)
MIN_HEIGHT = 96     # below, the check sphere covers too few pixels to check anything


def mb_rays(scene, w: int, h: int) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), unit directions (h w, 3)) of Mandelbulber2's pixel rays, row-major, row
    0 on top: pyjulia4d's pinhole camera (geometry/camera.py) through screen point (x / w,
    y / h) instead of the pixel centre ((x + 0.5) / w, (y + 0.5) / h)."""
    from pyjulia4d.geometry.camera import camera_frame

    f = camera_frame(scene)
    y, x = np.mgrid[0:h, 0:w]
    u = (2 * x.ravel() / w - 1) * f.tan_half_fov * (w / h)
    v = (1 - 2 * y.ravel() / h) * f.tan_half_fov
    d = f.forward + u[:, None] * f.right + v[:, None] * f.up
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    if np.any(np.abs(d[:, 3]) > 1e-12) or abs(f.position[3]) > 1e-12:
        raise ValueError("the camera leaves the w = 0 slice: Mandelbulber2's 3D formula cannot render it")
    return np.asarray(f.position[:3], float), d[:, :3]


class Readout:
    """The reference spheres of one scene and threshold, and the decoding of its z-buffer.

    ``threshold``: None for Mandelbulber2's default (detail_level ``detail``), else its
    constant DE_thresh."""

    def __init__(self, scene, w: int, h: int, detail: float = 1.0, threshold: float | None = None):
        from pyjulia4d.geometry.camera import march_radius

        self.w, self.h, self.detail, self.threshold = w, h, detail, threshold
        self.eye, self.dirs = mb_rays(scene, w, h)
        self.fov = 2 * math.tan(math.radians(scene.camera.fov) / 2)   # Mandelbulber2's fov (peers.py)
        ball = march_radius(scene)
        gap = float(np.linalg.norm(self.eye)) - ball
        if gap <= 0:
            raise ValueError("the camera is inside the set's bounding ball: no room for the near sphere")
        self.t_near, self.r_near = T_NEAR * gap, R_NEAR * gap
        self.r_far = gap + 2 * ball + 0.5
        self.z_min, self.z_max = self.stop(self.t_near), self.stop(self.r_far)

    def threshold_at(self, t):
        """Mandelbulber2's threshold at depth t: t fov / (height detail_level), or the constant."""
        return t * self.fov / (self.h * self.detail) if self.threshold is None else self.threshold

    def stop(self, t: float) -> float:
        """Where a ray stops on an exact surface it meets head-on at depth t: s = t - STOP
        threshold_at(s), which is linear in s."""
        if self.threshold is None:
            return t / (1 + STOP * self.threshold_at(1.0))
        return t - STOP * self.threshold

    def primitives(self, check: tuple[np.ndarray, float] | None = None) -> str:
        """Settings lines for the two spheres (and a check sphere: (centre, radius))."""
        def vec(p) -> str:   # pyjulia4d (x, y, z) -> Mandelbulber2 (x, z, y), as peers.py
            return f"{float(p[0])!r} {float(p[2])!r} {float(p[1])!r}"

        near = self.eye + (self.t_near + self.r_near) * self.dirs[0]
        spheres = [(near, self.r_near, False), (self.eye, self.r_far, True)]
        if check is not None:
            spheres.append((check[0], check[1], False))
        out = []
        for i, (c, r, empty) in enumerate(spheres, 1):
            out += [f"primitive_sphere_{i}_enabled true;", f"primitive_sphere_{i}_position {vec(c)};",
                    f"primitive_sphere_{i}_radius {float(r)!r};"]
            if empty:
                out.append(f"primitive_sphere_{i}_empty true;")
        out.append(f"view_distance_max {2 * self.r_far!r};")
        return "\n".join(out) + "\n"

    def threshold_override(self) -> str:
        """Mandelbulber2's --override items for this threshold."""
        return (f"detail_level={self.detail!r}" if self.threshold is None
                else f"constant_DE_threshold=1#DE_thresh={self.threshold!r}")

    def override(self) -> str:
        """The same with the z-buffer channel on."""
        return self.threshold_override() + "#optional_image_channels_enabled=1#zbuffer_enabled=1"

    def decode(self, v: np.ndarray) -> np.ndarray:
        """Depth per pixel (h, w) from the z-buffer PNG's values: +inf on a miss and on the
        two reference spheres."""
        v = np.asarray(v, np.float64)
        z = self.z_min * (self.z_max / self.z_min) ** ((v + 0.5) / 60000)
        far = v >= 65535
        # the empty sphere's pixels sit at z_max, the set's well inside; the near sphere's
        # below the ball's front
        far |= z > 0.5 * (self.z_max + float(np.linalg.norm(self.eye)))
        far |= z < self.t_near + 3 * self.r_near
        return np.where(far, np.inf, z)


def render_depth(readout: Readout, settings: str, over: str, tmp: Path,
                 check: tuple[np.ndarray, float] | None = None) -> np.ndarray:
    """Mandelbulber2's depth per pixel (h, w) of ``settings`` (peers.mb_settings' text) with
    the reference spheres added, run with ``over`` (its OpenCL or CPU switches)."""
    from PIL import Image

    src, stem = tmp / "mb_depth.fract", tmp / "mb_depth"
    src.write_text(settings.replace("[fractal_1]", readout.primitives(check) + "[fractal_1]", 1))
    zpng = tmp / "mb_depth_zbuffer.png"
    zpng.unlink(missing_ok=True)
    p = subprocess.run(["mandelbulber2", "--nogui", "--format", "png", "--res", f"{readout.w}x{readout.h}",
                        "--output", str(stem), "--override", over + "#" + readout.override(), str(src)],
                       capture_output=True, text=True, cwd=tmp, env=peers.mb_env(tmp), timeout=3600)
    if p.returncode != 0 or not zpng.exists():
        last = [ln for ln in (p.stdout + p.stderr).replace("\r", "\n").splitlines() if ln.strip()] or ["?"]
        raise RuntimeError(f"mandelbulber2 failed (exit {p.returncode}): {last[-1].strip()}")
    v = np.asarray(Image.open(zpng), dtype=np.float64)
    if v.shape != (readout.h, readout.w):
        raise RuntimeError(f"mandelbulber2 wrote a {v.shape[1]}x{v.shape[0]} z-buffer, not {readout.w}x{readout.h}")
    if v[0, 0] != 0:
        raise RuntimeError("the near reference sphere is not the nearest pixel: the camera or the rays differ")
    return readout.decode(v)


def check(readout: Readout, settings: str, over: str, tmp: Path) -> float:
    """The largest error of the decoded depth over the pixels of a check sphere in the set's
    depth range (top right of the image), against the exact depth where each pixel's ray
    meets that sphere grown by the threshold, in pixels' footprints; raises if that sphere
    covers fewer than 20 pixels."""
    k = readout.w - 1                       # the top-right pixel's ray
    t = float(np.linalg.norm(readout.eye))  # the ball's centre's distance
    r = t * min(0.1, max(0.04, 8 * readout.fov / readout.h))   # 8 pixels' footprint at least
    centre = readout.eye + (t + r) * readout.dirs[k]
    depth = render_depth(readout, settings, over, tmp, check=(centre, r)).ravel()
    # the ray meets the sphere grown by the threshold, |o + t d - c| = r + STOP thr(t); rays
    # that pass further than 2 r / 3 from its centre are left out, where the stop is
    # ill-conditioned
    oc = readout.eye - centre
    b = readout.dirs @ oc
    pixel = readout.fov / readout.h
    tt = -b - np.sqrt(np.maximum(b * b - (oc @ oc - r * r), 0))
    for _ in range(4):   # the grown radius depends on t with the default threshold
        disc = b * b - (oc @ oc - (r + STOP * readout.threshold_at(tt)) ** 2)
        tt = -b - np.sqrt(np.maximum(disc, 0))
    on = b * b - oc @ oc > -(2 * r / 3) ** 2   # the ray passes within 2 r / 3 of the centre
    rows = np.abs(depth[on] - tt[on]) / (tt[on] * pixel)
    if rows.size < 20:
        raise RuntimeError(f"the check sphere covers {rows.size} pixels: the camera or the rays differ")
    return float(rows.max())


@contextmanager
def scene_set(name: str):
    """peers.py's --set for scene ``name`` while the block runs (peers.mb_settings reads it)."""
    peers.SCENE_SET[:] = SCENES[name]
    try:
        yield
    finally:
        peers.SCENE_SET[:] = []


def peer_depths(name: str, scene, w: int, h: int, tmp: Path) -> tuple[dict, dict]:
    """Mandelbulber2's OpenCL rows of scene ``name``: ({row: its depth (h, w), +inf on a
    miss}, {row: the --override its timed runs take}), or two empty dicts, with a message,
    where its OpenCL does not start or the image is too small to check.  Each depth is read
    through the reference spheres (``render_depth``) once ``check`` has passed to within 0.05
    of a pixel; it looks along ``mb_rays``.  The timed runs are peers.py's, without the
    spheres."""
    if h < MIN_HEIGHT:
        print(f"Mandelbulber2's rows skipped: its depth check needs {MIN_HEIGHT} pixels of height or more, "
              f"got {h}", file=sys.stderr)
        return {}, {}
    with scene_set(name):
        why = peers.mb_warm(w, h, tmp, peers.MB_OPENCL, True)
        if why:
            print(f"Mandelbulber2's OpenCL rows skipped: {why}", file=sys.stderr)
            return {}, {}
        settings = peers.mb_settings(w, h)
        depths, overs = {}, {}
        for k, (detail, threshold) in ROWS.items():
            ro = Readout(scene, w, h, detail, threshold)
            off = check(ro, settings, peers.MB_OPENCL, tmp)
            if off > 0.05:
                raise RuntimeError(f"{k}: the depth readout's check sphere is off by {off:.3f} of a pixel")
            depths[k] = render_depth(ro, settings, peers.MB_OPENCL, tmp)
            overs[k] = peers.MB_OPENCL + "#" + ro.threshold_override()
            if peers.mb_warm(w, h, tmp, overs[k], True):
                raise RuntimeError(f"{k}: Mandelbulber2's OpenCL did not start")
        return depths, overs


def cpu_seconds(name: str, w: int, h: int, tmp: Path, over: str) -> float:
    """Mandelbulber2's CPU seconds for scene ``name`` with ``over`` (peers.run_mandelbulber)."""
    with scene_set(name):
        return peers.run_mandelbulber(w, h, tmp, over)["cpu"]
