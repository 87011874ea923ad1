"""Do the quality presets keep their stated error on scenes they were not derived from?

``benchmarks/accuracy/error_vs_time.py`` derives the presets of pyjulia4d/scene/quality.py from its
own seventeen scenes.  This check draws NEW scenes, deterministically from a seed, of
the kinds that broke the earlier presets:

* c = a + b u (u a random unit pure quaternion: the set is the complex Julia set of
  a + bi turned into 4D, rotated by an automorphism), with a + bi drawn by rejection
  - ``boundary``: the critical orbit stays bounded (``ESCAPE_TEST`` iterations) and a
    point within ``BOUNDARY_RADIUS`` of c escapes: c near the boundary of the
    connectedness locus, inside it;
  - ``dust``: the critical orbit escapes between iterations 8 and 60: just outside it;
  - ``interior``: every point within ``INTERIOR_RADIUS`` of c stays bounded;
* max_iter 12, 20, 30 and 50: scene i has kind KINDS[i % 3] and max_iter
  MAX_ITERS[(i // 3) % 4], so 12 scenes cover each pair once and 24 twice;
* a 4D camera: position at distance 3.5-5 from the origin in a random direction with
  |w| >= 0.2, looking at the origin, limbo (x, y, z, 1) with x, y, z in [-0.3, 0.3].

Scenes whose truth hits fewer than MIN_HIT of the pixels are redrawn (counted in the
report).  Each scene is rendered with each preset (float32 kernels, the default) at a
small size and compared with ground truth from pyjulia4d/measure/truth.py (the converged
double-precision scan combined with the double-precision de search; never a preset's
own setting).  Per preset the report gives the worst p99 and max depth error, the worst
silhouette error, the render's own bracket p99 and pixels whose truth lies in front of
the certified depth (a part stepped over), and whether each stated bound held - the
p99 bound on the scenes it is stated for (max_iter <= quality.BOUND_MAX_ITER; beyond,
the errors are reported and nothing is claimed), the silhouette bound on all.

The reported run draws 24 scenes from each of the seeds in SEEDS.  Seeds 20261125 (12
scenes) and 1 (24 scenes) were looked at while deriving the presets; 2027 was drawn after
they were fixed (final's first stated p99, 3e-6, failed on one of its max_iter <= 20
scenes: 3.4e-6, one pixel of 131 that float32 classifies differently; it was widened to
1e-5), and 2028 after that change.

Writes benchmarks/results/preset_check.csv and .md (device, date, commit, command).

    python benchmarks/accuracy/preset_check.py                 # 2 x 24 scenes, 64x48 (~4 min on 2 CPU cores)
    python benchmarks/accuracy/preset_check.py --n 2 --width 16 --height 12 --z-start 1000 --time-default 0  # smoke run
"""
from __future__ import annotations

import csv
import datetime as _dt
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser  # noqa: E402
from benchmarks.accuracy.error_vs_time import SLACK_ULPS, git_head  # noqa: E402
from pyjulia4d.measure import truth  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from pyjulia4d.scene.quality import PRESETS, apply_quality, stated_p99  # noqa: E402

# the tables' split: scenes up to max_iter 20 and the deeper ones, reported apart
BOUND_MAX_ITER = 20
from pyjulia4d.opencl.executor import render  # noqa: E402
from pyjulia4d.pipeline.codes import STATUS_HIT  # noqa: E402
from pyjulia4d.scene.model import Scene  # noqa: E402

SEEDS = (2027, 2028)
KINDS = ("boundary", "dust", "interior")
MAX_ITERS = (12, 20, 30, 50)
ESCAPE_TEST = 2000
BOUNDARY_RADIUS = 0.01
INTERIOR_RADIUS = 0.05
MIN_HIT = 0.03


def escape_time(c: complex, n: int = ESCAPE_TEST) -> int:
    """Iteration at which the critical orbit 0 -> z^2 + c leaves |z| <= 2 (n: never)."""
    z = 0j
    for i in range(n):
        z = z * z + c
        if abs(z) > 2.0:
            return i + 1
    return n


