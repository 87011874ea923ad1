"""POV-Ray, Mandelbulber2 and pyjulia4d at equal depth error: each one's error against a
float64 brute force, beside its pixels per CPU-second.

The speed targets ask for pyjulia4d's rate as a multiple of POV-Ray's "at equal or better
depth error".  ``peers.py`` times both at their defaults, which are not equally accurate:
POV-Ray's julia_fractal steps at 1/precision along the ray and so steps over thin parts of
the set, where pyjulia4d's distance-estimate march stops within epsilon 1e-3 of it.  Here
each renderer runs at several settings, and each setting's error is measured:

* The scenes: ``matched`` is ``peers.py``'s POV-Ray scene (pyjulia4d's default scene at 640x480,
  a shadowless light at the eye) and ``max_iter 20``, the same at ``max_iteration 20``;
  ``hypercomplex sqr`` and ``documentation example`` (POV-Ray's own quaternion example, seed
  003, written at precision 15) are ``pov_compare.py``'s, as are ``hypercomplex cube``, ``exp``,
  ``sin``, ``ln`` and ``pwr(2, 0.5)`` (settings_for: where a pair has no distance estimate,
  the scans and the proven march, with coarser scans besides).  pyjulia4d renders what ``import-pov`` makes of
  each, so both render the same truncated set (POV-Ray's escape radius and iteration count).
* The truth: ``measure.brute_force.brute_force_depth`` (float64, a chord scan at 2e-4 through the
  bounding ball, a scan at 2e-6 over the chord before the first inside sample, bisection) on
  ``--samples`` pixels drawn at random, the same pixels for every row.
* POV-Ray's depth: the same scene with the fractal's pigment replaced by a function of the
  distance to the camera, ``finish { ambient 1 diffuse 0 }``, no light, written as a linear
  16-bit PNG: red holds v = (distance - lo) / (hi - lo) over the truth's depth range, green
  frac(256 v), which together give v to 1 / (256 x 65535) of the range, about 2e-7 in depth
  here (OpenImageIO reads the file; Pillow would cut it to 8 bits).  Its hit mask is the
  alpha.  Its CPU seconds are its own report of the trace of the scene with its own look
  ("Trace Time ... CPU-seconds total"), at each ``precision``.
* pyjulia4d's depth: the ``depth`` output of a render at each setting (the same march as the
  timed render, which keeps colour and alpha as ``peers.py``'s does); CPU seconds of a warm
  render in a child process (``peers.py``'s measure), median of ``--renders`` renders, and the
  median of ``--repeats`` runs alternating with POV-Ray's.
* The error of a row: the share of the sampled pixels whose hit or miss differs from the
  truth's (silhouette); over the pixels both hit, |depth - truth| at the median, 90th and
  99th percentiles (scene units); and the share of pixels that are wrong: in the silhouette,
  or in depth by more than 0.1 (and 1) pixel's worth, t 2 tan(fov/2) / height at the truth's
  depth t.  POV-Ray polishes each hit by bisection to within that readout, below float32's spacing at
  these depths (2.4e-7 at t = 3) and far below what a picture shows, so its median is not
  what separates the renderers; its misses of thin parts (precision is its step, 1/precision)
  are.  A row is at least as good as another where it has no more wrong pixels at either
  tolerance.  The shares carry their standard error over the draw of pixels.

* Mandelbulber2 (Debian's 2.20, its OpenCL path on PoCL, never a dependency): the scenes
  ``matched (Mandelbulber2's set)`` and ``max_iter 20 (Mandelbulber2's set)`` are pyjulia4d's
  matched scene as ``peers.py`` writes it for Mandelbulber2 (12 or 20 iterations, escape
  radius 4: POV-Ray's import keeps POV-Ray's own count and bailout, a different truncated
  set), and pyjulia4d's settings are rendered again on them.  Its depth is read from its
  16-bit z-buffer through two reference spheres and checked on a third
  (``benchmarks/peers/mb_depth.py``), against the truth along its own rays, which pass through the
  pixels' corners; its CPU seconds are ``peers.py``'s (the process's, less those of the same
  command at 8x6 pixels), at its default threshold (detail_level 1), finer and coarser ones,
  and constant thresholds 1e-3 to 1e-5 (skipped below 96 pixels of height, where the check
  has too few pixels to check).

For each peer's row the table names the fastest pyjulia4d row at least as good, and the ratio
of the two rates.  Writes benchmarks/results/peer_error.md (a section per run) and
peer_error.png (peer_error_default_look.png with ``--look default``; Mandelbulber2's scenes in
peer_error_mandelbulber2.png, the other hypercomplex functions in peer_error_functions.png): wrong pixels against CPU-seconds, a panel per scene.  POV-Ray is skipped with a message where it is not installed.

    python benchmarks/peers/peer_error.py [--scenes all] [--samples 4000] [--repeats 3] [--look default]
    python benchmarks/peers/peer_error.py --scenes Mandelbulber2     # its two scenes alone
"""
from __future__ import annotations

