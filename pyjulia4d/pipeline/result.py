"""What a render returns (RenderResult): the image buffers, what the render cost, the
guards that fired and the certified depth bracket; made by the OpenCL executor
(executor.render) and by the float64 reference (reference.render) alike, so it needs no
OpenCL."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from pyjulia4d.pipeline.codes import GUARD_JACOBIAN_TINY, GUARD_NORMAL_FALLBACK, GUARD_SHELL_MISS, GUARD_ULP_STEP, STATUS_CAPPED, \
    STATUS_HIT
from pyjulia4d.pipeline.film import Film
from pyjulia4d.pipeline.workload import OUTPUTS
from pyjulia4d.scene.model import Scene

if TYPE_CHECKING:
    from pyjulia4d.pipeline.calibrate import Prediction


def stored_depth(depth: np.ndarray, bracket: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A double-precision render's depth and bracket as the float32 images keep them, the
    statement kept true: the depth rounded towards the camera (never past the first
    crossing's lower end) and the bracket widened by that rounding and rounded up, so
    [depth - unresolved, depth + bracket] still holds the crossing (rounded to nearest, the
    float32 depth of a render in double precision was off by up to half a spacing of t,
    more than the 1.9e-7 brackets it stated: 5.6e-7 measured on the hypercomplex
    reciprocal).  Single precision's arrays pass unchanged."""
    if depth.dtype == np.float32:
        return depth, bracket
    d64, b64 = depth.astype(np.float64), bracket.astype(np.float64)
    d32 = d64.astype(np.float32)
    with np.errstate(invalid="ignore"):   # inf - inf off the hits
        d32 = np.where(d32 > d64, np.nextafter(d32, np.float32(-np.inf)), d32)
        want = b64 + np.where(np.isfinite(d64), d64 - d32.astype(np.float64), 0.0)
    b32 = want.astype(np.float32)
    with np.errstate(invalid="ignore"):
        b32 = np.where(b32 < want, np.nextafter(b32, np.float32(np.inf)), b32)
    return d32, b32