def classify(c: complex, rng) -> str | None:
    e = escape_time(c)
    if e < ESCAPE_TEST:
        return "dust" if 8 <= e <= 60 else None
    ring = [c + r * np.exp(2j * np.pi * k / 16) for r in (BOUNDARY_RADIUS, INTERIOR_RADIUS) for k in range(16)]
    esc = [escape_time(z, 500) < 500 for z in ring]
    if any(esc[:16]):
        return "boundary"
    if not any(esc):
        return "interior"
    return None


def draw_c(rng, kind: str) -> complex:
    while True:
        c = complex(rng.uniform(-1.6, 0.5), rng.uniform(-1.1, 1.1))
        if classify(c, rng) == kind:
            return c


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def draw_scene(rng, kind: str, max_iter: int) -> tuple[list[str], dict]:
    c = draw_c(rng, kind)
    u = unit(rng.normal(size=3))                          # the imaginary unit c lives on
    cq = (c.real, *(c.imag * u))
    while True:
        pos = unit(rng.normal(size=4)) * rng.uniform(3.5, 5.0)
        if abs(pos[3]) >= 0.2:
            break
    limbo = (*rng.uniform(-0.3, 0.3, 3), 1.0)
    f = lambda v: ",".join(f"{x:.6g}" for x in v)
    over = [f"fractal.c={f(cq)}", f"fractal.max_iter={max_iter}", f"camera.position={f(pos)}",
            f"camera.limbo={f(limbo)}"]
    return over, dict(kind=kind, c=f"{c.real:.5f}{c.imag:+.5f}i", c_quaternion=f(cq), max_iter=max_iter,
                      escape=escape_time(c), position=f(pos), limbo=f(limbo))


def measure(res, tr: truth.Truth) -> dict:
    hit = res.status == STATUS_HIT
    both = hit & tr.hit
    dep = res.depth.astype(np.float64)[both]
    signed = dep - tr.depth[both]
    err = np.abs(signed)
    br = res.bracket.astype(np.float64)[both]
    slack = SLACK_ULPS * truth.ulp32(dep)
    over = signed > slack
    bs = res.bracket_stats()
    return dict(n_both=int(both.sum()), silhouette_err=float(np.mean(hit != tr.hit)),
                depth_err_p99=float(np.percentile(err, 99)) if err.size else math.nan,
                depth_err_max=float(err.max()) if err.size else math.nan,
                depth_err_median=float(np.median(err)) if err.size else math.nan,
                bracket_p99=bs["p99"], bracket_max=bs["max"], stepped_over=int(over.sum()),
                stepped_over_max=float(signed[over].max()) if over.any() else 0.0,
                after_bracket=int(np.sum(-signed > br + slack)), capped=res.capped,
                shell_miss=int(res.guards.get("shell_miss", 0)), ulp_step=int(res.guards.get("ulp_step", 0)),
                kernel_s=res.kernel_seconds)


COLUMNS = ["scene", "seed", "kind", "c", "c_quaternion", "max_iter", "escape", "position", "limbo", "truth_hit",
           "truth_s", "truth_de_first", "truth_converged", "quality", "p99_bound", "silhouette_bound",
           "n_both", "silhouette_err", "depth_err_median", "depth_err_p99", "depth_err_max", "bracket_p99",
           "bracket_max", "stepped_over", "stepped_over_max", "after_bracket", "capped", "shell_miss",
           "ulp_step", "kernel_s", "p99_held", "silhouette_held", "device", "date", "commit", "width", "height"]


