"""Is every algebra x function pair as accurate as it reports?  Each pair rendered at its
defaults (camera.fit, the pair's own march) and every pixel's first crossing compared with
a float64 brute force of the set (measure/brute_force.brute_force_depth: a chord scan at 2e-4,
a 2e-6 scan before each first inside sample, bisection).  The render's own inside ends, and
points within four float32 spacings of them, are more samples for it (refine_truth): where the float64 set test finds one inside in front of
the brute force's crossing, the chord scan stepped over a part there (the cubic locus's
spikes are thinner than 2e-4), and the crossing is searched again before it; "truth
refined" counts those pixels.

    python benchmarks/accuracy/pair_accuracy.py [--size 80x60] [--only NAME ...] [--set KEY=VALUE ...]
                                       [--random N [--seed S]]

--random N: besides the defaults, N scenes per pair that are in no gallery, drawn from a
seeded generator: c with |c| up to 1.2 (near the connectedness boundary, in dust, interior),
max_iter 6, 12, 20 or 50, a 4D camera (its w up to 0.8 either side), a slice tilted by up
to 0.4 towards z, camera.fit framing what is there.

Per pair: the render's stated p99 error (its bracket behind the depth plus the width in front
it did not prove empty, result.error_stats)
and the measured p99 depth error |depth - truth| on the pixels both hit ("-" where no pixel
is hit by both, a scene that shows nothing: its silhouette alone judges it); the silhouette
error (pixels hit by one and not the other); the pixels that stepped over the set (the
truth's crossing in front of the render's depth by more than it states and float32's
rounding of t); and the pixels behind the first crossing (in front of the depth by more than
the bracket, whatever the render states there: for the estimate and the scan, which state
the whole ray in front, the share whose picture is wrong).  "As accurate as it reports": p99
error within 2x the stated p99 bracket,
silhouette wrong on at most 0.5 % of the pixels, at most 0.1 % stepped over.  Writes
benchmarks/results/pair_accuracy.md (a section per run, with commit, device and date).
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from pyjulia4d import Scene, reference as ref, render  # noqa: E402
from pyjulia4d.fractal.registry import FUNCTIONS_OF, march_method  # noqa: E402
from pyjulia4d.geometry.camera import camera_frame  # noqa: E402
from pyjulia4d.measure.brute_force import brute_force_depth, refine_depth  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

SILHOUETTE_MOST, STEPPED_MOST, BRACKET_FACTOR = 0.005, 0.001, 2.0


def pairs() -> list[tuple[str, str]]:
    return [(a, f) for a, fs in FUNCTIONS_OF.items() for f in fs]


def random_overrides(rng: np.random.Generator) -> list[str]:
    """One scene no gallery holds (--random)."""
    c = rng.normal(size=4) * np.array([1.0, 1.0, 0.5, 0.5])
    c *= rng.uniform(0.1, 1.2) / np.linalg.norm(c)
    ang = rng.uniform(0, 2 * np.pi)
    pos = [4 * np.cos(ang), rng.uniform(-2, 2), 4 * np.sin(ang), rng.uniform(-0.8, 0.8)]
    return [f"fractal.c={','.join(f'{x:.4f}' for x in c)}",
            f"fractal.max_iter={rng.choice([6, 12, 20, 50])}",
            f"camera.position={','.join(f'{x:.3f}' for x in pos)}", f"camera.target=0,0,0,{pos[3]:.3f}",
            "camera.fit=true", f"slice.normal=0,0,{rng.uniform(-0.4, 0.4):.3f},1"]


def truth_of(s: Scene) -> np.ndarray:
    """The float64 brute force's first crossing on every pixel's ray of ``s`` (its camera as
    given: a rendered scene's, camera.fit resolved), shaped (height, width); +inf: none."""
    w, h = s.image.width, s.image.height
    o, d = ref.generate_rays(camera_frame(s), w, h)
    return brute_force_depth(s, o, d).reshape(h, w)


# a render's depth comes back in float32, so its inside end is known to a spacing of t: the
# truth samples that far either side of it, at an eighth of a spacing (islands of the set
# thinner than one spacing - dust at max_iter 20 - had been lost between the samples)
END_SPACINGS = np.arange(-32, 33) / 8


def refine_truth(s: Scene, truth: np.ndarray, results) -> tuple[np.ndarray, int]:
    """The truth with the renders' inside ends (depth + bracket of each hit, and points
    within END_SPACINGS float32 spacings of it) as more samples (measure/brute_force.refine_depth:
    where the float64 set test finds one inside in front of the truth, the chord scan
    stepped over a part, and the crossing is searched again before it).  Returns (the truth,
    the pixels it moved)."""
    w, h = s.image.width, s.image.height
    o, d = ref.generate_rays(camera_frame(s), w, h)
    out = truth.ravel()
    before = out.copy()
    for r in results:
        hit = (r.status == 1).ravel()
        end = (r.depth.astype(np.float64) + r.bracket.astype(np.float64)).ravel()
        ulp = np.spacing(np.abs(r.depth.astype(np.float32))).astype(np.float64).ravel()
        for k in END_SPACINGS:   # 0 among them: the inside end itself
            out, _ = refine_depth(s, o, d, out, np.where(hit, end + k * ulp, np.inf))
    return out.reshape(h, w), int(np.count_nonzero(out != before))


def figure(x: float) -> str:
    """A table's error figure: two significant digits, "-" for none (no pixel hit)."""
    return f"{x:.2g}" if np.isfinite(x) else "-"


def measure(scene: Scene, dev) -> dict:
    """One scene: render it, brute-force its truth on the render's own rays, compare."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = render(scene, device=dev)
    render_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    truth, moved = refine_truth(r.scene, truth_of(r.scene), [r])
    truth_s = time.perf_counter() - t0
    out = compare(r, truth)
    out.update(render_s=render_s, truth_s=truth_s, truth_moved=moved)
    return out


def compare(r, truth: np.ndarray) -> dict:
    """A render (RenderResult) against the truth on its own rays: its stated p99 error, the
    measured p99 depth error, the silhouette and stepped-over shares, and the verdict."""
    s = r.scene
    w, h = s.image.width, s.image.height
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
        # behind the first crossing: a part of the set in front of the depth by more than the
        # bracket, stated (unresolved) or not - what the picture gets wrong, where a march that
        # proves nothing in front (the estimate, the scan) says only that it proved nothing
        behind = both & (truth < depth - bracket - rounding)
    stated = r.error_stats()["p99"]
    out = {"pixels": w * h, "hit": float(hit_r.mean()), "truth_hit": float(hit_t.mean()),
           "silhouette": float(np.mean(hit_r != hit_t)), "stepped": float(stepped.mean()),
           "behind": float(behind.mean()),
           "p99_err": float(np.percentile(err, 99)) if err.size else float("nan"),
           "stated_p99": stated, "method": march_method(s), "device": r.device_name}
    # a scene that neither render nor truth hits is judged by its silhouette alone
    depth_ok = err.size == 0 or out["p99_err"] <= BRACKET_FACTOR * stated
    out["honest"] = bool(depth_ok and out["silhouette"] <= SILHOUETTE_MOST and out["stepped"] <= STEPPED_MOST)
    return out


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="80x60")
    ap.add_argument("--only", nargs="*", default=[], help="pairs as algebra_function, e.g. hypercomplex_sin")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="on every pair's scene")
    ap.add_argument("--device", default=None)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--random", type=int, default=0, metavar="N", help="N scenes of one's own per pair, besides the defaults")
    ap.add_argument("--seed", type=int, default=2026)
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")
    dev = select_device(a.device)
    todo = [p for p in pairs() if not a.only or f"{p[0]}_{p[1]}" in a.only]
    head = ("| pair | march | stated p99 error | measured p99 error | silhouette wrong | stepped over | "
            "behind the first crossing | as accurate as stated | render s | truth s | truth refined |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|\n")
    rows = []
    print(head, end="")
    honest = 0
    rng = np.random.default_rng(a.seed)
    runs = 0
    for algebra, function in todo:
        for k in range(1 + a.random):
            extra = random_overrides(rng) if k else []
            scene = Scene.from_dict({"fractal": {"algebra": algebra, "function": function}},
                                    [f"image.width={w}", f"image.height={h}"] + extra + a.set)
            m = measure(scene, dev)
            honest += m["honest"]
            runs += 1
            name = f"{algebra} {function}" + (f" (own scene {k}: {' '.join(extra)})" if k else "")
            row = (f"| {name} | {m['method']} | {figure(m['stated_p99'])} | {figure(m['p99_err'])} | "
                   f"{100 * m['silhouette']:.2f} % | {100 * m['stepped']:.2f} % | {100 * m['behind']:.2f} % | "
                   f"{'yes' if m['honest'] else 'no'} | "
                   f"{m['render_s']:.2f} | {m['truth_s']:.1f} | {m['truth_moved']} |")
            rows.append(row)
            print(row, flush=True)
    summary = f"\n{honest} of {runs} renders as accurate as they report.\n"
    print(summary)
    section = (f"\n## {utc_now()}, commit {git_commit()}, {dev.name.strip()} ({dev.platform.name.strip()}), "
               f"{w}x{h}{', ' + ' '.join(a.set) if a.set else ''}{f', {a.random} own scenes per pair (seed {a.seed})' if a.random else ''}\n\n" + head + "\n".join(rows) + "\n" + summary)
    append_run(a.out / "pair_accuracy.md", "# Every pair against a float64 brute force of its set\n", section)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
