"""The explorer's render loop, shared by the page (server.py) and the notebook (notebook.py).

- The latest request wins: a request replaces any that waits, and the render in progress
  is abandoned at its next tile (executor.render's ``on_progress`` raises Stale), so no queue
  of stale frames builds up behind a drag.
- While a control moves, one small preview per request, its size chosen from the speed of
  the last ones so that a preview takes about PREVIEW_SECONDS.
- At rest, progressive refinement: the preview, half size, the full size, then the full size
  with the scene's image.samples, each shown as it is done.  The last stage renders the scene
  exactly as given, so the picture at rest is the one ``pyjulia4d render`` makes of the saved
  scene on the same device.
- A path-traced scene (shading.integrator = "path") previews with the direct integrator while
  a control moves (at its speed), and at rest accumulates its paths in batches - 4, then
  doubling the total up to image.samples (path_batches) - each batch the next samples of the
  same sequence, pooled with the earlier (film.merge), shown with its stated noise and, where
  Open Image Denoise is installed, denoised.

Fractal artists know this from Mandelbulber2's navigator and Fragmentarium's progressive
refinement.  The loop knows nothing of the page: it calls ``render(scene, on_progress)`` and
hands each Picture to ``show``, each one-line error to ``fail``.
"""
from __future__ import annotations

import dataclasses
import io
import math
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from pyjulia4d.scene.checks import one_line
from pyjulia4d.scene.model import Scene

# A preview's aim (render time alone); the page asks at most one per frame of its display.
PREVIEW_SECONDS = 0.08
MIN_PREVIEW_PIXELS = 64 * 48
FIRST_RATE = 3e5          # pixels per second assumed before the first preview is timed


class Stale(Exception):
    """The render was overtaken by a newer request (raised inside on_progress)."""


@dataclass(frozen=True)
class Picture:
    """One finished stage: its PNG (8-bit sRGB, no alpha: misses show the background), the
    scene as rendered (camera.fit resolved), and the render's facts in words."""
    generation: int
    stage: str            # "preview", "refine" or "final"
    scene: Scene
    png: bytes
    facts: dict


def stages(scene: Scene, moving: bool, preview_pixels: float) -> list[tuple[str, Scene]]:
    """The renders one request makes: a preview of about ``preview_pixels`` pixels; at rest
    (``moving`` false) then half size and the full size, and the full size again with
    image.samples where that is above 1 (a path-traced scene: the preview, then its paths)."""
    w, h, s = scene.image.width, scene.image.height, scene.image.samples
    full = w * h
    k = min(1.0, math.sqrt(max(MIN_PREVIEW_PIXELS, preview_pixels) / full))

    def sized(f: float, samples: int = 1) -> Scene:
        # a path-traced scene's previews are the direct integrator's: today's speed while dragging
        return scene.replace(**{"image.width": max(1, round(w * f)), "image.height": max(1, round(h * f)),
                                "image.samples": samples, "image.adaptive": False, "shading.integrator": "direct"})

    if moving:   # one preview, finished even when the next request comes (RenderLoop)
        return [("preview", sized(k))]
    out = []
    if k < 1.0:
        out.append(("preview", sized(k)))
    # a half-size stage well above the preview's size; not before a path-traced picture's
    # first batch of paths, which replaces it about a second later
    if 0.25 * full > 1.5 * k * k * full and scene.shading.integrator == "direct":
        out.append(("refine", sized(0.5)))
    if (s > 1 or scene.image.adaptive) and scene.shading.integrator == "direct":
        out.append(("refine", sized(1.0)))
    out.append(("final", scene))
    return out


# the first batch of paths at rest: 2 per pixel, denoised, looked clean on the default scene
# and came 1.3 s after a change at 640x480 on the 2-core CPU (4 paths took 2.1 s:
# benchmarks/speed/explore_latency.py --rest-batches)
PATH_FIRST_BATCH = 2


def path_batches(samples: int) -> list[tuple[int, int]]:
    """(first sample, count) of each batch a path-traced picture at rest is refined in:
    PATH_FIRST_BATCH samples, then as many again as there are (the total doubling), up to
    ``samples``."""
    out, first, count = [], 0, PATH_FIRST_BATCH
    while first < samples:
        count = min(count, samples - first)
        out.append((first, count))
        first += count
        count = first
    return out


def shown_color(result: Any) -> np.ndarray:
    """What the page shows of a render: its colour, a path-traced one's denoised where Open
    Image Denoise is installed (film.denoise, guided by its normal where the stage kept it)."""
    from pyjulia4d.resources import module_installed
    if result.film is None or not module_installed("pyoidn"):
        return result.color
    from pyjulia4d.pipeline.film import denoise, guide_normal
    return denoise(result.color, result.film.albedo, guide_normal(result))


def picture_png(color: np.ndarray, scene: Scene | None = None) -> bytes:
    """(H, W, 3) linear colour -> PNG bytes, through the scene's exposure and tone map as the
    files have it (pipeline/tonemap.py), sRGB-encoded, fast zlib level (a local page)."""
    from PIL import Image

    from pyjulia4d.app.output import rgba_levels
    from pyjulia4d.pipeline.tonemap import display

    if scene is not None:
        color = display(color, scene.image.exposure, scene.image.tonemap)
    buf = io.BytesIO()
    Image.fromarray(rgba_levels(color, None)).save(buf, format="PNG", compress_level=1)
    return buf.getvalue()


