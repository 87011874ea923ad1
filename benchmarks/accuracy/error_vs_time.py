"""Error against run time for every marching setting, and what the certified bracket
says about it.

For each scene, ground truth comes from ``pyjulia4d.truth`` (analytic for c = 0; for
real c the float64 2D oracle and for any other c the converged double-precision fixed
scan, each combined per pixel with a double-precision distance-estimate search at
epsilon 1e-10 - the earlier float64-verified crossing wins; never a float32 setting under
test).  Then for a grid of

* distance-estimate marching: epsilon 1e-2 .. 1e-6 x post_steps 0, 2, 4, 6, 10, 20 with
  ITP refinement (march.refine = itp, the default), epsilon 5e-7, 3e-7 and 1e-7 (at and
  below float32's spacing of t at depths 2-8: the smallest steps become one ulp,
  counted as ulp_step) with 10 and 20, and a few
  settings with bisection (march.refine = bisect, Ödegaard & Wennergren's post-stepping);
* fixed marching: z_resolution 35 .. 16,000 (log-spaced) x post_steps 0, 4, 10, 20 with
  ITP, a few with bisection, and z = 256,000 without post-steps on the Fig. 5 scene only
  (Ödegaard & Wennergren's claim),

it renders the scene (float32 kernels, the default) and records the median wall time
over repeats - kernels alone and the whole render, separately; each program is built
and each kernel run once on a cheap warm-up render of the same size first, so neither
OpenCL compilation nor PoCL's first-launch specialisation is timed - the depth error
over pixels that both hit (mean, median, p99, max; scene units and pixels' worth of
depth = error / (depth * 2 tan(fov/2) / height)), the silhouette error (fraction of
pixels hit by exactly one of render and truth), the render's own certified bracket
(RenderResult.bracket_stats: p50 / p99 / max over its hits) and, per pixel, whether the
truth lies where the bracket says - in [depth, depth + bracket] up to float32 slack
(SLACK_ULPS spacings of depth): ``stepped_over`` counts pixels whose truth lies in
front of the depth (a thin part the march stepped over before its first crossing, which
the bracket does not cover), ``after_bracket`` those whose truth lies behind the
bracket's inside end (the float64 truth calls the render's float32 inside point
outside).  Normal errors in degrees for the jacobian, gradient and zbuffer normal
kernels, each run on the same march output.

A second phase times ITP against bisection interleaved (alternating renders of the two
at equal post_steps, so both see the same machine load) and counts the set tests each
refinement takes with a float32 twin of kernels/march/refine.cl (``refine_tests``) started
from the march's own brackets.

Writes to --out (default benchmarks/results/): error_vs_time.csv, error_vs_time.md,
error_vs_time.png, seed_claim.md and truth.json (the ground-truth convergence record).

    python benchmarks/accuracy/error_vs_time.py            # full run (~20 min on 2 CPU cores)
    python benchmarks/accuracy/error_vs_time.py --quick    # CI smoke run: 2 scenes, 4 settings
"""
from __future__ import annotations

import csv
import datetime as _dt
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser  # noqa: E402
import pyopencl.array as cla  # noqa: E402

from pyjulia4d.opencl import build  # noqa: E402
from pyjulia4d.measure import truth
from pyjulia4d.pipeline import kernel_config  # noqa: E402
from pyjulia4d.measure import truth
from pyjulia4d import reference as ref  # noqa: E402
from pyjulia4d.geometry.camera import camera_frame  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline.codes import STATUS_HIT  # noqa: E402
from pyjulia4d.opencl.records import Packed, Precision  # noqa: E402
from pyjulia4d.opencl.runner import launch, queue_for  # noqa: E402
from pyjulia4d.pipeline import signatures  # noqa: E402
from pyjulia4d.pipeline.plan import make_plan  # noqa: E402
from pyjulia4d.scene.model import Scene  # noqa: E402

# name -> (overrides, description).  The first nine: Ödegaard & Wennergren's figures, POV-Ray's example
# and the two exact oracles, all max_iter 8-12 with w = 0 cameras.  The rest: max_iter 20
# and 50, c near the boundary of the connectedness locus (critical orbit bounded) or just
# outside it (dust: the critical orbit escapes, at the iteration given), 4D cameras
# (w != 0 or a tilted limbo vector) and a tilted slice.
SCENES = {
    "fig1": (["fractal.c=-0.7,-0.2,0,0"], "Ödegaard & Wennergren Fig. 1, c = -0.7-0.2i"),
    "fig5": (["fractal.c=-0.803762,-0.40615,0,0", "fractal.max_iter=8"],
             "Ödegaard & Wennergren Fig. 5, c = -0.803762-0.40615i, max_iter 8"),
    "fig6": (["fractal.c=-0.7323,-0.2179,0,0", "camera.position=-2,1,5,0"],
             "Ödegaard & Wennergren Fig. 6 (left), c = -0.7323-0.2179i, camera (-2, 1, 5, 0)"),
    "fig8_i8": (["fractal.c=0.4,0.5,0,0", "fractal.max_iter=8"], "Ödegaard & Wennergren Fig. 8, c = 0.4+0.5i, max_iter 8"),
    "fig8_i12": (["fractal.c=0.4,0.5,0,0", "fractal.max_iter=12"], "Ödegaard & Wennergren Fig. 8, c = 0.4+0.5i, max_iter 12"),
    "fig9": (["fractal.c=-0.8,0.4,0,0"], "Ödegaard & Wennergren Fig. 9, c = -0.8+0.4i"),
    "povray": (["fractal.c=-0.083,0,-0.83,-0.025", "fractal.max_iter=8"],
               "POV-Ray example <-0.083, 0, -0.83, -0.025>, max_iter 8"),
    "sphere": (["fractal.c=0,0,0,0"], "c = 0 (the ball; analytic truth)"),
    "real": (["fractal.c=-1,0,0,0"], "real c = -1 (basilica turned about the real axis; 2D oracle)"),
    # --- the reported case and its kind
    "fig8_i20_w": (["fractal.c=0.4,0.5,0,0", "fractal.max_iter=20", "camera.position=-2,1,5,0.8"],
                   "c = 0.4+0.5i (dust, escapes at 7), max_iter 20, camera (-2, 1, 5, 0.8)"),
    "bnd_i20_w": (["fractal.c=0.28,0.53,0,0", "fractal.max_iter=20", "camera.position=-2,1,5,0.8"],
                  "c = 0.28+0.53i (boundary, inside), max_iter 20, camera (-2, 1, 5, 0.8)"),
    "cusp_i20_limbo": (["fractal.c=-0.75,0.11,0,0", "fractal.max_iter=20", "camera.limbo=0,0.3,0,1"],
                       "c = -0.75+0.11i (boundary, escapes at 29), max_iter 20, limbo (0, 0.3, 0, 1)"),
    "dust_i20_limbo": (["fractal.c=-0.8,0.2,0,0", "fractal.max_iter=20", "camera.limbo=0.2,0,0.3,1"],
                       "c = -0.8+0.2i (dust, escapes at 15), max_iter 20, limbo (0.2, 0, 0.3, 1)"),
    "slice_i20": (["fractal.c=-0.2,0.6,0.2,0", "fractal.max_iter=20", "slice.normal=0.3,0,0.2,1",
                   "slice.distance=0.1"],
                  "c = -0.2+0.6i+0.2j, max_iter 20, slice normal (0.3, 0, 0.2, 1), distance 0.1"),
    "cusp_i50_w": (["fractal.c=-0.75,0.11,0,0", "fractal.max_iter=50", "camera.position=-2,1,5,0.8"],
                   "c = -0.75+0.11i (dust at max_iter 50), camera (-2, 1, 5, 0.8)"),
    "bnd_i50_limbo": (["fractal.c=0.3,0.55,0,0", "fractal.max_iter=50", "camera.position=1.8,1.6,-2.2,0.5",
                       "camera.limbo=0.2,0,0.3,1"],
                      "c = 0.3+0.55i (boundary, inside), max_iter 50, camera w 0.5, limbo (0.2, 0, 0.3, 1)"),
    "real_i50_w": (["fractal.c=-1,0,0,0", "fractal.max_iter=50", "camera.position=-2,1,5,0.8"],
                   "real c = -1, max_iter 50, camera (-2, 1, 5, 0.8) (2D oracle)"),
}
OLD_SCENES = ["fig1", "fig5", "fig6", "fig8_i8", "fig8_i12", "fig9", "povray", "sphere", "real"]
QUICK_SCENES = ["sphere", "real"]