import json
import math
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.peers import mb_depth  # noqa: E402
from benchmarks.peers import peers  # noqa: E402
from benchmarks.peers import pov_compare  # noqa: E402
from benchmarks.lib.args import Parser, add_look, size_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402

PRECISIONS = (10, 20, 40, 100)   # POV-Ray's default is 20

PEERS = ("POV-Ray", "Mandelbulber2")


def custom(method: str, epsilon: float | None = None, z: int | None = None, steps: int | None = None,
           refine: str | None = None) -> list[str]:
    """A setting's overrides: the march keys given, the quality custom."""
    over = ["march.quality=custom", f"march.method={method}"]
    for key, v in (("epsilon", epsilon), ("z_resolution", z), ("post_steps", steps), ("refine", refine)):
        if v is not None:
            over.append(f"march.{key}={v}")
    return over


# pyjulia4d's settings: name -> overrides of the imported scene
SETTINGS = {
    "default (march.quality auto)": [],   # the scene's own: see the section's title
    "de, epsilon 3e-3": custom("de", 0.003),
    "de, epsilon 1e-2": custom("de", 0.01),
    "de, epsilon 1e-2, 6 ITP steps": custom("de", 0.01, steps=6),
    "de, epsilon 1e-2, 8 ITP steps": custom("de", 0.01, steps=8),
    "de, epsilon 3e-2": custom("de", 0.03),
    "de, epsilon 3e-2, 6 ITP steps": custom("de", 0.03, steps=6),
    "de, epsilon 3e-2, 8 ITP steps": custom("de", 0.03, steps=8),
    "de, epsilon 5e-2, 8 ITP steps": custom("de", 0.05, steps=8),
    # bisection: at these epsilons the march's brackets are all about epsilon wide, where
    # ITP converges no faster than bisection and costs two level evaluations more a ray
    "de, epsilon 3e-2, 8 bisection steps": custom("de", 0.03, steps=8, refine="bisect"),
    # 5 and 6 leave the bracket at 1.6e-3 and 7.8e-4, 0.3-0.4 and 0.15-0.2 of a pixel's
    # footprint: the same hits and misses as 7 (the march decides those), coarser depths
    "de, epsilon 5e-2, 5 bisection steps": custom("de", 0.05, steps=5, refine="bisect"),
    "de, epsilon 5e-2, 6 bisection steps": custom("de", 0.05, steps=6, refine="bisect"),
    # 7: the fewest steps that bring an epsilon-wide bracket near a tenth of a pixel's footprint
    # (5e-2 / 2^7 = 3.9e-4, against 3.8e-4 to 5.3e-4 at depths 2.5 to 3.5 here)
    "de, epsilon 5e-2, 7 bisection steps": custom("de", 0.05, steps=7, refine="bisect"),
    "de, epsilon 5e-2, 8 bisection steps": custom("de", 0.05, steps=8, refine="bisect"),
    "de, epsilon 5e-2, 10 bisection steps": custom("de", 0.05, steps=10, refine="bisect"),
    "fixed, z 50, 8 ITP steps": custom("fixed", z=50, steps=8),
    "fixed, z 100, 8 ITP steps": custom("fixed", z=100, steps=8),
    "draft (proven)": ["march.quality=draft"],
}
# where the pair has no distance estimate, coarser scans besides (POV-Ray's step at precision 20
# is 0.05, a tenth to a twentieth of these scenes' chords)
FIXED_SETTINGS = {
    "fixed, z 25, 8 ITP steps": custom("fixed", z=25, steps=8),
    "fixed, z 50, 8 bisection steps": custom("fixed", z=50, steps=8, refine="bisect"),
    "fixed, z 100, 8 bisection steps": custom("fixed", z=100, steps=8, refine="bisect"),
}