def facts(result: Any, stage: str) -> dict:
    """What the page shows of a render: size, time, share hit, the depth bracket, the pixels
    left unresolved, capped rays and the guards that fired (result.report's words)."""
    header, _ = result.report()
    h, w = result.color.shape[:2]
    un = result.unresolved_counts()
    out = {"stage": stage, "size": f"{w}x{h}", "seconds": f"{result.seconds:.3f}",
            "hit": f"{100 * result.hit_fraction:.1f} %",
            "bracket": header["pyjulia4d.depth_bracket"] or "none hit",
            "error": (header["pyjulia4d.depth_error"] if result.proven else
                      "not stated: this march proves no space in front of its hits empty (quality "
                      "'normal' proves it)"),
            "unresolved": (f"{un['hit']} hits, {un['miss']} misses" if result.proven else "every ray"),
            "capped": str(result.capped),
            "guards": ", ".join(f"{k} {v}" for k, v in result.guards.items() if v) or "none",
            "device": result.device_name}
    if result.film is not None:   # a path-traced picture's stated noise and its paths
        n = result.film.noise_stats()
        lo, hi = int(result.film.paths.min()), int(result.film.paths.max())
        out["noise"] = f"p50 {n['p50']:.3g}, p99 {n['p99']:.3g}"
        out["paths"] = str(lo) if lo == hi else f"{lo}-{hi}"
    return out


class RenderLoop:
    """A worker thread rendering the latest request (see the module's docstring)."""

    def __init__(self, render: Callable[..., Any],
                 show: Callable[[Picture], None], fail: Callable[[str], None],
                 preview_seconds: float = PREVIEW_SECONDS) -> None:
        self._render, self._show, self._fail = render, show, fail
        self.preview_seconds = preview_seconds
        self.rate = FIRST_RATE
        self._cond = threading.Condition()
        self._pending: tuple[int, Scene, bool] | None = None
        self._generation = 0
        self._moving = False      # whether the newest request's control still moves
        self._closed = False
        self._thread = threading.Thread(target=self._run, name="pyjulia4d-explore", daemon=True)
        self._thread.start()

    def request(self, scene: Scene, moving: bool = False) -> int:
        """Render ``scene`` (replacing whatever waits or runs); returns its generation."""
        with self._cond:
            self._generation += 1
            self._pending = (self._generation, scene, bool(moving))
            self._moving = bool(moving)
            self._cond.notify()
            return self._generation

    @property
    def generation(self) -> int:
        return self._generation

    def close(self, timeout: float = 10.0) -> None:
        with self._cond:
            self._closed = True
            self._generation += 1
            self._cond.notify()
        self._thread.join(timeout)

    def _stop_if_stale(self, generation: int, stage: list[str]) -> Callable[[int, int], None]:
        """on_progress for the stages of ``generation``: Stale once a newer request came, except
        that a preview is finished while the newer one is a preview too - a drag sends
        requests faster than previews render, and cancelling each would show none."""
        def check(done: int, total: int) -> None:
            if self._generation != generation and not (stage[0] == "preview" and self._moving):
                raise Stale()
        return check

    def _run(self) -> None:
        while True:
            with self._cond:
                while self._pending is None and not self._closed:
                    self._cond.wait()
                if self._closed:
                    return
                (generation, scene, moving), self._pending = self._pending, None
            self._serve(generation, scene, moving)

    def _serve(self, generation: int, scene: Scene, moving: bool) -> None:
        current = [""]
        check = self._stop_if_stale(generation, current)
        try:
            plan = stages(scene, moving, self.rate * self.preview_seconds)
        except ValueError as e:
            self._fail(one_line(e))
            return
        camera = None   # the camera a framing pass chose (camera.fit), kept for the later stages
        for stage, s in plan:
            if self._generation != generation:
                return
            if camera is not None:
                s = dataclasses.replace(s, camera=camera)
            current[0] = stage
            if stage == "final" and s.shading.integrator == "path":
                self._serve_paths(generation, s, check)
                return
            t0 = time.perf_counter()
            try:
                result = self._render(s, check)
                png = picture_png(result.color, s)
            except Stale:
                return
            except ValueError as e:   # SceneError, a refusal, a device's one-line error
                self._fail(one_line(e))
                return
            except Exception as e:   # never a dead page: the error in one line, the loop goes on
                self._fail(f"render failed: {type(e).__name__}: {one_line(e)}")
                return
            seconds = time.perf_counter() - t0
            if stage == "preview" and seconds > 0:
                pixels = s.image.width * s.image.height
                self.rate = 0.5 * self.rate + 0.5 * pixels / seconds
            rendered = result.scene or s
            if s.camera.fit:
                camera = rendered.camera
            if self._generation != generation and stage != "preview":
                return
            self._show(Picture(generation, stage, rendered, png, facts(result, stage)))

    def _serve_paths(self, generation: int, scene: Scene, check) -> None:
        """A path-traced picture's paths in batches (path_batches), pooled and shown after each."""
        from pyjulia4d.pipeline.film import merge
        batches = path_batches(scene.image.samples)
        pooled = None
        t0 = time.perf_counter()
        for k, (first, count) in enumerate(batches):
            if self._generation != generation:
                return
            try:
                result = self._render(scene.replace(**{"image.samples": count}), check, first)
                part = (result.color, result.alpha, result.film)
                pooled = part if pooled is None else merge(pooled, part)
                result.color, result.alpha, result.film = pooled
                result.seconds = time.perf_counter() - t0
                png = picture_png(shown_color(result), scene)
            except Stale:
                return
            except ValueError as e:
                self._fail(one_line(e))
                return
            except Exception as e:
                self._fail(f"render failed: {type(e).__name__}: {one_line(e)}")
                return
            if self._generation != generation:
                return
            stage = "final" if k == len(batches) - 1 else "refine"
            self._show(Picture(generation, stage, scene, png, facts(result, stage)))