@dataclass
class RenderResult:
    """Image buffers (row 0 at the top) and what the render cost."""
    # each array is None where the render was not asked to keep it (render(outputs=...))
    color: np.ndarray | None     # (H, W, 3) float32, background where missed
    alpha: np.ndarray | None     # (H, W) float32, 1 on a hit
    depth: np.ndarray | None     # (H, W) float32, distance along the unit 4D ray; +inf on a miss
    normal: np.ndarray | None    # (H, W, 3) float32, unit, camera coordinates; 0 on a miss
    position: np.ndarray | None  # (H, W, 4) float32, the 4D hit point; NaN on a miss
    status: np.ndarray | None    # (H, W) int32, STATUS_* per pixel
    samples: np.ndarray | None   # (H, W) int32, set tests (fixed) or estimates (de) before the hit
    bracket: np.ndarray = None   # (H, W) float32: the surface lies in [depth, depth + bracket]; +inf off hits
    # (H, W) float32: on a hit, how far in front of the depth the first segment the march did
    # not prove empty begins (kernels/march/proven.cl): the first crossing lies in [depth -
    # unresolved, depth + bracket]; on a miss, the width of the ray left unproven.  The fixed
    # and de marches prove nothing: all of it.
    unresolved: np.ndarray = None
    counts: dict = field(default_factory=dict)  # pixels by status: "miss", "hit", "capped" (all tiles)
    device_name: str = ""
    seconds: float = 0.0         # the whole render: set-up, build, kernels, read-back
    kernel_seconds: float = 0.0  # the kernels alone
    guards: dict = field(default_factory=dict)  # pixels each numerical guard fired on (count_guards)
    lanes: int = 1               # rays per work-item of the march (pyjulia4d/opencl/lanes.py)
    scene: Scene | None = None   # the scene as rendered: camera.fit resolved into the camera it chose
    march_method: str = ""       # the march that ran: "fixed", "de" or "proven" (the plan's)
    prediction: Prediction | None = None   # calibrate.py's, where a probe ran
    film: Film | None = None     # a path-traced render's samples, variance and stated noise (pipeline/film.py)
    backdrop: np.ndarray | None = None   # (H, W, 3) the gradient or image behind the set, where one is (pipeline/backdrop.py)
    motion_blur: str = ""        # a frame blurred over its shutter: how (pipeline/motion.py); "" for none
    fell_back: str = ""          # the devices that failed before this one took the render over (opencl/failures.py)

    def __repr__(self) -> str:
        h, w = next(a.shape[:2] for a in (self.color, self.depth, self.bracket, self.alpha) if a is not None)
        kept = [k for k in OUTPUTS if getattr(self, k) is not None]
        return (f"RenderResult({w}x{h}, {100 * self.hit_fraction:.1f}% hit, {self.seconds:.3f} s on "
                f"{self.device_name or '?'}, {self.lanes} rays per work-item, outputs {', '.join(kept)})")

    def save(self, path, header: dict | None = None) -> None:
        """Write the image: .png or .tif (colour and alpha) or .exr (the scene's EXR layout),
        atomically; the header gets the scene as rendered and this render's report, as the
        command line writes them (so ``pyjulia4d render`` of the file renders it again), and
        ``header``'s own text entries (output.check_header; not the pyjulia4d.* ones)."""
        from pyjulia4d.app.output import check_header, render_header, write_image
        own = check_header(header, reserved="pyjulia4d.")   # the render's own entries stay its own
        if self.scene is None:   # a result assembled without its scene: the report alone
            entries = self.report()[0]
        else:
            entries = render_header(self.scene, self)[0]
        write_image(path, self, {**entries, **own})

    def _repr_png_(self) -> bytes | None:
        """The picture, for notebooks (sRGB-encoded 8-bit RGBA)."""
        if self.color is None:
            return None
        import io

        from PIL import Image

        from pyjulia4d.pipeline.colormap import levels_u8
        rgb = levels_u8(self.color, srgb=True)   # the levels a written PNG has (app/output.py)
        a = levels_u8(self.alpha if self.alpha is not None else np.ones(rgb.shape[:2], np.float32), srgb=False)
        rgba = np.dstack([rgb, a])
        buf = io.BytesIO()
        Image.fromarray(rgba).save(buf, format="PNG")
        return buf.getvalue()

    @property
    def hit_fraction(self) -> float:
        total = sum(self.counts.values())
        if total:
            return self.counts.get("hit", 0) / total
        return float(np.mean(self.status == STATUS_HIT))

    def bracket_stats(self) -> dict[str, float]:
        """p50 / p99 / max of the certified bracket width over the pixels hit (march/refine.cl):
        each hit's surface crossing lies within its width behind its depth.  NaN when
        nothing was hit."""
        if self.bracket is None:
            return _percentiles(np.empty(0))
        # finite exactly on hits (march/march.cl), so this needs no status array
        return _percentiles(self.bracket[np.isfinite(self.bracket)])

    def error_stats(self) -> dict[str, float]:
        """p50 / p99 / max over the pixels hit of the depth error each states: its bracket
        behind the depth plus its unresolved reach in front (kernels/march/proven.cl).  NaN when
        nothing was hit."""
        if self.bracket is None or self.unresolved is None:
            return self.bracket_stats()
        hit = np.isfinite(self.bracket)
        return _percentiles((self.bracket[hit] + self.unresolved[hit]).astype(np.float64))

    def unresolved_counts(self) -> dict[str, int]:
        """Pixels whose ray the march left partly unproven: hits with space in front of the
        depth not proven empty, and misses with any of the ray unproven (where a thin part may
        hide); none for a render without the array."""
        if self.unresolved is None or self.bracket is None:
            return {"hit": 0, "miss": 0}
        hit = np.isfinite(self.bracket)
        open_ = self.unresolved > 0
        return {"hit": int(np.count_nonzero(open_ & hit)), "miss": int(np.count_nonzero(open_ & ~hit))}

    @property
    def proven(self) -> bool:
        """Whether the march proved the space it skipped empty (march.method "proven"); the
        fixed scan and the distance estimate prove nothing in front of their hits."""
        return self.march_method == "proven"

    def report(self, stated_p99: float | None = None) -> tuple[dict[str, str], str]:
        """What a render says about itself: (header entries for PNG/EXR, the tail of the
        closing line).  Capped rays, the guards that fired, the certified depth bracket and
        the error each pixel states (bracket plus the unresolved reach in front,
        kernels/march/proven.cl; p50/p99/max) and the pixels left unresolved are never
        hidden; with ``stated_p99`` (the bound a quality preset states) the line says whether
        this render's stated p99 error is within it."""
        if stated_p99 is not None and (isinstance(stated_p99, bool) or not isinstance(stated_p99, (int, float))
                                       or not 0 < stated_p99 < math.inf):
            from pyjulia4d.scene.checks import SceneError, show

            raise SceneError("stated_p99", f"expected None or a positive finite number, got {show(stated_p99)}")
        b = self.bracket_stats()
        e = self.error_stats()
        un = self.unresolved_counts()
        header = {
            "pyjulia4d.device": self.device_name,
            "pyjulia4d.rays_per_work_item": str(self.lanes),
            "pyjulia4d.render_seconds": "%.6f" % self.seconds,
            "pyjulia4d.capped_pixels": str(self.capped),
            "pyjulia4d.guards": " ".join(f"{k}={v}" for k, v in self.guards.items()),
            "pyjulia4d.depth_bracket": " ".join(f"{k}={v:.3g}" for k, v in b.items()),
            "pyjulia4d.depth_error": " ".join(f"{k}={v:.3g}" for k, v in e.items()),
            "pyjulia4d.space_proven": "yes" if self.proven else "no",
            "pyjulia4d.unresolved_pixels": f"hit={un['hit']} miss={un['miss']}",
        }
        if self.fell_back:
            header["pyjulia4d.device_failed"] = self.fell_back
        if self.motion_blur:
            header["pyjulia4d.motion_blur"] = self.motion_blur + "; depth, normals and errors: the middle moment's"
        fired = [f"{k} {v}" for k, v in self.guards.items() if v]
        tail = f", {self.capped} capped" if self.capped else ""
        tail += f"; guards fired: {', '.join(fired)}" if fired else ""
        def target(value: float) -> str:
            """Whether ``value`` is within the preset's target (nothing without one)."""
            if stated_p99 is None or math.isnan(value):
                return ""
            ok = value <= stated_p99
            header["pyjulia4d.preset_bound_met"] = "yes" if ok else "no"
            return (f" (within the preset's stated {stated_p99:.0e})" if ok else
                    f" (ABOVE the preset's stated {stated_p99:.0e}: parts of the set finer than the floor "
                    f"near the rays left space unproven in front of the hits; a finer preset proves more)")

        if self.proven:
            if not math.isnan(e["p99"]):
                tail += (f"; depth error p50 {e['p50']:.2g} p99 {e['p99']:.2g} max {e['max']:.2g}"
                         f"{target(e['p99'])}: the bracket (p99 {b['p99']:.2g}) plus, on {un['hit']} hits, the "
                         f"reach of the space left unproven in front")
            tail += (f"; {un['miss']} misses with unproven space, where a thin part may hide" if un["miss"]
                     else "; every miss proven empty")
        else:
            if not math.isnan(b["p99"]):
                tail += f"; depth bracket p50 {b['p50']:.2g} p99 {b['p99']:.2g} max {b['max']:.2g}{target(b['p99'])}"
            if un["hit"] or un["miss"]:
                tail += ("; the space in front of the hits is not proven empty (march.method=proven proves "
                         "it and states the whole error)")
        if self.film is not None:   # a path-traced picture states its noise as it states its depth error
            header["pyjulia4d.noise"] = self.film.header()
            n = self.film.noise_stats()
            lo, hi = int(self.film.paths.min()), int(self.film.paths.max())
            tail += (f"; noise p50 {n['p50']:.2g} p99 {n['p99']:.2g} (standard error of the mean luminance of "
                     f"the set's pixels, {lo if lo == hi else f'{lo}-{hi}'} paths per pixel)")
        return header, tail

    def brief(self, stated_p99: float | None = None) -> str:
        """The closing line's short tail (the full one behind --verbose: report): the rays
        capped, the depth error stated (or, for a march that proves nothing in front, the
        bracket and how to prove it), a path-traced picture's noise, and what to do where
        one is above the preset the user chose (``stated_p99``: its bound, None without one)."""
        e, b = self.error_stats(), self.bracket_stats()
        parts = [f"{self.capped} rays capped at march.max_steps"] if self.capped else []
        if self.proven and not math.isnan(e["p99"]):
            above = stated_p99 is not None and e["p99"] > stated_p99
            parts.append(f"depth error p99 {e['p99']:.2g}" + (
                f", above the preset's {stated_p99:.0e} (a finer march.quality proves more)" if above else ""))
        elif not self.proven and not math.isnan(b["p99"]):
            parts.append(f"depth bracket p99 {b['p99']:.2g}, the space in front not proven "
                         f"(march.quality=normal proves it)")
        if self.film is not None:
            n = self.film.noise_stats()
            lo, hi = int(self.film.paths.min()), int(self.film.paths.max())
            parts.append(f"noise p99 {n['p99']:.2g} at {lo if lo == hi else f'{lo}-{hi}'} paths per pixel")
        return "".join("; " + x for x in parts)

    @property
    def capped(self) -> int:
        """Pixels whose march ran into the step cap (counted, never hidden)."""
        if self.counts:
            return int(self.counts.get("capped", 0))
        return int(np.sum(self.status == STATUS_CAPPED))

    def exr_channels(self) -> dict[str, np.ndarray]:
        """The EXR channels of the outputs kept: RGBA, Z, Z.bracket and Z.unresolved, N.XYZ, P.XYZW."""
        f = np.float32
        ch = {}
        if self.color is not None:
            ch.update({"R": self.color[..., 0], "G": self.color[..., 1], "B": self.color[..., 2]})
        if self.alpha is not None:
            ch["A"] = self.alpha
        if self.depth is not None:
            ch["Z"] = self.depth
            if self.bracket is not None:
                ch["Z.bracket"] = self.bracket
            if self.unresolved is not None:
                ch["Z.unresolved"] = self.unresolved
        if self.normal is not None:
            for k, name in enumerate("XYZ"):
                ch[f"N.{name}"] = self.normal[..., k]
        if self.position is not None:
            for k, name in enumerate("XYZW"):
                ch[f"P.{name}"] = self.position[..., k]
        if self.film is not None:   # path-traced: the variance of each channel's mean, the noise, the albedo
            for k, name in enumerate("RGB"):
                ch[f"variance.{name}"] = self.film.variance[..., k]
                ch[f"albedo.{name}"] = self.film.albedo[..., k]
            ch["noise.Y"] = self.film.noise
            ch["paths.Y"] = self.film.paths
            if self.film.noisy is not None:   # image.denoise: R, G, B are the denoised picture
                for k, name in enumerate("RGB"):
                    ch[f"noisy.{name}"] = self.film.noisy[..., k]
        return {k: np.ascontiguousarray(v, dtype=f) for k, v in ch.items()}