def settings_for(scene) -> dict[str, list[str]]:
    """SETTINGS that the scene's pair renders: without a distance estimate, the scans and the
    proven march, and FIXED_SETTINGS' coarser scans."""
    from pyjulia4d.fractal.registry import has_distance_estimate

    if has_distance_estimate(scene.fractal):
        return dict(SETTINGS)
    return {**{k: v for k, v in SETTINGS.items() if "march.method=de" not in v}, **FIXED_SETTINGS}


def pov_matched(w: int, h: int, precision: float) -> str:
    return re.sub(r"precision [0-9.]+", f"precision {precision:g}", peers.pov_scene(w, h))


def pov_max_iter(w: int, h: int, precision: float) -> str:
    return re.sub(r"max_iteration \d+", "max_iteration 20", pov_matched(w, h, precision))


def pov_hypercomplex(w: int, h: int, precision: float) -> str:
    return pov_compare.pov_text("hypercomplex sqr", precision=precision)


def pov_documentation(w: int, h: int, precision: float) -> str:
    return pov_compare.pov_text("documentation example (quaternion sqr)", precision=precision)


SCENES = {"matched": pov_matched, "max_iter 20": pov_max_iter, "hypercomplex sqr": pov_hypercomplex,
          "documentation example": pov_documentation}
# pov_compare.py's other hypercomplex functions, at its defaults but for precision; most have no
# distance estimate, so the distance-estimate settings are left out there (settings_for)
FUNCTIONS = ("hypercomplex cube", "hypercomplex exp", "hypercomplex sin", "hypercomplex ln",
             "hypercomplex pwr(2, 0.5)")
for _name in FUNCTIONS:
    SCENES[_name] = (lambda w, h, precision, n=_name: pov_compare.pov_text(n, precision=precision))
ALL = list(SCENES) + list(mb_depth.SCENES)
LIT = ("matched", "max_iter 20")   # the scenes --look default lights (peers.py's point light)
LOOK: list[str] = []               # --look default: pyjulia4d's soft shadows and occlusion

CHILD = r"""
import json, resource, statistics, sys, warnings
warnings.simplefilter("ignore")
import numpy as np
from pyjulia4d import Scene, render
from pyjulia4d.app.cli import CHANNEL_GROUPS
from pyjulia4d.pipeline.codes import STATUS_HIT
a = json.loads(sys.argv[1])
s = Scene.from_toml(a["toml"], a["over"])
PNG = CHANNEL_GROUPS["RGBA"]   # what `render -o picture.png` keeps
render(s, outputs=PNG)
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
times = []
for _ in range(a["renders"]):
    c0 = cpu()
    render(s, outputs=PNG)
    times.append(cpu() - c0)
r = render(s, outputs={"depth", "status"})
np.save(a["depth"], np.where(r.status == STATUS_HIT, r.depth, np.inf).astype(np.float64))
print(json.dumps({"cpu": statistics.median(times), "device": r.device_name}))
"""


def run_pyjulia4d(toml: Path, over: list[str], depth_path: Path, renders: int) -> dict:
    arg = json.dumps({"toml": str(toml), "over": over, "depth": str(depth_path), "renders": renders})
    p = subprocess.run([sys.executable, "-c", CHILD, arg], capture_output=True, text=True, cwd=ROOT, timeout=3600)
    if p.returncode != 0:
        raise RuntimeError((p.stderr.strip().splitlines() or ["?"])[-1])
    r = json.loads(p.stdout)
    r["depth"] = np.load(depth_path)
    return r


def _pov(text: str, w: int, h: int, tmp: Path, name: str, extra: list[str]) -> tuple[float, Path]:
    src, out = tmp / f"{name}.pov", tmp / f"{name}.png"
    src.write_text(text)
    out.unlink(missing_ok=True)
    p = subprocess.run(["povray", f"+I{src}", f"+O{out}", f"+W{w}", f"+H{h}", "-D", "-A", "+UA", *extra],
                       capture_output=True, text=True, cwd=tmp, timeout=3600)
    m = re.search(r"Trace Time:.*?with ([0-9.]+) CPU-seconds total", p.stdout + p.stderr, re.S)
    if p.returncode != 0 or not m or not out.exists():
        raise RuntimeError(f"povray failed: {(p.stderr.strip().splitlines() or ['?'])[-1]}")
    return float(m.group(1)), out