DE_EPS = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
DE_POSTS = [0, 2, 4, 6, 10, 20]
DE_EXTRA = [(5e-7, 10), (5e-7, 20), (3e-7, 10), (3e-7, 20), (1e-7, 10), (1e-7, 20)]  # at and below float32 spacing of t ~ 2-5: ulp steps
DE_BISECT = [(1e-4, 6), (1e-4, 10), (1e-5, 6), (1e-5, 10), (1e-5, 20), (1e-6, 10), (1e-6, 20)]
Z_RES = [35, 70, 250, 1000, 4000, 16000]
FIXED_POSTS = [0, 4, 10, 20]
FIXED_BISECT = [(250, 10), (250, 20), (1000, 10), (4000, 10)]
ONLY = {("fixed", 256000, 0, "itp"): ["fig5"]}              # Ödegaard & Wennergren's claim: one scene is enough
# ITP against bisection, interleaved: (method, z_resolution, epsilon, post_steps)
ITP_PAIRS = [("de", 250, 1e-5, 6), ("de", 250, 1e-6, 10), ("de", 250, 5e-7, 20), ("fixed", 250, 1e-3, 10),
             ("fixed", 1000, 1e-3, 20)]
ITP_REPEATS = 9
SIL_MAX = 0.005   # a setting is usable (on the Pareto front) if it gets <= 0.5 % of the silhouette wrong
SLACK_ULPS = 8    # float32 slack of the bracket check, in spacings of float32 at the depth (~2e-6 at depth 3)
NORMAL_METHODS = ("jacobian", "gradient", "zbuffer")



# the tables' split: scenes up to max_iter 20 and the deeper ones, reported apart
BOUND_MAX_ITER = 20

def scene_max_iter(name: str) -> int:
    return Scene.default().with_overrides(SCENES[name][0]).fractal.max_iter


def bounded(name: str) -> bool:
    """Scenes up to max_iter BOUND_MAX_ITER (the tables report the deeper ones apart)."""
    return scene_max_iter(name) <= BOUND_MAX_ITER


def setting(method, z, post, eps, refine="itp") -> dict:
    return dict(method=method, z_resolution=z, post_steps=post, epsilon=eps, refine=refine)


def grid(quick: bool) -> list[dict]:
    if quick:
        return [setting("fixed", 35, 0, 1e-3), setting("fixed", 250, 10, 1e-3),
                setting("de", 250, 0, 1e-3), setting("de", 250, 10, 1e-3)]
    out = []
    for p in DE_POSTS:
        for e in DE_EPS:
            out.append(setting("de", 250, p, e))
    out += [setting("de", 250, p, e) for e, p in DE_EXTRA]
    out += [setting("de", 250, p, e, "bisect") for e, p in DE_BISECT]
    for z in Z_RES:
        for p in FIXED_POSTS:
            out.append(setting("fixed", z, p, 1e-3))
    out += [setting("fixed", z, p, 1e-3, "bisect") for z, p in FIXED_BISECT]
    out += [setting(m, z, p, 1e-3, r) for (m, z, p, r) in ONLY]
    # every preset's own setting is measured on every scene
    from pyjulia4d.scene.quality import PRESETS
    keys = {setting_key(s) for s in out}
    for q, pr in PRESETS.items():
        s = setting(pr["method"], pr["z_resolution"], pr["post_steps"], pr["epsilon"], pr.get("refine", "itp"))
        if setting_key(s) not in keys:
            out.append(s)
            keys.add(setting_key(s))
    return out


def runs_on(s: dict, scene: str) -> bool:
    key = (s["method"], s["z_resolution"], s["post_steps"], s["refine"])
    return key not in ONLY or scene in ONLY[key]


def setting_key(s: dict) -> tuple:
    return (s["method"], s["z_resolution"] if s["method"] == "fixed" else 0, s["post_steps"],
            float(s["epsilon"]) if s["method"] == "de" else 0.0, s["refine"])


def label(s: dict) -> str:
    r = "" if s["refine"] == "itp" else " bisect"
    if s["method"] == "fixed":
        return f"fixed z={s['z_resolution']} post={s['post_steps']}{r}"
    return f"de eps={float(s['epsilon']):g} post={s['post_steps']}{r}"


def curve_name(s: dict) -> str:
    return f"{s['method']} post={s['post_steps']}" + ("" if s["refine"] == "itp" else " bisect")


def setting_overrides(s: dict) -> list[str]:
    return [f"march.method={s['method']}", f"march.z_resolution={s['z_resolution']}",
            f"march.post_steps={s['post_steps']}", f"march.epsilon={s['epsilon']}",
            f"march.refine={s['refine']}"]


