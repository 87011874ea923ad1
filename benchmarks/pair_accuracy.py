"""Is every algebra x function pair as accurate as it reports?  Each pair rendered at its
defaults (camera.fit, the pair's own march) and every pixel's first crossing compared with
a float64 brute force of the set (measure/truth.brute_force_depth: a chord scan at 2e-4,
a 2e-6 scan before each first inside sample, bisection).

    python benchmarks/pair_accuracy.py [--size 80x60] [--only NAME ...] [--set KEY=VALUE ...]

Per pair: the render's stated p99 error (its bracket behind the depth plus the width in front
it did not prove empty, result.error_stats)
and the measured p99 depth error |depth - truth| on the pixels both hit; the silhouette
error (pixels hit by one and not the other); the pixels that stepped over the set (the
truth's crossing in front of the render's depth by more than it states and float32's
rounding of t).  "As accurate as it reports": p99 error within 2x the stated p99 bracket,
silhouette wrong on at most 0.5 % of the pixels, at most 0.1 % stepped over.  Writes
benchmarks/results/pair_accuracy.md (a section per run, with commit, device and date).
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
for p in (ROOT / "benchmarks", ROOT):
    if str(p) not in sys.path:
        sys.path.insert(0, str(p))

from pyjulia4d import Scene, reference as ref, render  # noqa: E402
from pyjulia4d.fractal.registry import FUNCTIONS_OF, march_method  # noqa: E402
from pyjulia4d.geometry.camera import camera_frame  # noqa: E402
from pyjulia4d.measure.truth import brute_force_depth  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from run_log import append_run, git_commit, utc_now  # noqa: E402

SILHOUETTE_MOST, STEPPED_MOST, BRACKET_FACTOR = 0.005, 0.001, 2.0


def pairs() -> list[tuple[str, str]]:
    return [(a, f) for a, fs in FUNCTIONS_OF.items() for f in fs]


def measure(scene: Scene, dev) -> dict:
    """One scene: render it, brute-force its truth on the render's own rays, compare."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = render(scene, device=dev)
    render_s = time.perf_counter() - t0
    s = r.scene
    w, h = s.image.width, s.image.height
    o, d = ref.generate_rays(camera_frame(s), w, h)
    t0 = time.perf_counter()
    truth = brute_force_depth(s, o, d).reshape(h, w)
    truth_s = time.perf_counter() - t0
    hit_r, hit_t = r.status == 1, np.isfinite(truth)
    both = hit_r & hit_t
    depth, bracket = r.depth.astype(np.float64), r.bracket.astype(np.float64)
    unresolved = r.unresolved.astype(np.float64)
    err = np.abs(depth[both] - truth[both])
    # float32 classifies points within a few ulps of the surface either way (its set test, not
    # the proof): 16 spacings of t are its resolution, not a thin part stepped over
    rounding = 16 * np.spacing(np.float32(np.maximum(depth, 1.0))).astype(np.float64)
    # stepped over: the truth's crossing in front of all the render admits to, its bracket
    # behind the depth and its unresolved width in front (kernels/march/proven.cl)
    with np.errstate(invalid="ignore"):   # inf - inf off the hits
        stepped = both & (truth < depth - np.maximum(bracket, unresolved) - rounding)
    stated = r.error_stats()["p99"]
    out = {"pixels": w * h, "hit": float(hit_r.mean()), "truth_hit": float(hit_t.mean()),
           "silhouette": float(np.mean(hit_r != hit_t)), "stepped": float(stepped.mean()),
           "p99_err": float(np.percentile(err, 99)) if err.size else float("nan"),
           "stated_p99": stated, "render_s": render_s, "truth_s": truth_s,
           "method": march_method(s), "device": r.device_name}
    out["honest"] = (err.size > 0 and out["p99_err"] <= BRACKET_FACTOR * stated
                     and out["silhouette"] <= SILHOUETTE_MOST and out["stepped"] <= STEPPED_MOST)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="80x60")
    ap.add_argument("--only", nargs="*", default=[], help="pairs as algebra_function, e.g. hypercomplex_sin")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="on every pair's scene")
    ap.add_argument("--device", default=None)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = (int(x) for x in a.size.lower().split("x"))
    dev = select_device(a.device)
    todo = [p for p in pairs() if not a.only or f"{p[0]}_{p[1]}" in a.only]
    head = ("| pair | march | stated p99 error | measured p99 error | silhouette wrong | stepped over | "
            "as accurate as stated | render s | truth s |\n|---|---|---|---|---|---|---|---|---|\n")
    rows = []
    print(head, end="")
    honest = 0
    for algebra, function in todo:
        scene = Scene.from_dict({"fractal": {"algebra": algebra, "function": function}},
                                [f"image.width={w}", f"image.height={h}"] + a.set)
        m = measure(scene, dev)
        honest += m["honest"]
        row = (f"| {algebra} {function} | {m['method']} | {m['stated_p99']:.2g} | {m['p99_err']:.2g} | "
               f"{100 * m['silhouette']:.2f} % | {100 * m['stepped']:.2f} % | {'yes' if m['honest'] else 'no'} | "
               f"{m['render_s']:.2f} | {m['truth_s']:.1f} |")
        rows.append(row)
        print(row, flush=True)
    summary = f"\n{honest} of {len(todo)} pairs as accurate as they report.\n"
    print(summary)
    section = (f"\n## {utc_now()}, commit {git_commit()}, {dev.name.strip()} ({dev.platform.name.strip()}), "
               f"{w}x{h}{', ' + ' '.join(a.set) if a.set else ''}\n\n" + head + "\n".join(rows) + "\n" + summary)
    append_run(a.out / "pair_accuracy.md", "# Every pair against a float64 brute force of its set\n", section)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