def pov_time(text: str, w: int, h: int, tmp: Path) -> float:
    """POV-Ray's CPU seconds for the trace of ``text`` with its own look."""
    return _pov(text, w, h, tmp, "look", [])[0]


def depth_text(text: str, lo: float, hi: float) -> str:
    """``text`` with the fractal coloured by its distance to the camera, unlit (ambient 1, no
    light): v = (distance - lo) / (hi - lo) in red, frac(256 v) in green (POV-Ray's functions
    are double precision; two 16-bit channels hold v to 1 / (256 x 65535), 6e-8 of hi - lo)."""
    m = re.search(r"camera \{[^}]*?location <([^>]*)>", text)
    ex, ey, ez = (float(v) for v in m.group(1).split(","))
    lo, hi = float(lo), float(hi)
    v = (f"(sqrt((x-({ex}))*(x-({ex}))+(y-({ey}))*(y-({ey}))+(z-({ez}))*(z-({ez}))) - ({lo!r})) / {hi - lo!r}")
    # the average of two pigments halves each: their colours are doubled
    look = ("pigment { average pigment_map { "
            f"[1 function {{ {v} }} color_map {{ [0 rgb <0, 0, 0>] [1 rgb <2, 0, 0>] }}] "
            f"[1 function {{ mod(256 * {v}, 1) }} color_map {{ [0 rgb <0, 0, 0>] [1 rgb <0, 2, 0>] }}] }} }} "
            "finish { ambient 1 diffuse 0 specular 0 }")
    text = re.sub(r"pigment \{[^{}]*\}\s*finish \{[^{}]*\}", look, text)
    return re.sub(r"light_source \{[^{}]*\}", "", text)


def pov_depth(text: str, w: int, h: int, tmp: Path, lo: float, hi: float) -> np.ndarray:
    """POV-Ray's depth per pixel (+inf on a miss), from a linear 16-bit PNG of depth_text: red
    gives 256 v to within 0.002, which picks the whole part that green's fraction completes."""
    import OpenImageIO as oiio

    _, out = _pov(depth_text(text, lo, hi), w, h, tmp, "depth",
                  ["+FN", "Bits_Per_Color=16", "File_Gamma=1.0", "Dither=off"])
    f = oiio.ImageInput.open(str(out))
    try:
        a = f.read_image("uint16")
    finally:
        f.close()
    coarse, frac = (a[..., k].astype(np.float64) / 65535 for k in (0, 1))
    v = (np.round(256 * coarse - frac) + frac) / 256
    return np.where(a[..., 3] > 0, lo + v * (hi - lo), np.inf)


def footprint(truth: np.ndarray, scene, h: int) -> np.ndarray:
    """A pixel's footprint at the truth's depth t (0 on a miss): t 2 tan(fov / 2) / height, fov
    the vertical angle."""
    return np.where(np.isfinite(truth), truth, 0.0) * 2 * math.tan(math.radians(scene.camera.fov) / 2) / h


def errors(depth: np.ndarray, idx: np.ndarray, truth: np.ndarray, pixel: np.ndarray) -> dict:
    """The error of ``depth`` (H, W; inf on a miss) at the flat pixel indices ``idx`` against
    ``truth`` (inf on a miss): the silhouette error (share of pixels whose hit or miss differs),
    |depth - truth| over the pixels both hit at p50, p90 and p99 (scene units), and the share
    of pixels wrong by more than 0.1 and 1 pixel's worth of depth (``pixel``: the footprint of
    a pixel at the truth's depth) or in the silhouette."""
    t = depth.ravel()[idx]
    hit, thit = np.isfinite(t), np.isfinite(truth)
    both = hit & thit
    e = np.abs(t[both] - truth[both])
    p50, p90, p99 = (np.percentile(e, [50, 90, 99]) if e.size else (math.nan,) * 3)
    out = {"sil": float(np.mean(hit != thit)), "p50": float(p50), "p90": float(p90), "p99": float(p99)}
    for key, px in WRONG.items():
        wrong = hit != thit
        wrong[both] |= e > px * pixel[both]
        out[key] = float(np.mean(wrong))
    return out


WRONG = {"wrong01": 0.1, "wrong1": 1.0}   # tolerances, in pixels' worth of depth


def share(p: float, n: int) -> str:
    """A share of n sampled pixels with its standard error, sqrt(p (1 - p) / n), in percent:
    how far another draw of the pixels could move it."""
    return f"{100 * p:.2f} ± {100 * math.sqrt(p * (1 - p) / n):.2f} %"