def percentiles(values: np.ndarray, qs=(50, 99)) -> list[float]:
    """np.percentile's default (linear interpolation between the closest ranks) of ``values``
    at each of ``qs``, by np.partition: np.percentile imports numpy.ma on its first call,
    20-40 ms of every command's start-up."""
    v = np.ravel(values)
    pos = [q / 100 * (v.size - 1) for q in qs]
    ranks = sorted({r for p in pos for r in (math.floor(p), math.ceil(p))})
    part = np.partition(v, ranks)
    lo, hi = ([float(part[f(p)]) for p in pos] for f in (math.floor, math.ceil))
    return [a + (b - a) * (p - math.floor(p)) for a, b, p in zip(lo, hi, pos)]


def _percentiles(values: np.ndarray) -> dict[str, float]:
    """p50 / p99 / max of ``values``; NaN for none."""
    if values.size == 0:
        return {"p50": math.nan, "p99": math.nan, "max": math.nan}
    p50, p99 = percentiles(values)
    return {"p50": p50, "p99": p99, "max": float(values.max())}


def add_counts(total: dict[str, int], more: dict[str, int]) -> dict[str, int]:
    """Add ``more``'s pixel counts (by status, or by guard) into ``total``; returns it.  One
    render's tiles, one frame's cluster tiles and an animation's frames are summed by it."""
    for k, v in more.items():
        total[k] = total.get(k, 0) + v
    return total