def summary(rows: list[dict]) -> list[dict]:
    out = []
    for q in PRESETS:
        rs = [r for r in rows if r["quality"] == q]
        if not rs:
            continue
        bd = [r for r in rs if r["max_iter"] <= BOUND_MAX_ITER]
        deep = [r for r in rs if r["max_iter"] > BOUND_MAX_ITER]
        w = max(bd, key=lambda r: r["depth_err_p99"]) if bd else None
        wd = max(deep, key=lambda r: r["depth_err_p99"]) if deep else None
        ws = max(rs, key=lambda r: r["silhouette_err"])
        nb = sum(r["n_both"] for r in bd)
        out.append(dict(quality=q, p99_bound=PRESETS[q]["p99_bound"], silhouette_bound=PRESETS[q]["silhouette_bound"],
                        worst_p99=w["depth_err_p99"] if w else math.nan, worst_p99_scene=w["scene"] if w else "",
                        worst_p99_deep=wd["depth_err_p99"] if wd else math.nan,
                        worst_p99_deep_scene=wd["scene"] if wd else "",
                        median_p99=float(np.median([r["depth_err_p99"] for r in bd])) if bd else math.nan,
                        median_p99_deep=float(np.median([r["depth_err_p99"] for r in deep])) if deep else math.nan,
                        worst_max=max((r["depth_err_max"] for r in bd), default=math.nan),
                        worst_sil=ws["silhouette_err"], worst_sil_scene=ws["scene"],
                        worst_bracket_p99=max(r["bracket_p99"] for r in rs),
                        stepped_over=sum(r["stepped_over"] for r in bd), n_both=nb,
                        stepped_over_deep=sum(r["stepped_over"] for r in deep),
                        n_both_deep=sum(r["n_both"] for r in deep),
                        stepped_over_max=max((r["stepped_over_max"] for r in bd), default=0.0),
                        p99_held=sum(r["p99_held"] is True for r in bd), scenes_bounded=len(bd),
                        sil_held=sum(r["silhouette_held"] for r in rs), scenes=len(rs),
                        kernel_s=sum(r["kernel_s"] for r in rs)))
    return out


def time_default(dev, rounds: int = 5) -> list[dict]:
    """The default scene (Scene.default(): 640x480, c = -0.2+0.8i, max_iter 12) with each
    preset and as it is (custom), rendered ``rounds`` times in rotating order so all see
    the same load; medians of kernel and whole-render time."""
    base = Scene.default()
    names = ["custom", *PRESETS]
    for q in names:                                      # build and warm every program
        render(apply_quality(base, q), device=dev)
    times = {q: ([], []) for q in names}
    for i in range(rounds):
        for q in names[i % len(names):] + names[:i % len(names)]:
            r = render(apply_quality(base, q), device=dev)
            times[q][0].append(r.kernel_seconds)
            times[q][1].append(r.seconds)
    return [dict(quality=q, kernel_s=float(np.median(k)), render_s=float(np.median(w)), rounds=rounds,
                 width=base.image.width, height=base.image.height) for q, (k, w) in times.items()]