def as_good(a: dict, b: dict) -> bool:
    """a has no more wrong pixels than b at either tolerance."""
    return all(a[k] <= b[k] for k in WRONG)


def run_scene(name: str, w: int, h: int, samples: int, repeats: int, renders: int, have_pov: bool,
              have_mb: bool, tmp: Path) -> tuple[list[str], str]:
    from pyjulia4d import reference as ref
    from pyjulia4d.geometry.camera import camera_frame
    from pyjulia4d.interop.povray import import_pov
    from pyjulia4d.measure.brute_force import brute_force_depth

    toml = tmp / "scene.toml"
    if name in mb_depth.SCENES:
        from pyjulia4d.scene.model import Scene

        scene = Scene.default().with_overrides(peers.MATCHED + mb_depth.SCENES[name] + [f"image.width={w}",
                                                                                  f"image.height={h}"])
        toml.write_text(scene.to_toml())
    else:
        make = SCENES[name]
        src = tmp / "scene.pov"
        src.write_text(make(w, h, 20))
        imported = import_pov(src, w, h)
        toml.write_text(imported.toml)
        scene = imported.scene
    o, d = ref.generate_rays(camera_frame(scene), w, h)
    idx = np.random.default_rng(1).choice(w * h, min(samples, w * h), replace=False)
    truth = brute_force_depth(scene, o[idx], d[idx])
    pixel = footprint(truth, scene, h)
    fin = truth[np.isfinite(truth)]
    lo, hi = (float(fin.min()) - 0.5, float(fin.max()) + 0.5) if fin.size else (0.0, 10.0)
    rows: dict[str, dict] = {}
    timers = {}   # a peer's row -> its timed run (CPU s)
    if have_pov and name in SCENES:
        for p in PRECISIONS:
            rows[f"POV-Ray, precision {p}"] = errors(pov_depth(make(w, h, p), w, h, tmp, lo, hi), idx, truth, pixel)
            timers[f"POV-Ray, precision {p}"] = lambda p=p: pov_time(make(w, h, p), w, h, tmp)
    if have_mb and name in mb_depth.SCENES:
        depths, overs = mb_depth.peer_depths(name, scene, w, h, tmp)
        if depths:   # its pixels look along their corners: its own truth along its own rays
            eye, dirs = mb_depth.mb_rays(scene, w, h)
            n = len(idx)
            mb_truth = brute_force_depth(scene, np.tile(np.append(eye, 0.0), (n, 1)),
                                         np.hstack([dirs[idx], np.zeros((n, 1))]))
            rows.update({k: errors(v, idx, mb_truth, footprint(mb_truth, scene, h)) for k, v in depths.items()})
        timers.update({k: (lambda over=over: mb_depth.cpu_seconds(name, w, h, tmp, over)) for k, over in overs.items()})
    settings = settings_for(scene)
    times: dict[str, list[float]] = {k: [] for k in list(rows) + list(settings)}
    device = "?"
    for _ in range(repeats):   # alternate, so the shared machine's load falls on all alike
        for k, timed in timers.items():
            times[k].append(timed())
        for k, over in settings.items():
            r = run_pyjulia4d(toml, LOOK + over, tmp / "depth.npy", renders)
            device = r["device"]
            times[k].append(r["cpu"])
            if k not in rows:
                rows[k] = errors(r["depth"], idx, truth, pixel)
    px, n = w * h, len(idx)
    for k, r in rows.items():
        r["cpu"] = statistics.median(times[k])
        r["rate"] = px / r["cpu"] if r["cpu"] > 0 else math.inf
    from pyjulia4d.scene.quality import resolved_quality

    auto = resolved_quality(scene)   # "custom": the distance estimate, epsilon 1e-3, 4 ITP steps
    auto = "the distance estimate" if auto == "custom" else f"the {auto} preset"
    lines = [f"\n### {name} ({w}x{h}, {len(idx)} pixels against the truth, {int(np.isfinite(truth).sum())} of them "
             f"hit; pyjulia4d's default march here: {auto})\n", "| renderer, setting | CPU s | pixels per CPU-second | silhouette error | depth error p50 "
             "| p90 | p99 | wrong by > 0.1 px | > 1 px |", "|---|---|---|---|---|---|---|---|---|"]
    for k, r in rows.items():
        lines.append(f"| {k} | {r['cpu']:.3f} | {r['rate']:.3g} | {share(r['sil'], n)} | {r['p50']:.1e} "
                     f"| {r['p90']:.1e} | {r['p99']:.1e} | {share(r['wrong01'], n)} | {share(r['wrong1'], n)} |")
        print(lines[-1], flush=True)
    peer_rows = [k for k in rows if k.startswith(PEERS)]
    if peer_rows:
        default = next(iter(settings))
        lines += ["", "| peer's row | fastest pyjulia4d setting at least as good | rate / the peer's "
                  "| pyjulia4d's default: rate / the peer's | its wrong pixels (0.1 px) / the peer's |",
                  "|---|---|---|---|---|"]
        for k in peer_rows:
            good = [s for s in settings if as_good(rows[s], rows[k])]
            best = max(good, key=lambda s: rows[s]["rate"]) if good else None
            ratio = f"{rows[best]['rate'] / rows[k]['rate']:.2f}" if best else "-"
            wrong = (f"{rows[default]['wrong01'] / rows[k]['wrong01']:.2f}" if rows[k]["wrong01"] > 0 else "-")
            lines.append(f"| {k} | {best or 'none'} | {ratio} | {rows[default]['rate'] / rows[k]['rate']:.2f} "
                         f"| {wrong} |")
            print(lines[-1], flush=True)
    return lines, device, rows


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--scenes", default="matched", help="comma-separated: " + ", ".join(ALL)
                    + " (substrings), or all")
    ap.add_argument("--samples", type=int, default=4000, help="pixels compared with the truth (1 to 100000)")
    ap.add_argument("--repeats", type=int, default=3, help="alternating timed runs of each row (1 to 50)")
    ap.add_argument("--renders", type=int, default=3, help="timed renders per pyjulia4d run, median (1 to 50)")
    add_look(ap, ", on the quaternion scenes (the depths, and so the errors, are the same)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")
    for flag, v, top in (("--samples", a.samples, 100_000), ("--repeats", a.repeats, 50), ("--renders", a.renders, 50)):
        if not 1 <= v <= top:
            ap.error(f"{flag}: expected 1 to {top}, got {v}")
    want = [s.strip() for s in a.scenes.split(",")]
    # a scene's whole name picks it alone; a part of one, every scene it is part of
    names = [n for n in ALL if "all" in want or n in want or any(s and s not in ALL and s in n for s in want)]
    if not names:
        ap.error(f"--scenes: expected some of {', '.join(ALL)} or all, got {a.scenes!r}")
    if a.look == "default":
        from pyjulia4d.scene.model import Scene

        sh = Scene.default().shading
        peers.LOOK[:] = []   # peers.pov_scene: the point light, POV-Ray's shadows on
        LOOK[:] = [f"shading.shadow={sh.shadow}", f"shading.ao={sh.ao}"]
        kept = [n for n in names if n in LIT]
        if not kept:
            ap.error(f"--look default: lights {' and '.join(LIT)} alone, got --scenes {a.scenes!r}")
        if kept != names:
            print(f"--look default: {', '.join(n for n in names if n not in LIT)} left out (lit at the eye)",
                  file=sys.stderr)
        names = kept
    warnings.simplefilter("ignore")
    have_pov = shutil.which("povray") is not None
    if not have_pov:
        print("povray not installed (Debian: apt-get install povray): POV-Ray skipped", file=sys.stderr)
    have_mb = shutil.which("mandelbulber2") is not None
    if not have_mb:
        print("mandelbulber2 not installed (Debian: apt-get install mandelbulber2): Mandelbulber2 skipped",
              file=sys.stderr)
    lines, device, plotted = [], "?", {}
    try:
        with tempfile.TemporaryDirectory() as td:
            for n in names:
                more, device, plotted[n] = run_scene(n, w, h, a.samples, a.repeats, a.renders, have_pov, have_mb,
                                                     Path(td))
                lines += more
    except RuntimeError as e:   # a peer or a pyjulia4d child failed: one line, nothing written
        print(f"peer_error.py: {e}", file=sys.stderr)
        return 1
    finally:   # peers.py's look, and this module's, as they were for the next caller in this process
        peers.LOOK[:] = peers.MATCHED
        LOOK[:] = []
    look = (", pyjulia4d's default look (soft shadows, occlusion) against POV-Ray's shadows from the same point "
            "light" if a.look == "default" else "")
    head = (f"\n## {utc_now()}{look}, pyjulia4d on {device}, commit {git_commit()}, median of {a.repeats} alternating "
            f"runs ({a.renders} renders each for pyjulia4d)\n")
    md = a.out / "peer_error.md"
    append_run(md, "# POV-Ray and pyjulia4d at equal depth error\n\nWritten by `python benchmarks/peers/peer_error.py` "
               "(see its docstring: the truth, how each depth is read, what is timed).\n",
               head + "\n".join(lines) + "\n")
    print(f"wrote {md}")
    # POV-Ray's scenes and Mandelbulber2's each have their own plot, so a run of one leaves the other's
    stem = "peer_error" if a.look == "matched" else "peer_error_default_look"
    for suffix, panels in (("", {n: r for n, r in plotted.items() if n not in (*mb_depth.SCENES, *FUNCTIONS)}),
                           ("_functions", {n: r for n, r in plotted.items() if n in FUNCTIONS}),
                           ("_mandelbulber2", {n: r for n, r in plotted.items() if n in mb_depth.SCENES})):
        if panels:
            png = a.out / f"{stem}{suffix}.png"
            write_plot(png, panels, f"{w}x{h}{look}, {device}, {utc_now()}, commit {git_commit()}")
            print(f"wrote {png}")
    return 0