def count_guards(status, depth, guard) -> dict[str, int]:
    """Pixels each numerical guard fired on (nothing clamped without being counted).
    ``guard`` holds the flags (kernels/common/codes.cl) of the march kernel's flags buffer ORed
    with those the normals kernels OR into it.  Guards are rare: one pass ORs
    every pixel's flags, and only the flags that fired anywhere are counted pixel by pixel."""
    status, guard = (np.asarray(a).ravel() for a in (status, guard))
    guard = guard.astype(np.int32, copy=False)
    fired_any = int(np.bitwise_or.reduce(guard)) if guard.size else 0
    zero = np.asarray(depth).ravel() == 0
    hit = status == STATUS_HIT if fired_any & (GUARD_NORMAL_FALLBACK | GUARD_JACOBIAN_TINY) or zero.any() else None

    def fired(flag, on=None):
        if not fired_any & flag:
            return 0
        m = (guard & flag) != 0
        return int(np.count_nonzero(m if on is None else m & on))

    return {
        # de step below the spacing of t raised to one ulp (march/de.cl): effective epsilon = ulp(t)
        "ulp_step": fired(GUARD_ULP_STEP),
        # normal replaced by the view axis: degenerate or non-finite gradient (normals_*.cl)
        "normal_fallback": fired(GUARD_NORMAL_FALLBACK, hit),
        # Jacobian iteration stopped before q_n underflowed to 0 (normals/jacobian.cl)
        "jacobian_tiny": fired(GUARD_JACOBIAN_TINY, hit),
        # de: within epsilon of the set by the estimate, yet no point inside: a miss (march/de.cl)
        "shell_miss": fired(GUARD_SHELL_MISS),
        # the hit is the eye itself, depth 0 (camera inside the set; shade.cl takes the view axis)
        "eye_hit": int(np.count_nonzero(hit & zero)) if hit is not None else 0,
    }