def write(out: Path, rows: list[dict], scenes: list[dict], meta: dict, timing: list[dict] | None = None) -> None:
    with open(out / "preset_check.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
    g = lambda v: f"{v:.3g}" if isinstance(v, float) and not math.isnan(v) else str(v)
    L = ["# Quality presets on scenes they were not derived from", "",
         f"- device: {meta['device']}", f"- date: {meta['date']}", f"- commit: `{meta['commit']}`",
         f"- image: {meta['width']}x{meta['height']}, float32 kernels; seeds {meta['seed']}; "
         f"{len(scenes)} scenes ({meta['redrawn']} redrawn for a truth hit fraction below {MIN_HIT:.0%})",
         f"- command: `{meta['command']}`; total run time {meta['total_s']:.0f} s", "",
         "Depth errors in scene units over the pixels both render and truth hit. Stepped over = pixels whose "
         f"truth lies in front of the render's certified depth by more than {SLACK_ULPS} float32 spacings: a thin "
         "part the march passed before its first crossing, which the bracket does not cover.", "",
         "## Per preset, worst case over the scenes", "",
         f"The p99 bound is stated for max_iter <= {BOUND_MAX_ITER}  and checked there; the "
         "max_iter 30 and 50 scenes are reported beside it.", "",
         f"| quality | stated p99 | worst p99, max_iter <= {BOUND_MAX_ITER} (scene) | median p99 | worst max | "
         f"stepped over, max_iter <= {BOUND_MAX_ITER} (max) | p99 held | worst p99, max_iter 30-50 (scene) | "
         "median p99, 30-50 | stepped over, 30-50 | stated silhouette | worst silhouette, all (scene) | silhouette held | "
         "worst bracket p99 | kernel s |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in summary(rows):
        L.append(f"| {s['quality']} | {s['p99_bound']:g} | {g(s['worst_p99'])} ({s['worst_p99_scene']}) | "
                 f"{g(s['median_p99'])} | {g(s['worst_max'])} | {s['stepped_over']} of {s['n_both']} "
                 f"({s['stepped_over'] / max(s['n_both'], 1):.2%}; {g(s['stepped_over_max'])}) | "
                 f"{s['p99_held']} of {s['scenes_bounded']} | {g(s['worst_p99_deep'])} ({s['worst_p99_deep_scene']}) | "
                 f"{g(s['median_p99_deep'])} | {s['stepped_over_deep']} of {s['n_both_deep']} "
                 f"({s['stepped_over_deep'] / max(s['n_both_deep'], 1):.2%}) | {s['silhouette_bound']:.2%} | "
                 f"{s['worst_sil']:.3%} ({s['worst_sil_scene']}) | {s['sil_held']} of {s['scenes']} | "
                 f"{g(s['worst_bracket_p99'])} | {g(s['kernel_s'])} |")
    seeds = list(dict.fromkeys(r["seed"] for r in rows))
    if len(seeds) > 1:
        L += ["", "Per seed (max_iter <= 20: worst p99, held):", "", "| seed | " + " | ".join(PRESETS) + " |",
              "|---|" + "---|" * len(PRESETS)]
        for sd in seeds:
            cells = []
            for s in summary([r for r in rows if r["seed"] == sd]):
                cells.append(f"{g(s['worst_p99'])} ({s['worst_p99_scene']}), {s['p99_held']} of {s['scenes_bounded']}")
            L.append(f"| {sd} | " + " | ".join(cells) + " |")
    if timing:
        L += ["", f"## The default scene ({timing[0]['width']}x{timing[0]['height']}), each preset", "",
              f"Medians of {timing[0]['rounds']} renders each, in rotating order (programs built first). `custom` = the "
              "default scene's own march keys.", "", "| quality | kernel s | render s |", "|---|---|---|"]
        for t in timing:
            L.append(f"| {t['quality']} | {t['kernel_s']:.3g} | {t['render_s']:.3g} |")
    L += ["", "## Scenes", "", "| scene | kind | c (critical orbit escapes at) | max_iter | camera position | limbo | "
          "truth hit | truth s | de search first on | scan converged |", "|---|---|---|---|---|---|---|---|---|---|"]
    for s in scenes:
        esc = "never" if s["escape"] >= ESCAPE_TEST else str(s["escape"])
        L.append(f"| {s['scene']} | {s['kind']} | {s['c']} ({esc}) | {s['max_iter']} | {s['position']} | {s['limbo']} | "
                 f"{s['truth_hit']:.3f} | {s['truth_s']:.1f} | {s['truth_de_first']} | {s['truth_converged']} |")
    L += ["", "## Every render", "", "| scene | quality | sil | median | p99 | max | bracket p99 | stepped over (max) | "
          "after bracket | shell miss | ulp step | capped | held |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        bad = [x for x, ok in (("p99", r["p99_held"] is not False), ("silhouette", r["silhouette_held"])) if not ok]
        held = ("no: " + ", ".join(bad)) if bad else ("yes" if r["p99_held"] is True else "silhouette yes; p99: no bound stated")
        L.append(f"| {r['scene']} | {r['quality']} | {g(r['silhouette_err'])} | {g(r['depth_err_median'])} | "
                 f"{g(r['depth_err_p99'])} | {g(r['depth_err_max'])} | {g(r['bracket_p99'])} | {r['stepped_over']} "
                 f"({g(r['stepped_over_max'])}) | {r['after_bracket']} | {r['shell_miss']} | {r['ulp_step']} | "
                 f"{r['capped']} | {held} |")
    (out / "preset_check.md").write_text("\n".join(L) + "\n")


def main(argv=None) -> int:
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=24, help="number of scenes")
    ap.add_argument("--seeds", default=",".join(map(str, SEEDS)), help="comma-separated; --n scenes from each")
    ap.add_argument("--width", type=int, default=64)
    ap.add_argument("--height", type=int, default=48)
    ap.add_argument("--z-start", type=int, default=8000, help="the truth scan's first z-resolution")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--device", default=None)
    ap.add_argument("--time-default", type=int, default=5, metavar="ROUNDS",
                    help="time the default scene with each preset, ROUNDS renders each (0: skip)")
    a = ap.parse_args(argv)
    t_all = time.perf_counter()
    dev = select_device(a.device)
    meta = dict(device=dev.name.strip(), date=_dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                commit=git_head(), width=a.width, height=a.height, seed=a.seeds, redrawn=0,
                command="python benchmarks/accuracy/preset_check.py " + " ".join(argv if argv is not None else sys.argv[1:]))
    a.out.mkdir(parents=True, exist_ok=True)
    rows, scenes = [], []
    for seed in (int(x) for x in a.seeds.split(",")):
        rng = np.random.default_rng(seed)
        for i in range(a.n):
            kind = KINDS[i % len(KINDS)]
            max_iter = MAX_ITERS[(i // len(KINDS)) % len(MAX_ITERS)]
            while True:
                over, info = draw_scene(rng, kind, max_iter)
                base = Scene.default().with_overrides(over + [f"image.width={a.width}", f"image.height={a.height}"])
                tr = truth.ground_truth(base, z_start=a.z_start)
                if tr.hit.mean() >= MIN_HIT:
                    break
                meta["redrawn"] += 1
            name = f"{seed}_s{i:02d}_{kind}"
            de = tr.record.get("de_search", {})
            info.update(scene=name, seed=seed, truth_hit=float(tr.hit.mean()), truth_s=tr.seconds,
                        truth_de_first=f"{de.get('de_first', 0)} of {de.get('rays_hit', 0)}",
                        truth_converged=tr.record.get("converged", "2D oracle"))
            scenes.append(info)
            print(f"[{time.perf_counter() - t_all:5.0f} s] {name}: c = {info['c_quaternion']}, max_iter {info['max_iter']}, "
                  f"camera {info['position']}, limbo {info['limbo']}; truth hit {tr.hit.mean():.3f} in {tr.seconds:.1f} s",
                  flush=True)
            for q, pr in PRESETS.items():
                s = apply_quality(base, q)
                res = render(s, device=dev)
                bound = stated_p99(q)
                row = dict(info, quality=q, p99_bound=bound if bound is not None else "none",
                           silhouette_bound=pr["silhouette_bound"], **measure(res, tr))
                row["p99_held"] = (bool(row["depth_err_p99"] <= bound) if row["n_both"] else True) \
                    if bound is not None else "no bound"
                row["silhouette_held"] = bool(row["silhouette_err"] <= pr["silhouette_bound"])
                row.update(device=meta["device"], date=meta["date"], commit=meta["commit"], width=a.width, height=a.height)
                rows.append(row)
                ok = row["p99_held"] is not False and row["silhouette_held"]
                print(f"    {q:>6}: p99 {row['depth_err_p99']:.3g} (stated {row['p99_bound']}) max {row['depth_err_max']:.3g} "
                      f"sil {row['silhouette_err']:.4f} bracket p99 {row['bracket_p99']:.3g} over {row['stepped_over']} "
                      f"-> {'held' if ok else 'NOT held'}", flush=True)
    timing = time_default(dev, a.time_default) if a.time_default > 0 else None
    for t in timing or []:
        print(f"default scene, {t['quality']}: kernel {t['kernel_s']:.3f} s, render {t['render_s']:.3f} s")
    meta["total_s"] = time.perf_counter() - t_all
    write(a.out, rows, scenes, meta, timing)
    for s in summary(rows):
        print(f"{s['quality']}: max_iter <= {BOUND_MAX_ITER}: worst p99 {s['worst_p99']:.3g} ({s['worst_p99_scene']}) vs "
              f"stated {s['p99_bound']:g}, held on {s['p99_held']} of {s['scenes_bounded']}; max_iter 30-50: worst p99 "
              f"{s['worst_p99_deep']:.3g} ({s['worst_p99_deep_scene']}); worst sil {s['worst_sil']:.4f}, "
              f"silhouette held on {s['sil_held']} of {s['scenes']}")
    print(f"wrote {a.out} in {meta['total_s']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