def write_plot(path: Path, scenes: dict[str, dict[str, dict]], title: str) -> None:
    """Wrong pixels against CPU-seconds, a panel per scene: POV-Ray's precisions joined by a
    line, pyjulia4d's settings as points, its default starred.  Written atomically (a
    temporary file in the folder, renamed over ``path``)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from matplotlib.ticker import FixedLocator, FormatStrFormatter, NullFormatter

    ncol = min(2, len(scenes))
    nrow = -(-len(scenes) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 3.6 * nrow + 0.6), squeeze=False)
    for ax in axes.ravel()[len(scenes):]:
        ax.axis("off")
    for ax, (name, rows) in zip(axes.ravel(), scenes.items()):
        pov = [(k, r) for k, r in rows.items() if k.startswith("POV-Ray")]
        mb = [(k, r) for k, r in rows.items() if k.startswith("Mandelbulber2")]
        ours = [(k, r) for k, r in rows.items() if not k.startswith(PEERS)]
        if mb:
            ax.plot([r["cpu"] for _, r in mb], [100 * r["wrong01"] for _, r in mb], "^-", color="tab:green",
                    ms=5, label="Mandelbulber2 2.20 OpenCL: detail level 0.5 to 4, then thresholds 1e-3 to 1e-5")
            for k, r in mb:   # its default and the thresholds; the detail levels between crowd together
                tag = k.split(", ", 1)[1].replace("detail 1 (default)", "default").replace("threshold ", "")
                if tag not in ("detail 2", "detail 4"):
                    ax.annotate(tag, (r["cpu"], 100 * r["wrong01"]), fontsize=6, xytext=(4, -2),
                                textcoords="offset points", color="tab:green")
        if pov:
            ax.plot([r["cpu"] for _, r in pov], [100 * r["wrong01"] for _, r in pov], "o-", color="tab:red",
                    label="POV-Ray 3.7, precision 10 / 20 / 40 / 100")
            for k, r in pov:
                ax.annotate(k.rsplit(" ", 1)[1], (r["cpu"], 100 * r["wrong01"]), fontsize=6,
                            xytext=(3, 3), textcoords="offset points", color="tab:red")
        ax.plot([r["cpu"] for _, r in ours], [100 * r["wrong01"] for _, r in ours], "s", color="tab:blue",
                ms=4, label="pyjulia4d, its march settings")
        r0 = ours[0][1]   # settings_for's first: the scene's default
        ax.plot([r0["cpu"]], [100 * r0["wrong01"]], "*", color="tab:blue", ms=12, label="pyjulia4d's default")
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(FixedLocator([0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10]))
        ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_title(name, fontsize=8)
        ax.set_xlabel("CPU seconds per render", fontsize=7)
        ax.set_ylabel("pixels wrong by more than 0.1 px (%)", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.grid(True, alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7, frameon=False)
    fig.suptitle(f"Depth error against time: {title}", fontsize=8)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    with tempfile.NamedTemporaryFile(dir=path.parent, prefix=f".{path.stem}.", suffix=".png", delete=False) as f:
        tmp = Path(f.name)
    try:
        fig.savefig(tmp, dpi=90)
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)
        plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