def git_head() -> str:
    """``git rev-parse HEAD``, with "+dirty" when the working tree has uncommitted changes."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                              check=True).stdout.strip()
        # dirty = the code that runs differs from the commit (not README, not the results)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--",
                                "pyjulia4d", "kernels", "benchmarks", "setup.cfg",
                                ":(exclude)benchmarks/results"], cwd=ROOT,
                               capture_output=True, text=True, check=True).stdout.strip()
        return head + ("+dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


# ------------------------------------------------------------------ normals

class NormalKernels:
    """The normal kernels of kernels/normals/*.cl run on one march output, so all three
    methods are measured on exactly the same hit points without re-marching."""

    def __init__(self, dev):
        self.dev = dev
        self.ctx, self.queue = queue_for(dev)

    def __call__(self, scene: Scene, res, method: str) -> np.ndarray:
        pr = Precision(scene.render.float == "double")
        cfg = kernel_config.KernelConfig(kernel_config.iteration_pieces(scene) + (f"normals/{method}",),
                                 kernel_config.precision_defines(scene) + kernel_config.fractal_defines(scene))
        prg = build.program(self.ctx, cfg)
        q = self.queue
        w, h = scene.image.width, scene.image.height
        n = w * h
        pos = np.nan_to_num(res.position.reshape(n, 4)).astype(pr.scalar)
        point = cla.to_device(q, np.ascontiguousarray(pos).view(pr.vec_dtype).ravel())
        status = cla.to_device(q, np.ascontiguousarray(res.status.reshape(n), np.int32))
        depth = cla.to_device(q, np.ascontiguousarray(res.depth.reshape(n).astype(pr.scalar)))
        normal = cla.empty(q, n, pr.vec_dtype)
        flags = cla.zeros(q, n, np.int32)
        given = dict(point=point, status=status, normal=normal, flags=flags)
        if method == "zbuffer":
            given.update(depth=depth, width=w, height=h)
        sig = signatures.NORMALS[method]
        records = make_plan(scene, "CPU", 1, force=True).records()
        launch(q, build.kernel(prg, sig.kernel), n, *Packed(sig, records, pr)(**given))
        q.finish()
        return normal.get().view(pr.scalar).reshape(h, w, 4)[..., :3].astype(np.float64)


# ------------------------------------------------------------------ metrics

def _stats(x: np.ndarray) -> tuple[float, float, float, float]:
    if x.size == 0:
        return (math.nan,) * 4
    return float(np.mean(x)), float(np.median(x)), float(np.percentile(x, 99)), float(np.max(x))


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between unit vectors (a zero vector counts as 90 degrees)."""
    return np.degrees(np.arccos(np.clip(np.sum(a * b, -1), -1.0, 1.0)))


def measure(scene: Scene, res, tr: truth.Truth, normals: dict[str, np.ndarray]) -> dict:
    hit = res.status == STATUS_HIT
    both = hit & tr.hit
    dep = res.depth.astype(np.float64)[both]
    signed = dep - tr.depth[both]                    # > 0: the render is behind the truth
    err = np.abs(signed)
    px = tr.depth[both] * 2.0 * math.tan(math.radians(scene.camera.fov) / 2.0) / scene.image.height
    row = {"n_both": int(both.sum()), "hit_fraction": float(hit.mean()), "capped": res.capped,
           "silhouette_err": float(np.mean(hit != tr.hit)),
           "sil_missed": int(np.sum(~hit & tr.hit)), "sil_extra": int(np.sum(hit & ~tr.hit))}
    for k, v in zip(("mean", "median", "p99", "max"), _stats(err)):
        row[f"depth_err_{k}"] = v
    for k, v in zip(("mean", "median", "p99", "max"), _stats(err / px)):
        row[f"depth_err_px_{k}"] = v
    bs = res.bracket_stats()
    row.update(bracket_p50=bs["p50"], bracket_p99=bs["p99"], bracket_max=bs["max"])
    # the certified bracket against the truth: the crossing should lie in [depth, depth + bracket]
    br = res.bracket.astype(np.float64)[both]
    slack = SLACK_ULPS * truth.ulp32(dep)
    over = signed > slack                             # truth in front of the depth: stepped over
    after = -signed > br + slack                      # truth behind the bracket's inside end
    row["stepped_over"] = int(over.sum())
    row["stepped_over_frac"] = float(over.mean()) if both.any() else 0.0
    row["stepped_over_max"] = float(signed[over].max()) if over.any() else 0.0
    row["stepped_over_median"] = float(np.median(signed[over])) if over.any() else 0.0
    row["after_bracket"] = int(after.sum())
    row["after_bracket_max"] = float((-signed - br)[after].max()) if after.any() else 0.0
    inb = ~over & ~after
    row["err_in_bracket_p99"] = float(np.percentile(err[inb], 99)) if inb.any() else math.nan
    for g in ("shell_miss", "ulp_step"):
        row[g] = int(res.guards.get(g, 0))
    for mth, nrm in normals.items():
        a = angle_deg(nrm[both], tr.normal[both])
        row[f"normal_err_{mth}_median"] = float(np.median(a)) if a.size else math.nan
        row[f"normal_err_{mth}_p95"] = float(np.percentile(a, 95)) if a.size else math.nan
    return row


def timed(scene: Scene, dev, repeats: int, min_repeat_s: float):
    """Median times over ``repeats`` renders (fewer when one render takes longer than
    ``min_repeat_s``: the grid's costliest settings are timed once)."""
    warm = scene.with_overrides(["march.z_resolution=2", "march.epsilon=0.5", "march.max_steps=4"])
    render(warm, device=dev)   # builds the program and runs every kernel once at this image size
    runs = [render(scene, device=dev)]
    while len(runs) < repeats and runs[0].seconds < min_repeat_s:
        runs.append(render(scene, device=dev))
    return runs[-1], float(np.median([r.kernel_seconds for r in runs])), \
        float(np.median([r.seconds for r in runs])), len(runs)


def pareto(rows: list[dict], xkey="kernel_s", ykey="depth_err_p99") -> set[int]:
    """Indices of the rows (silhouette error <= SIL_MAX) that no other such row beats in
    both time and p99 depth error."""
    ok = [i for i, r in enumerate(rows) if r["silhouette_err"] <= SIL_MAX and not math.isnan(r[ykey])]
    front = set()
    for i in ok:
        xi, yi = rows[i][xkey], rows[i][ykey]
        if not any((rows[j][xkey] <= xi and rows[j][ykey] <= yi and
                    (rows[j][xkey] < xi or rows[j][ykey] < yi)) for j in ok if j != i):
            front.add(i)
    return front


# ------------------------------------------------------------ ITP vs bisection

def refine_tests(scene: Scene, r0, steps: int, itp: bool) -> tuple[np.ndarray, np.ndarray]:
    """Set tests each hit ray's refinement takes, by a float32 twin of kernels/march/refine.cl
    (bracket arithmetic in float32 like the kernel, so both stop where the bracket cannot
    be split; the level function and the set test in float64 at the float32 points) started
    from ``r0``'s brackets (a render with post_steps 0: [depth, depth + bracket] is the
    march's certified bracket).  Returns (tests per ray, final width per ray); ITP's two
    end-point level evaluations are not in the count (they cost one set test each)."""
    f32 = np.float32
    f = scene.fractal
    o, d = ref.generate_rays(camera_frame(scene), scene.image.width, scene.image.height)
    hit = (r0.status.ravel() == STATUS_HIT) & (r0.bracket.ravel() > 0)
    a = r0.depth.ravel()[hit].astype(f32)
    b = (a + r0.bracket.ravel()[hit].astype(f32)).astype(f32)
    o32, d32 = o[hit].astype(f32), d[hit].astype(f32)

    def point(k, x):
        return (o32[k] + x[:, None] * d32[k]).astype(np.float64)

    n = len(a)
    tests = np.zeros(n, np.int64)
    if itp:
        k = np.arange(n)
        fa, _ = ref.julia_level(point(k, a), f.c, f.max_iter, f.bailout)
        fb, _ = ref.julia_level(point(k, b), f.c, f.max_iter, f.bailout)
        tiny = f32(np.finfo(f32).tiny)
        ya = -np.maximum(fa.astype(f32), tiny)
        yb = -np.minimum(fb.astype(f32), f32(0))
        w0 = b - a
        eps = np.ldexp(w0, -(steps + 1)).astype(f32)
        k1 = (f32(0.2) / w0).astype(f32)
    live = np.ones(n, bool)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for j in range(steps + 1 if itp else steps):
            if itp:
                live &= (b - a) > f32(2) * eps
            xh = (f32(0.5) * (a + b)).astype(f32)
            live &= (xh > a) & (xh < b)
            k = np.nonzero(live)[0]
            if k.size == 0:
                break
            tests[k] += 1
            if itp:
                ak, bk, yak, ybk, xhk = a[k], b[k], ya[k], yb[k], xh[k]
                r = (np.ldexp(eps[k], steps + 1 - j) - f32(0.5) * (bk - ak)).astype(f32)
                delta = (k1[k] * (bk - ak) * (bk - ak)).astype(f32)
                xf = np.where(ybk != yak, (ybk * ak - yak * bk) / (ybk - yak), xhk).astype(f32)
                sigma = np.where(xhk >= xf, f32(1), f32(-1))
                xt = np.where(delta <= np.abs(xhk - xf), xf + sigma * delta, xhk).astype(f32)
                x = np.where(np.abs(xt - xhk) <= r, xt, xhk - sigma * r).astype(f32)
                x = np.where((x > ak) & (x < bk), x, xhk).astype(f32)
                fx, ins = ref.julia_level(point(k, x), f.c, f.max_iter, f.bailout)
                y = -fx.astype(f32)
                b[k] = np.where(ins, x, bk)
                yb[k] = np.where(ins, np.maximum(y, f32(0)), ybk)
                a[k] = np.where(ins, ak, x)
                ya[k] = np.where(ins, yak, np.minimum(y, -tiny))
            else:
                x = xh[k]
                ins = ref.julia_inside(point(k, x), f.c, f.max_iter, f.bailout)
                b[k] = np.where(ins, x, b[k])
                a[k] = np.where(ins, a[k], x)
    return tests, (b - a).astype(np.float64)


def itp_phase(name: str, base: Scene, dev, tr: truth.Truth, repeats: int = ITP_REPEATS) -> list[dict]:
    """ITP against bisection at equal post_steps (the same guaranteed bracket h / 2^post):
    kernel times from renders of the two and of the same march without post-steps,
    alternated in rotating order ``repeats`` times each (medians; the refinement's cost is
    a render's median less the post-0 median), set tests from ``refine_tests`` on the
    march's own brackets, the brackets each reports."""
    out = []
    for (m, z, e, post) in ITP_PAIRS:
        sc = {r: base.with_overrides(setting_overrides(setting(m, z, post, e, r))) for r in ("itp", "bisect")}
        sc["post0"] = base.with_overrides(setting_overrides(setting(m, z, 0, e, "itp")))
        for x in sc.values():
            render(x.with_overrides(["march.z_resolution=2", "march.epsilon=0.5", "march.max_steps=4"]), device=dev)
            render(x, device=dev)
        order = ["itp", "bisect", "post0"]
        ks = {r: [] for r in order}
        res = {}
        for i in range(repeats):
            for r in order[i % 3:] + order[:i % 3]:
                res[r] = render(sc[r], device=dev)
                ks[r].append(res[r].kernel_seconds)
        r0 = res["post0"]
        k0 = float(np.median(ks["post0"]))
        row = dict(scene=name, label=label(setting(m, z, post, e)), method=m, post_steps=post,
                   z_resolution=z, epsilon=e, rays=int(np.sum((r0.status == STATUS_HIT) & (r0.bracket > 0))),
                   march_samples_mean=float(np.mean(r0.samples[r0.status == STATUS_HIT])) if r0.hit_fraction else 0.0,
                   post0_kernel_s=k0)
        for r in ("itp", "bisect"):
            tests, width = refine_tests(base, r0, post, r == "itp")
            st = res[r].bracket_stats()
            hit = (res[r].status == STATUS_HIT) & tr.hit
            err = np.abs(res[r].depth.astype(np.float64)[hit] - tr.depth[hit])
            kr = float(np.median(ks[r]))
            row.update({f"{r}_kernel_s": kr, f"{r}_refine_s": kr - k0,
                        f"{r}_tests_mean": float(np.mean(tests)) if tests.size else 0.0,
                        f"{r}_tests_max": int(tests.max()) if tests.size else 0,
                        f"{r}_bracket_p50": st["p50"], f"{r}_bracket_p99": st["p99"],
                        f"{r}_twin_width_p99": float(np.percentile(width, 99)) if width.size else math.nan,
                        f"{r}_err_p99": float(np.percentile(err, 99)) if err.size else math.nan})
        row["kernel_ratio"] = row["itp_kernel_s"] / max(row["bisect_kernel_s"], 1e-12)
        out.append(row)
    return out


# ------------------------------------------------------------------ output

COLUMNS = ["scene", "method", "z_resolution", "post_steps", "epsilon", "refine", "curve", "kernel_s", "render_s",
           "repeats", "hit_fraction", "capped", "n_both", "silhouette_err", "sil_missed", "sil_extra",
           "depth_err_mean", "depth_err_median", "depth_err_p99", "depth_err_max",
           "depth_err_px_mean", "depth_err_px_median", "depth_err_px_p99", "depth_err_px_max",
           "bracket_p50", "bracket_p99", "bracket_max", "stepped_over", "stepped_over_frac", "stepped_over_median",
           "stepped_over_max", "after_bracket", "after_bracket_max", "err_in_bracket_p99", "shell_miss", "ulp_step"] + \
          [f"normal_err_{m}_{s}" for m in NORMAL_METHODS for s in ("median", "p95")] + \
          ["pareto", "device", "date", "commit", "width", "height"]
ITP_COLUMNS = ["scene", "label", "method", "z_resolution", "epsilon", "post_steps", "rays", "march_samples_mean",
               "post0_kernel_s", "itp_kernel_s", "bisect_kernel_s", "kernel_ratio", "itp_refine_s", "bisect_refine_s", "itp_tests_mean", "bisect_tests_mean",
               "itp_tests_max", "bisect_tests_max", "itp_bracket_p50", "bisect_bracket_p50",
               "itp_bracket_p99", "bisect_bracket_p99", "itp_twin_width_p99", "bisect_twin_width_p99",
               "itp_err_p99", "bisect_err_p99"]


def fmt(v) -> str:
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return f"{v:.3g}"
    return str(v)


def measure_settings(name: str, base: Scene, settings, tr: truth.Truth, dev, repeats: int) -> list[dict]:
    """One row per (label, march overrides) of ``settings`` on ``base``: its kernel and render
    time and its error against ``tr`` (measure), printed as it goes (galleries/kinds_gallery.py)."""
    rows = []
    for label, march in settings:
        scene = base.with_overrides(march)
        res, ks, rs, _ = timed(scene, dev, repeats, 1.0)
        row = dict(scene=name, setting=label, kernel_s=ks, render_s=rs)
        row.update(measure(scene, res, tr, {"jacobian": res.normal.astype(np.float64)}))
        rows.append(row)
        print(f"    {label:>24} kernel {ks:8.4f} s  sil {row['silhouette_err']:.4f}  "
              f"p50 {row['depth_err_median']:.3g}  p99 {row['depth_err_p99']:.3g}  "
              f"bracket p99 {row['bracket_p99']:.3g}  normal {row['normal_err_jacobian_median']:.2g} deg",
              flush=True)
    return rows


ERROR_TABLE_COLUMNS = ["scene", "setting", "kernel_s", "render_s", "hit_fraction", "silhouette_err",
                       "depth_err_median", "depth_err_p99", "depth_err_max", "bracket_p99", "stepped_over",
                       "normal_err_jacobian_median"]


def write_error_tables(out: Path, stem: str, title: str, script: str, rows: list[dict], truths: dict,
                       device: str, size: tuple[int, int], seconds: float) -> None:
    """<stem>.csv (replaced) and a run appended to <stem>.md in ``out``: the truths and, per
    scene and setting, time and error; ``script`` wrote them (galleries/kinds_gallery.py)."""
    from benchmarks.lib.runlog import append_run, git_commit, utc_now
    with open(out / f"{stem}.csv", "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(ERROR_TABLE_COLUMNS)
        for r in rows:
            wr.writerow([fmt(r[c]) for c in ERROR_TABLE_COLUMNS])
    w, h = size
    L = [f"\n## {utc_now()}, {device}, commit {git_commit()}, {w}x{h}, {seconds:.0f} s\n",
         "| scene | truth | truth hit | truth s |", "|---|---|---|---|"]
    for name, (tr, desc) in truths.items():
        L.append(f"| {name}: {desc} | {tr.kind}, converged {tr.record.get('converged', '')} | "
                 f"{tr.hit.mean():.3f} | {tr.seconds:.1f} |")
    L += ["", "| scene | setting | kernels s | silhouette err | depth err p50 | p99 | max | bracket p99 | "
              "stepped over | normal err (deg, median) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r['scene']} | {r['setting']} | {r['kernel_s']:.4f} | {r['silhouette_err']:.4f} | "
                 f"{fmt(r['depth_err_median'])} | {fmt(r['depth_err_p99'])} | {fmt(r['depth_err_max'])} | "
                 f"{fmt(r['bracket_p99'])} | {r['stepped_over']} | {fmt(r['normal_err_jacobian_median'])} |")
    append_run(out / f"{stem}.md", f"# {title}\n\nWritten by `python benchmarks/{script}` (see its "
                                   f"docstring for the truth and the metrics).\n", "\n".join(L) + "\n")


def write_csv(path: Path, rows: list[dict], columns=None) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=columns or COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})


def preset_table(rows: list[dict]) -> list[dict]:
    """Each quality.py preset's measured worst case over the scenes of ``rows``: over the
    scenes it states a bound for (max_iter <= BOUND_MAX_ITER) and over the rest."""
    from pyjulia4d.scene.quality import PRESETS
    out = []
    for q, pr in PRESETS.items():
        key = setting_key(setting(pr["method"], pr["z_resolution"], pr["post_steps"], pr["epsilon"],
                                  pr.get("refine", "itp")))
        rs = [r for r in rows if setting_key(r) == key]
        if not rs:
            continue
        bd = [r for r in rs if bounded(r["scene"])] or rs
        deep = [r for r in rs if not bounded(r["scene"])]
        w99 = max(bd, key=lambda r: r["depth_err_p99"])
        wsil = max(rs, key=lambda r: r["silhouette_err"])
        wdeep = max(deep, key=lambda r: r["depth_err_p99"]) if deep else None
        fail = [r["scene"] for r in bd if r["depth_err_p99"] > pr["p99_bound"]] + \
               [r["scene"] for r in rs if r["silhouette_err"] > pr["silhouette_bound"]]
        nb = sum(r["n_both"] for r in rs)
        out.append(dict(quality=q, label=label(dict(method=pr["method"], z_resolution=pr["z_resolution"],
                                                    post_steps=pr["post_steps"], epsilon=pr["epsilon"],
                                                    refine=pr.get("refine", "itp"))),
                        p99_bound=pr["p99_bound"], silhouette_bound=pr["silhouette_bound"],
                        worst_p99=w99["depth_err_p99"], worst_p99_scene=w99["scene"],
                        worst_p99_deep=wdeep["depth_err_p99"] if wdeep else math.nan,
                        worst_p99_deep_scene=wdeep["scene"] if wdeep else "",
                        worst_sil=wsil["silhouette_err"], worst_sil_scene=wsil["scene"],
                        worst_max=max(r["depth_err_max"] for r in rs),
                        median_p99=float(np.median([r["depth_err_p99"] for r in rs])),
                        worst_bracket_p99=max(r["bracket_p99"] for r in rs),
                        stepped_over=sum(r["stepped_over"] for r in rs), n_both=nb,
                        stepped_over_bounded=sum(r["stepped_over"] for r in bd),
                        n_both_bounded=sum(r["n_both"] for r in bd),
                        stepped_over_max=max(r["stepped_over_max"] for r in rs),
                        after_bracket=sum(r["after_bracket"] for r in rs),
                        total_kernel_s=sum(r["kernel_s"] for r in rs), fails=list(dict.fromkeys(fail)),
                        scenes=len(rs), scenes_bounded=len(bd)))
    return out


def write_markdown(path: Path, rows: list[dict], meta: dict, truths: dict, presets: dict,
                   itp_rows: list[dict] | None = None) -> None:
    L = [f"# Error against run time ({meta['mode']} run)", "",
         f"- device: {meta['device']}", f"- date: {meta['date']}", f"- commit: `{meta['commit']}`",
         f"- image: {meta['width']}x{meta['height']}, float32 kernels; times are medians over up to "
         f"{meta['repeats']} renders (one for renders slower than {meta['min_repeat_s']} s); programs "
         "built and kernels run once before timing, so compilation is excluded; the machine is shared, "
         "so times carry load noise",
         f"- command: `{meta['command']}`; total run time {meta['total_s']:.0f} s", "",
         "Depth errors in scene units over pixels both render and truth hit; `px` = the same in pixels' "
         "worth of depth (error / (depth 2 tan(fov/2) / height)); silhouette = fraction of pixels hit "
         "by exactly one of the two; normal errors in degrees (median / p95). Bracket = the render's own "
         "certified bracket width (p50 / p99 / max over its hits): the surface crossing lies in "
         "[depth, depth + bracket]. `over` = pixels whose truth lies in front of the depth by more than "
         f"{SLACK_ULPS} float32 spacings (a part the march stepped over before its first crossing - the one "
         "thing the bracket does not cover); `after` = pixels whose truth lies behind depth + bracket by "
         "more than that (the float64 truth calls the render's float32 inside point outside). `*` = on "
         "the scene's Pareto front (kernel time vs p99 depth error, among settings with silhouette error "
         f"<= {SIL_MAX:.1%}).", ""]
    L += ["## Ground truth", "", "| scene | description | truth | hit fraction | time (s) | convergence | "
          "de search (epsilon 1e-10, double) |", "|---|---|---|---|---|---|---|"]
    for name, tr in truths.items():
        L.append(f"| {name} | {SCENES[name][1]} | {tr.kind} | {tr.hit.mean():.3f} | {tr.seconds:.1f} | "
                 f"{truth_summary(tr)} | {de_summary(tr)} |")
    L.append("")
    ptab = preset_table(rows) if meta["mode"] == "full" else []
    if ptab:
        L += ["## The presets (pyjulia4d/scene/quality.py) on every scene", "",
              f"Stated bounds apply to scenes with max_iter <= {BOUND_MAX_ITER}; the "
              "max_iter 50 scenes are reported beside them (no float32 bound is stated there).", "",
              f"| quality | setting | stated p99 | worst p99, max_iter <= {BOUND_MAX_ITER} (scene) | worst p99, max_iter 50 "
              "(scene) | median p99, all | worst max | stated silhouette | worst silhouette (scene) | worst bracket p99 | "
              f"stepped over, max_iter <= {BOUND_MAX_ITER} | stepped over, all (max) | after bracket | total kernel s | fails on |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for t in ptab:
            L.append(f"| {t['quality']} | {t['label']} | {t['p99_bound']:g} | {t['worst_p99']:.3g} ({t['worst_p99_scene']}) | "
                     f"{t['worst_p99_deep']:.3g} ({t['worst_p99_deep_scene']}) | {t['median_p99']:.3g} | {t['worst_max']:.3g} | "
                     f"{t['silhouette_bound']:.2%} | {t['worst_sil']:.3%} ({t['worst_sil_scene']}) | {t['worst_bracket_p99']:.3g} | "
                     f"{t['stepped_over_bounded']} of {t['n_both_bounded']} "
                     f"({t['stepped_over_bounded'] / max(t['n_both_bounded'], 1):.2%}) | "
                     f"{t['stepped_over']} of {t['n_both']} ({t['stepped_over'] / max(t['n_both'], 1):.2%}), "
                     f"{t['stepped_over_max']:.3g} | {t['after_bracket']} | {t['total_kernel_s']:.3g} | "
                     f"{', '.join(t['fails']) or 'none'} |")
        L.append("")
    if presets:
        L += ["## Cheapest settings meeting an error bound on every scene", "",
              "Worst case of the p99 depth error over the scenes with max_iter <= 20 (those the presets state a "
              f"bound for), silhouette error <= {SIL_MAX:.1%} on every scene; cost = total kernel time over all "
              "the scenes.", "",
              "| bound (p99, scene units) | setting | worst p99 (scene) | worst silhouette | total kernel s |",
              "|---|---|---|---|---|"]
        for bound, p in presets.items():
            if str(bound).startswith("_"):
                continue
            if p is None:
                L.append(f"| {bound:g} | none meets it | | | |")
            else:
                L.append(f"| {bound:g} | {p['label']} | {p['worst_p99']:.3g} ({p['worst_p99_scene']}) | "
                         f"{p['worst_sil']:.3g} | {p['total_kernel_s']:.3g} |")
        L += ["", "### Every setting, worst case over the scenes (cheapest first)", "",
              "`old` = the nine scenes of the earlier run (max_iter 8-12, w = 0 cameras). Stepped over = pixels "
              "(of all pixels both hit, all scenes) whose truth lies in front of the certified outside point.", "",
              "| setting | total kernel s | worst p99, max_iter <= 20 (scene) | worst p99, old | worst p99, max_iter 50 | "
              "worst max | worst silhouette | worst bracket p99 | stepped over | after bracket |",
              "|---|---|---|---|---|---|---|---|---|---|"]
        for c in presets["_all"]:
            L.append(f"| {c['label']} | {c['total_kernel_s']:.3g} | {c['worst_p99']:.3g} ({c['worst_p99_scene']}) | "
                     f"{c['worst_p99_old']:.3g} | {c['worst_p99_deep']:.3g} | {c['worst_max']:.3g} | {c['worst_sil']:.3g} | "
                     f"{c['worst_bracket_p99']:.3g} | {c['stepped_over_frac']:.2%} | {c['after_bracket']} |")
        L.append("")
    if itp_rows:
        L += itp_markdown(itp_rows)
    for scene in dict.fromkeys(r["scene"] for r in rows):
        L += [f"## {scene}: {SCENES[scene][1]}", "",
              "| method | refine | z_res | post | eps | kernel s | sil | median | p99 | max | p99 px | "
              "bracket p50 / p99 / max | over (max) | after | shell miss | n jac | n grad | n zbuf |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            if r["scene"] != scene:
                continue
            star = "*" if r["pareto"] else ""
            zr = r["z_resolution"] if r["method"] == "fixed" else ""
            ep = fmt(float(r["epsilon"])) if r["method"] == "de" else ""
            nn = [f"{fmt(r[f'normal_err_{m}_median'])} / {fmt(r[f'normal_err_{m}_p95'])}" for m in NORMAL_METHODS]
            L.append(f"| {star}{r['method']} | {r['refine']} | {zr} | {r['post_steps']} | {ep} | {fmt(r['kernel_s'])} | "
                     f"{fmt(r['silhouette_err'])} | {fmt(r['depth_err_median'])} | {fmt(r['depth_err_p99'])} | "
                     f"{fmt(r['depth_err_max'])} | {fmt(r['depth_err_px_p99'])} | {fmt(r['bracket_p50'])} / "
                     f"{fmt(r['bracket_p99'])} / {fmt(r['bracket_max'])} | {r['stepped_over']} ({fmt(r['stepped_over_max'])}) | "
                     f"{r['after_bracket']} | {r['shell_miss']} | " + " | ".join(nn) + " |")
        L.append("")
    path.write_text("\n".join(L))


def itp_summary(itp_rows: list[dict]) -> list[dict]:
    """Per setting of ITP_PAIRS: medians over the scenes of the kernel-time ratio, set tests."""
    out = []
    for lab in dict.fromkeys(r["label"] for r in itp_rows):
        rs = [r for r in itp_rows if r["label"] == lab]
        out.append(dict(label=lab, post_steps=rs[0]["post_steps"], scenes=len(rs),
                        ratio_median=float(np.median([r["kernel_ratio"] for r in rs])),
                        ratio_min=min(r["kernel_ratio"] for r in rs), ratio_max=max(r["kernel_ratio"] for r in rs),
                        itp_tests=float(np.median([r["itp_tests_mean"] for r in rs])),
                        bisect_tests=float(np.median([r["bisect_tests_mean"] for r in rs])),
                        itp_kernel=float(np.sum([r["itp_kernel_s"] for r in rs])),
                        bisect_kernel=float(np.sum([r["bisect_kernel_s"] for r in rs])),
                        post0_kernel=float(np.sum([r["post0_kernel_s"] for r in rs])),
                        itp_refine=float(np.sum([r["itp_refine_s"] for r in rs])),
                        bisect_refine=float(np.sum([r["bisect_refine_s"] for r in rs])),
                        itp_bracket_p99=float(np.median([r["itp_bracket_p99"] for r in rs])),
                        bisect_bracket_p99=float(np.median([r["bisect_bracket_p99"] for r in rs])),
                        itp_err_p99=max(r["itp_err_p99"] for r in rs),
                        bisect_err_p99=max(r["bisect_err_p99"] for r in rs),
                        samples=float(np.median([r["march_samples_mean"] for r in rs]))))
    return out


def itp_markdown(itp_rows: list[dict]) -> list[str]:
    L = ["## ITP against bisection at equal post_steps", "",
         f"Same march, same guaranteed bracket (h / 2^post_steps). Kernel times: medians of {ITP_REPEATS} renders each "
         "of ITP, bisection and the same march without post-steps, alternated in rotating order so all three see the "
         "same load; refine s = a median less the post-0 median (summed over the scenes; the shared machine's noise "
         "is of the order of these differences). Set tests per hit ray by a float32 twin of kernels/march/refine.cl from "
         "the march's own brackets (ITP also evaluates the level function at the two ends once: + 2), median over "
         "the scenes.", "",
         "| setting | march samples (median) | set tests ITP (+2) | set tests bisect | kernel s post 0 | kernel s ITP | "
         "kernel s bisect | refine s ITP | refine s bisect | ITP / bisect kernel (median, range) | bracket p99 ITP | "
         "bracket p99 bisect | worst p99 err ITP | worst p99 err bisect |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in itp_summary(itp_rows):
        L.append(f"| {s['label']} | {s['samples']:.3g} | {s['itp_tests']:.2f} | {s['bisect_tests']:.2f} | "
                 f"{s['post0_kernel']:.3g} | {s['itp_kernel']:.3g} | {s['bisect_kernel']:.3g} | {s['itp_refine']:.3g} | "
                 f"{s['bisect_refine']:.3g} | {s['ratio_median']:.2f} ({s['ratio_min']:.2f}-{s['ratio_max']:.2f}) | "
                 f"{s['itp_bracket_p99']:.3g} | {s['bisect_bracket_p99']:.3g} | {s['itp_err_p99']:.3g} | {s['bisect_err_p99']:.3g} |")
    L += ["", "Per scene:", "", "| scene | setting | tests ITP | tests bisect | kernel s post 0 | kernel s ITP | "
          "kernel s bisect | ratio | bracket p50 ITP / bisect | bracket p99 ITP / bisect |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for r in itp_rows:
        L.append(f"| {r['scene']} | {r['label']} | {r['itp_tests_mean']:.2f} | {r['bisect_tests_mean']:.2f} | "
                 f"{fmt(r['post0_kernel_s'])} | {fmt(r['itp_kernel_s'])} | {fmt(r['bisect_kernel_s'])} | {r['kernel_ratio']:.2f} | "
                 f"{fmt(r['itp_bracket_p50'])} / {fmt(r['bisect_bracket_p50'])} | "
                 f"{fmt(r['itp_bracket_p99'])} / {fmt(r['bisect_bracket_p99'])} |")
    L.append("")
    return L


def truth_summary(tr: truth.Truth) -> str:
    if tr.kind == "sphere":
        return f"analytic, radius {tr.record['radius']:.6f}"
    if tr.kind == "real_c":
        return (f"2D oracle, scan {tr.record['n_scan'][0]} then {tr.record['n_scan'][1]} steps + 60 bisections: "
                f"{tr.record['changed_on_doubling']} of {tr.record['rays']} rays changed on doubling")
    steps = tr.record["steps"]
    parts = [f"z={s['z_resolution']}" + (f": {s['changed_fraction']:.4f} changed (p99 move {s['p99_change']:.2g})"
                                         if "changed_fraction" in s else "") for s in steps]
    return (f"double fixed scan, {tr.record['post_steps']} post-steps; " + ", ".join(parts) +
            f" (converged = {tr.record['converged']}: {tr.record['confirm']} successive doublings each changed at most "
            f"{tr.record['frac']:.1%} of the pixels, a change being a depth move > {tr.record['tol']:g} or a hit/miss flip)")


def de_summary(tr: truth.Truth) -> str:
    r = tr.record.get("de_search")
    if not r:
        return ""
    return (f"{r['seconds']:.1f} s, {r['verified']} of {r['hit']} hits verified in float64, capped {r['capped']}; "
            f"earlier than the scan on {r['de_first']} of {r['rays_hit']} pixels (lead p99 {r['de_lead_p99']:.2g}, "
            f"max {r['de_lead_max']:.2g}), the scan earlier on {r['scan_first']}")


def write_plot(path: Path, rows: list[dict], meta: dict) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in rows if r["refine"] == "itp"]
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    curves = list(dict.fromkeys(r["curve"] for r in rows))
    ncol = min(4, len(scenes))
    nrow = math.ceil(len(scenes) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 3.8 * nrow + 0.9), squeeze=False)
    cmap = plt.cm.tab20 if len(curves) > 10 else plt.cm.tab10
    colors = {c: cmap(i % 20) for i, c in enumerate(curves)}
    markers = {"fixed": "o", "de": "s"}
    floor = 1e-8
    for ax, scene in zip(axes.ravel(), scenes):
        sr = [r for r in rows if r["scene"] == scene]
        for cv in curves:
            pts = [r for r in sr if r["curve"] == cv]
            if not pts:
                continue
            pts.sort(key=lambda r: r["z_resolution"] if r["method"] == "fixed" else -float(r["epsilon"]))
            x = [r["kernel_s"] for r in pts]
            y = [max(r["depth_err_p99"], floor) if not math.isnan(r["depth_err_p99"]) else np.nan for r in pts]
            ax.plot(x, y, "-", color=colors[cv], lw=1.1, label=cv)
            for r, xi, yi in zip(pts, x, y):
                good = r["silhouette_err"] <= SIL_MAX
                ax.plot([xi], [yi], markers[r["method"]], ms=4, color=colors[cv],
                        mfc=colors[cv] if good else "none")
        front = sorted((r for r in sr if r["pareto"]), key=lambda r: r["kernel_s"])
        if front:
            fx = [r["kernel_s"] for r in front]
            fy = [max(r["depth_err_p99"], floor) for r in front]
            ax.step(fx, fy, where="post", color="k", lw=1.0, ls="--", zorder=0)
            ax.plot(fx, fy, "o", ms=9, mfc="none", mec="k", mew=1.1, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{scene}: " + SCENES[scene][1], fontsize=7)
        ax.set_xlabel("kernel time per render (s)", fontsize=7)
        ax.set_ylabel("p99 depth error (scene units)", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.grid(True, which="major", alpha=0.3)
    for ax in axes.ravel()[len(scenes):]:
        ax.axis("off")
    handles, labels = [], []
    for ax in axes.ravel():
        for h_, l_ in zip(*ax.get_legend_handles_labels()):
            if l_ not in labels:
                handles.append(h_)
                labels.append(l_)
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=7, frameon=False)
    fig.suptitle(f"Depth error against time, {meta['width']}x{meta['height']} px, float32 kernels, ITP refinement - "
                 f"{meta['device']}, {meta['date']}, commit {meta['commit'][:10]}\n"
                 f"hollow marker: silhouette error > {SIL_MAX:.1%}; curves: fixed (z_resolution 35 .. 16,000) and de "
                 f"(epsilon 1e-2 .. 1e-6) at each post_steps; error floor drawn at {floor:g}", fontsize=8)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    fig.savefig(path, dpi=90)
    plt.close(fig)


# ------------------------------------------------------------ seed claim

def find(rows, scene, method, z=None, post=None, eps=None, refine="itp"):
    for r in rows:
        if r["scene"] == scene and r["method"] == method and (z is None or r["z_resolution"] == z) and \
                (post is None or r["post_steps"] == post) and r["refine"] == refine and \
                (eps is None or math.isclose(float(r["epsilon"]), eps)):
            return r
    return None


def seed_claim(rows: list[dict], meta: dict) -> str | None:
    a = find(rows, "fig5", "fixed", 250, 10, refine="bisect")     # the seed's post-stepping is bisection
    ai = find(rows, "fig5", "fixed", 250, 10)
    b = find(rows, "fig5", "fixed", 256000, 0)
    c0 = find(rows, "fig5", "fixed", 250, 0)
    de = [r for r in rows if r["scene"] == "fig5" and r["method"] == "de" and r["post_steps"] in (10, 20)
          and r["refine"] == "itp"]
    if a is None or b is None:
        return None
    hdr = ("| setting | kernel s | render s | silhouette | median depth err | p99 | max | p99 (px) | bracket p99 | "
           "normal jac median/p95 (deg) |\n|---|---|---|---|---|---|---|---|---|---|")

    def line(lab, r):
        return (f"| {lab} | {fmt(r['kernel_s'])} | {fmt(r['render_s'])} | {fmt(r['silhouette_err'])} | "
                f"{fmt(r['depth_err_median'])} | {fmt(r['depth_err_p99'])} | {fmt(r['depth_err_max'])} | "
                f"{fmt(r['depth_err_px_p99'])} | {fmt(r['bracket_p99'])} | {fmt(r['normal_err_jacobian_median'])} / "
                f"{fmt(r['normal_err_jacobian_p95'])} |")

    L = ["# Ödegaard & Wennergren's post-stepping claim, tested (Fig. 5 scene)", "",
         "Ödegaard & Wennergren (§9, Fig. 5: c = -0.803762-0.40615i, max_iter 8) says z-resolution 250 with 10 post-steps "
         "gives the detail of z-resolution 256,000 (250 x 2^10) for about 7 % more time than z-resolution 250 "
         "alone (19.1 s against 17.9 s).", "",
         f"Measured here: {meta['device']}, {meta['width']}x{meta['height']} px, float32 kernels, "
         f"{meta['date']}, commit `{meta['commit']}`. The seed's post-steps are bisection (march.refine = bisect); "
         "ITP rows beside them.", "", hdr]
    if c0:
        L.append(line("fixed z=250, post 0", c0))
    L.append(line("fixed z=250, post 10 (bisect)", a))
    if ai:
        L.append(line("fixed z=250, post 10 (ITP)", ai))
    L.append(line("fixed z=256000, post 0", b))
    for r in de:
        L.append(line(f"de eps={float(r['epsilon']):g}, post {r['post_steps']} (ITP)", r))
    L.append("")
    same = a["depth_err_p99"] <= max(2 * b["depth_err_p99"], 1e-5) and a["silhouette_err"] <= b["silhouette_err"] + 0.002
    L.append(f"- z=250 + 10 post-steps (bisect) vs z=256,000: p99 depth error {fmt(a['depth_err_p99'])} vs "
             f"{fmt(b['depth_err_p99'])}, silhouette {fmt(a['silhouette_err'])} vs {fmt(b['silhouette_err'])} -> "
             + ("**as accurate** (within 2x on p99 and 0.2 % on silhouette)" if same else "**not as accurate**")
             + f"; kernel time {fmt(a['kernel_s'])} s vs {fmt(b['kernel_s'])} s "
             f"({b['kernel_s'] / max(a['kernel_s'], 1e-12):.0f}x).")
    if c0:
        L.append(f"- post-steps' cost at z=250: {fmt(c0['kernel_s'])} s -> {fmt(a['kernel_s'])} s "
                 f"({100 * (a['kernel_s'] / max(c0['kernel_s'], 1e-12) - 1):+.0f} %; the seed: +7 %; timing noise on "
                 f"this shared machine is of that order); p99 depth error {fmt(c0['depth_err_p99'])} -> "
                 f"{fmt(a['depth_err_p99'])}.")
    good = [r for r in de if r["silhouette_err"] <= SIL_MAX]
    if good:
        beat = [r for r in good if r["kernel_s"] < a["kernel_s"] and r["depth_err_p99"] <= a["depth_err_p99"]]
        best = min(good, key=lambda r: r["depth_err_p99"])
        if beat:
            r = min(beat, key=lambda r: r["kernel_s"])
            L.append(f"- de with post-steps **beats both**: eps={float(r['epsilon']):g} + {r['post_steps']} post-steps "
                     f"is faster ({fmt(r['kernel_s'])} s) with p99 error {fmt(r['depth_err_p99'])} "
                     f"(silhouette {fmt(r['silhouette_err'])}).")
        else:
            L.append(f"- de with post-steps does **not** beat fixed z=250 + 10 post-steps on both time and p99 error; "
                     f"its most accurate setting (eps={float(best['epsilon']):g}) takes {fmt(best['kernel_s'])} s "
                     f"for p99 {fmt(best['depth_err_p99'])}.")
    else:
        L.append(f"- no de setting with post-steps keeps the silhouette error within {SIL_MAX:.1%}.")
    return "\n".join(L) + "\n"


# --------------------------------------------------------------- presets

PRESET_BOUNDS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 2e-6)


def candidates(rows: list[dict]) -> list[dict]:
    """Every setting measured on all scenes of ``rows``, with its worst case over them."""
    scenes = set(r["scene"] for r in rows)
    by: dict = {}
    for r in rows:
        by.setdefault(setting_key(r), []).append(r)
    out = []
    for key, rs in by.items():
        if {r["scene"] for r in rs} != scenes:
            continue
        bd = [r for r in rs if bounded(r["scene"])] or rs
        p99 = [r["depth_err_p99"] for r in bd]
        w = max(bd, key=lambda r: r["depth_err_p99"] if not math.isnan(r["depth_err_p99"]) else math.inf)
        old = [r["depth_err_p99"] for r in rs if r["scene"] in OLD_SCENES]
        deep = [r["depth_err_p99"] for r in rs if not bounded(r["scene"])]
        nb = sum(r["n_both"] for r in rs)
        out.append(dict(key=key, label=label(rs[0]),
                        worst_p99=max(p99) if not any(math.isnan(x) for x in p99) else math.inf,
                        worst_p99_scene=w["scene"],
                        worst_p99_old=max(old) if old else math.nan,
                        worst_p99_deep=max(deep) if deep else math.nan,
                        worst_sil=max(r["silhouette_err"] for r in rs),
                        worst_max=max((r["depth_err_max"] for r in rs if not math.isnan(r["depth_err_max"])),
                                      default=math.nan),
                        worst_bracket_p99=max((r["bracket_p99"] for r in rs if not math.isnan(r["bracket_p99"])),
                                              default=math.nan),
                        stepped_over_frac=sum(r["stepped_over"] for r in rs) / max(nb, 1),
                        after_bracket=sum(r["after_bracket"] for r in rs),
                        total_kernel_s=sum(r["kernel_s"] for r in rs)))
    return out


def choose_presets(rows: list[dict], bounds=PRESET_BOUNDS) -> dict:
    """For each bound, the setting with the least total kernel time over all scenes whose
    worst-case p99 depth error over the scenes with max_iter <= BOUND_MAX_ITER is
    <= bound and whose worst silhouette error over all scenes is <= SIL_MAX."""
    cands = candidates(rows)
    out = {}
    for b in bounds:
        ok = [c for c in cands if c["worst_p99"] <= b and c["worst_sil"] <= SIL_MAX]
        out[b] = min(ok, key=lambda c: c["total_kernel_s"]) if ok else None
    out["_all"] = sorted(cands, key=lambda c: c["total_kernel_s"])
    return out


# ------------------------------------------------------------------ main

def main(argv=None) -> int:
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="CI smoke run: 2 scenes, 4 settings, tiny image")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--width", type=int, default=None)
    ap.add_argument("--height", type=int, default=None)
    ap.add_argument("--scenes", default=None, help="comma-separated subset of: " + ", ".join(SCENES))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--min-repeat-s", type=float, default=1.0,
                    help="renders slower than this are timed once, not --repeats times")
    ap.add_argument("--device", default=None)
    a = ap.parse_args(argv)
    t_all = time.perf_counter()
    w = a.width or (24 if a.quick else 96)
    h = a.height or (18 if a.quick else 72)
    names = a.scenes.split(",") if a.scenes else (QUICK_SCENES if a.quick else list(SCENES))
    dev = select_device(a.device)
    meta = dict(device=dev.name.strip(), date=_dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                commit=git_head(), width=w, height=h, repeats=a.repeats, min_repeat_s=a.min_repeat_s,
                mode="quick" if a.quick else "full",
                command="python benchmarks/accuracy/error_vs_time.py " + " ".join(argv if argv is not None else sys.argv[1:]))
    a.out.mkdir(parents=True, exist_ok=True)
    nk = NormalKernels(dev)
    settings = grid(a.quick)
    rows: list[dict] = []
    itp_rows: list[dict] = []
    truths: dict[str, truth.Truth] = {}
    for name in names:
        over, desc = SCENES[name]
        base = Scene.default().with_overrides(over + [f"image.width={w}", f"image.height={h}",
                                                      "normals.method=jacobian"])
        tr = truth.ground_truth(base, n_scan=2000 if a.quick else 8000,
                                **({"z_start": 1000} if a.quick else {}))
        truths[name] = tr
        print(f"[{time.perf_counter() - t_all:6.0f} s] {name}: truth {tr.kind} in {tr.seconds:.1f} s, "
              f"hit {tr.hit.mean():.3f}; {truth_summary(tr)}; {de_summary(tr)}", flush=True)
        srows = []
        for s in settings:
            if not runs_on(s, name):
                continue
            scene = base.with_overrides(setting_overrides(s))
            res, ks, rs, nrep = timed(scene, dev, a.repeats, a.min_repeat_s)
            normals = {"jacobian": res.normal.astype(np.float64)}
            for m in ("gradient", "zbuffer"):
                normals[m] = nk(scene, res, m)
            row = dict(scene=name, curve=curve_name(s), kernel_s=ks, render_s=rs, repeats=nrep, **s)
            row.update(measure(scene, res, tr, normals))
            row.update(device=meta["device"], date=meta["date"], commit=meta["commit"], width=w, height=h)
            srows.append(row)
            print(f"    {label(s):>28} kernel {ks:8.4f} s  sil {row['silhouette_err']:.4f}  "
                  f"p99 {row['depth_err_p99']:.3g}  max {row['depth_err_max']:.3g}  bracket p99 {row['bracket_p99']:.3g}  "
                  f"over {row['stepped_over']} after {row['after_bracket']}", flush=True)
        front = pareto(srows)
        for i, r in enumerate(srows):
            r["pareto"] = i in front
        rows += srows
        if not a.quick:
            ir = itp_phase(name, base, dev, tr)
            for r in ir:
                r.update(device=meta["device"], commit=meta["commit"])
                print(f"    ITP vs bisect {r['label']:>22}: tests {r['itp_tests_mean']:.2f}+2 vs {r['bisect_tests_mean']:.2f}, "
                      f"kernel {r['itp_kernel_s']:.4f} vs {r['bisect_kernel_s']:.4f} s, bracket p99 "
                      f"{r['itp_bracket_p99']:.3g} vs {r['bisect_bracket_p99']:.3g}", flush=True)
            itp_rows += ir
    meta["total_s"] = time.perf_counter() - t_all
    presets = choose_presets(rows) if not a.quick else {}
    write_csv(a.out / "error_vs_time.csv", rows)
    if itp_rows:
        write_csv(a.out / "error_vs_time_itp.csv", itp_rows, ITP_COLUMNS)
    write_markdown(a.out / "error_vs_time.md", rows, meta, truths, presets, itp_rows)
    write_plot(a.out / "error_vs_time.png", rows, meta)
    (a.out / "truth.json").write_text(json.dumps(
        {n: {"kind": t.kind, "seconds": t.seconds, "hit_fraction": float(t.hit.mean()), "record": t.record}
         for n, t in truths.items()} | {"_meta": meta}, indent=1, default=float))
    claim = seed_claim(rows, meta)
    if claim:
        (a.out / "seed_claim.md").write_text(claim)
        print(claim)
    for b, p in presets.items():
        if str(b).startswith("_"):
            continue
        print(f"p99 <= {b:g}: {p['label'] if p else 'none'}"
              + (f" (worst p99 {p['worst_p99']:.3g} on {p['worst_p99_scene']}, worst sil {p['worst_sil']:.3g}, "
                 f"total {p['total_kernel_s']:.3g} s)" if p else ""))
    for t in (preset_table(rows) if not a.quick else []):
        print(f"preset {t['quality']}: {t['label']}: worst p99 {t['worst_p99']:.3g} ({t['worst_p99_scene']}) vs "
              f"stated {t['p99_bound']:g}; max_iter 50: {t['worst_p99_deep']:.3g} ({t['worst_p99_deep_scene']}); "
              f"worst sil {t['worst_sil']:.3g}; fails on {t['fails'] or 'none'}")
    print(f"wrote {a.out} in {meta['total_s']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
