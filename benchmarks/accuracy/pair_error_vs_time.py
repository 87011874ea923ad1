"""Error against run time on every algebra x function pair: each march a user can choose,
against one float64 brute force of the pair's set.

For each pair (its default scene, camera.fit, or N scenes of one's own with --random), the
truth is computed once on the render's own rays (pair_accuracy.truth_of: a chord scan at
2e-4, a 2e-6 scan before each first inside sample, bisection), then every setting renders
the same view:

* the default (no march key: march.quality "auto", scene/quality.py);
* the fixed z-resolution scan at z_resolution 250 (the default of a pair without a distance
  estimate), 1000 and 4000;
* the distance estimate (the default of a pair that has one);
* the proven march at floors of 1/250 and 1/1000 of the ray (z_resolution 250, 1000: the
  scan's own resolutions, with post_steps 4) and at each quality preset: draft (1/5000),
  normal (1/20000), final (1/200000).

Per setting: the kernels' seconds (the median of --repeats renders after one that builds),
as a ratio to the fixed scan at 1000 of the same pair (this machine is shared and noisy:
ratios, not seconds, carry across runs), the p99 error the render states (bracket plus the
width in front it did not prove empty: RenderResult.error_stats; the scan and the estimate
prove nothing in front of their hits, so they state the whole ray there), the measured
p99 depth error, the silhouette and stepped-over shares, and pair_accuracy's verdict (as
accurate as it states: p99 error within 2x the stated, silhouette wrong on at most 0.5 %,
at most 0.1 % stepped over).

    python benchmarks/accuracy/pair_error_vs_time.py [--size 64x48] [--repeats 3] [--only PAIR ...]
                                            [--settings NAME ...] [--random N [--seed S]]

Writes benchmarks/results/pair_error_vs_time.md (a section per run: commit, device, date; a
table per pair and a summary per setting), .csv (a row per pair, scene and setting) and .png
(measured p99 error against the kernel-time ratio, a panel per setting family).
"""
from __future__ import annotations

import csv
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from pyjulia4d import Scene, render  # noqa: E402
from pyjulia4d.fractal.registry import has_distance_estimate  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from benchmarks.accuracy.pair_accuracy import compare, pairs, random_overrides, refine_truth, truth_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

SETTINGS = {"default": [],   # march.quality "auto": what a scene that names no march key gets
            "fixed 250": ["march.method=fixed", "march.z_resolution=250"],
            "fixed 1000": ["march.method=fixed", "march.z_resolution=1000"],
            "fixed 4000": ["march.method=fixed", "march.z_resolution=4000"],
            "de": ["march.method=de"],
            "proven 250": ["march.method=proven", "march.z_resolution=250"],
            "proven 1000": ["march.method=proven", "march.z_resolution=1000"],
            "draft": ["march.quality=draft"],
            "normal": ["march.quality=normal"],
            "final": ["march.quality=final"]}
UNIT = "fixed 1000"
CSV_FIELDS = ("pair", "scene", "setting", "method", "kernel_s", "ratio", "stated_p99", "p99_err",
              "silhouette", "stepped", "honest")


def timed(scene: Scene, dev, repeats: int):
    """The render after a warm-up, and the median of its kernel seconds over ``repeats``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = render(scene, device=dev)
        ts = []
        for _ in range(repeats):
            r = render(scene, device=dev)
            ts.append(r.kernel_seconds)
    return r, statistics.median(ts)


def settings_for(fractal: dict, names) -> list[str]:
    """The settings a pair can run: the estimate only where it has one."""
    probe = Scene.from_dict({"fractal": fractal})
    return [n for n in names if n != "de" or has_distance_estimate(probe.fractal)]


def run_scene(scene: Scene, dev, names, repeats: int) -> tuple[list[dict], float]:
    """Every setting on one view: rows of compare()'s numbers plus time; the truth's seconds."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = render(scene.with_overrides(["image.width=8", "image.height=6"]), device=dev).scene
    # the fitted camera, with the scene's own render.float: the framing render states the precision
    # it ran (render.float "auto" resolved), which each setting resolves again for its own march
    view = fitted.with_overrides([f"image.width={scene.image.width}", f"image.height={scene.image.height}",
                                  f"render.float={scene.render.float}"])
    t0 = time.perf_counter()
    truth = truth_of(view)
    truth_s = time.perf_counter() - t0
    got = {name: timed(view.with_overrides(SETTINGS[name]), dev, repeats) for name in names}
    # every render's inside ends are samples for the one truth all are held to
    truth, moved = refine_truth(view, truth, [r for r, _ in got.values()])
    rows = []
    for name, (r, kernel_s) in got.items():
        m = compare(r, truth)
        m.update(setting=name, kernel_s=kernel_s, truth_moved=moved)
        rows.append(m)
    unit = next((m["kernel_s"] for m in rows if m["setting"] == UNIT), float("nan"))
    for m in rows:
        m["ratio"] = m["kernel_s"] / unit if unit > 0 else float("nan")
    return rows, truth_s


def summary(rows: list[dict], names) -> str:
    """Per setting: renders as accurate as stated, the median time ratio, the worst errors."""
    out = ["| setting | as accurate as stated | median x fixed 1000 | largest measured p99 | largest stepped over | "
           "largest silhouette |", "|---|---|---|---|---|---|"]
    for n in names:
        g = [m for m in rows if m["setting"] == n]
        if not g:
            continue
        errs = [m["p99_err"] for m in g if np.isfinite(m["p99_err"])]
        out.append(f"| {n} | {sum(m['honest'] for m in g)} of {len(g)} | {statistics.median(m['ratio'] for m in g):.2f} | "
                   f"{max(errs) if errs else float('nan'):.2g} | {100 * max(m['stepped'] for m in g):.2f} % | "
                   f"{100 * max(m['silhouette'] for m in g):.2f} % |")
    return "\n".join(out) + "\n"


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib
    import matplotlib.ticker
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fams = {"fixed scan": ("fixed 250", "fixed 1000", "fixed 4000"), "distance estimate": ("de",),
            "proven (floors 1/250 .. 1/200000)": ("proven 250", "proven 1000", "draft", "normal", "final"),
            "default (auto)": ("default",)}
    # a panel per family the run has rows of
    fams = {f: ns for f, ns in fams.items() if any(m["setting"] in ns for m in rows)}
    fig, axes = plt.subplots(1, len(fams), figsize=(4 * len(fams), 4.2), sharex=True, sharey=True, squeeze=False)
    axes = axes[0]
    for ax, (fam, names) in zip(axes, fams.items()):
        for n, mk in zip(names, "o^sDv"):
            g = [m for m in rows if m["setting"] == n and np.isfinite(m["p99_err"])]
            ax.scatter([m["ratio"] for m in g], [max(m["p99_err"], 1e-7) for m in g], marker=mk, s=18,
                       label=n, alpha=0.7)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(fam)
        ax.set_xlabel("kernel time / fixed scan at 1000 (same pair)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("measured p99 depth error (scene units)")
    fig.tight_layout()
    tmp = path.with_name(f".{path.stem}.tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="64x48")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", nargs="*", default=[], help="pairs as algebra_function, e.g. hypercomplex_sin")
    ap.add_argument("--settings", nargs="*", default=list(SETTINGS), choices=list(SETTINGS))
    ap.add_argument("--random", type=int, default=0, metavar="N", help="N scenes of one's own per pair, not the defaults")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--device", default=None)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")
    dev = select_device(a.device)
    rng = np.random.default_rng(a.seed)
    names = [n for n in SETTINGS if n in a.settings]
    if UNIT not in names:
        names.insert(0, UNIT)
    head = ("| setting | march | kernel s | x fixed 1000 | stated p99 error | measured p99 error | silhouette wrong | "
            "stepped over | as accurate as stated |\n|---|---|---|---|---|---|---|---|---|\n")
    parts, rows = [], []
    for algebra, function in [p for p in pairs() if not a.only or f"{p[0]}_{p[1]}" in a.only]:
        fractal = {"algebra": algebra, "function": function}
        for k in range(max(a.random, 1)):
            extra = random_overrides(rng) if a.random else []
            scene = Scene.from_dict({"fractal": fractal}, [f"image.width={w}", f"image.height={h}"] + extra)
            got, truth_s = run_scene(scene, dev, settings_for(fractal, names), a.repeats)
            title = f"{algebra} {function}" + (f" (own scene {k + 1}: {' '.join(extra)})" if extra else "")
            table = [f"| {m['setting']} | {m['method']} | {m['kernel_s']:.4f} | {m['ratio']:.2f} | {m['stated_p99']:.2g} | "
                     f"{m['p99_err']:.2g} | {100 * m['silhouette']:.2f} % | {100 * m['stepped']:.2f} % | "
                     f"{'yes' if m['honest'] else 'no'} |" for m in got]
            text = (f"\n### {title}\n\ntruth {truth_s:.0f} s, refined at {got[0]['truth_moved']} pixels by the renders' "
                    "inside ends\n\n" + head + "\n".join(table) + "\n")
            print(text, flush=True)
            parts.append(text)
            for m in got:
                m.update(pair=f"{algebra}_{function}", scene=" ".join(extra) or "default")
            rows += got
    summ = summary(rows, names)
    print(summ)
    section = (f"\n## {utc_now()}, commit {git_commit()}, {dev.name.strip()} ({dev.platform.name.strip()}), {w}x{h}, "
               f"{a.repeats} repeats{f', {a.random} own scenes per pair (seed {a.seed})' if a.random else ''}\n\n"
               "Summary over the pairs:\n\n" + summ + "".join(parts))
    a.out.mkdir(parents=True, exist_ok=True)
    append_run(a.out / "pair_error_vs_time.md", "# Error against run time on every pair\n", section)
    csv_path = a.out / "pair_error_vs_time.csv"
    tmp = csv_path.with_name(f".{csv_path.name}.tmp")
    with open(tmp, "w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=CSV_FIELDS, extrasaction="ignore")
        wr.writeheader()
        wr.writerows(rows)
    tmp.replace(csv_path)
    plot(rows, a.out / "pair_error_vs_time.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
