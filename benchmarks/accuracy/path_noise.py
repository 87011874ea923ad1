"""The path tracer's stated noise against its measured error, and both against CPU-seconds.

One scene (the default set, path-traced, with a sky and a sun) is rendered with
--reference samples per pixel, then at each sample count of --samples.  Per count:

- measured: the RMS over the set's pixels of the luminance difference to the reference, its
  share of noise put back: the reference's first samples are the render's own (one sample
  sequence), so the difference's variance is s^2/n - s^2/N, and adding the reference's
  (s^2/N, its stated noise squared) gives s^2/n, the error a viewer of the n-sample picture sees;
- stated: the RMS of the per-pixel noise the render states (pipeline/film.py: the standard
  error of each pixel's mean luminance), and its ratio to the measured error;
- the CPU-seconds of the render (user + system time of this process over the render).

The measured error falls as 1/sqrt(samples) where the sampling is right: the script fits the
log-log slope of measured against samples (least squares) and of measured against
CPU-seconds.  Writes benchmarks/results/path_noise.md (a section per run: device, date,
commit), and with --plot benchmarks/results/path_noise.png.

    python benchmarks/accuracy/path_noise.py [--size 160x120] [--reference 4096]
                                              [--samples 4 16 64 256 1024] [--plot]
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402

LUMA = np.array([0.2126, 0.7152, 0.0722])
RESULTS = ROOT / "benchmarks" / "results"


def scene(w: int, h: int, samples: int) -> Scene:
    """The default set, path-traced: a sky and a sun, 4 bounces."""
    return Scene.from_dict({
        "camera": {"position": [2.036, 1.77, -2.468, 0]},
        "shading": {"integrator": "path", "bounces": 4, "ambient": 0.5, "sky": [0.6, 0.75, 1.0], "environment": "uniform",
                    "lights": [{"direction": [1, 2, -1], "color": [1.2, 1.1, 1.0]}]},
        "image": {"width": w, "height": h, "samples": samples}})


def cpu_render(sc: Scene):
    """The render and the CPU-seconds this process spent on it (all its threads)."""
    t0, c0 = time.perf_counter(), os.times()
    r = render(sc, calibrate=False)
    c1 = os.times()
    return r, (c1.user - c0.user) + (c1.system - c0.system), time.perf_counter() - t0


def slope(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def main() -> None:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="160x120", help="WIDTHxHEIGHT (default 160x120)")
    ap.add_argument("--reference", type=int, default=4096, help="the reference's samples per pixel (default 4096)")
    ap.add_argument("--samples", type=int, nargs="+", default=[4, 16, 64, 256, 1024],
                    help="sample counts to measure (default 4 16 64 256 1024)")
    ap.add_argument("--plot", action="store_true", help="write benchmarks/results/path_noise.png")
    a = ap.parse_args()
    w, h = size_of(a.size)
    if not 2 <= a.reference <= 65536 or any(not 1 <= s <= 65536 for s in a.samples):
        ap.error("--reference and --samples: sample counts in [2, 65536] and [1, 65536]")
    ref, ref_cpu, ref_wall = cpu_render(scene(w, h, a.reference))
    set_px = ref.film.covered
    ref_noise2 = float(np.mean(ref.film.noise[set_px].astype(np.float64) ** 2))
    rows = []
    for s in a.samples:
        r, cpu, wall = cpu_render(scene(w, h, s))
        diff = ((r.color - ref.color).astype(np.float64) @ LUMA)[set_px]
        measured = float(np.sqrt(np.mean(diff ** 2) + ref_noise2))
        stated = float(np.sqrt(np.mean(r.film.noise[set_px].astype(np.float64) ** 2)))
        rows.append((s, measured, stated, cpu, wall))
        print(f"{s:6d} samples: measured {measured:.5f}  stated {stated:.5f}  ratio {stated / measured:.3f}  "
              f"{cpu:.1f} CPU-s  {wall:.1f} s", flush=True)
    S = np.array([r[0] for r in rows], float)
    M = np.array([r[1] for r in rows])
    C = np.array([r[3] for r in rows])
    k_s, k_c = slope(S, M), slope(C, M)
    device = ref.device_name
    lines = [f"\n## {utc_now()}, commit {git_commit()}, {device}\n\n",
             f"`python benchmarks/accuracy/path_noise.py --size {w}x{h} --reference {a.reference} --samples "
             f"{' '.join(map(str, a.samples))}`: the default set path-traced (a uniform sky 0.5 x (0.6, 0.75, 1), a sun, 4 "
             f"bounces) over its {int(set_px.sum())} covered pixels; the {a.reference}-sample reference took "
             f"{ref_cpu:.0f} CPU-s ({ref_wall:.0f} s), its own stated noise {np.sqrt(ref_noise2):.2e} RMS.\n\n",
             "| samples | measured RMSE | stated noise (RMS) | stated / measured | CPU-s | wall s |\n",
             "| ---: | ---: | ---: | ---: | ---: | ---: |\n"]
    lines += [f"| {s} | {m:.5f} | {st:.5f} | {st / m:.3f} | {c:.1f} | {wl:.1f} |\n" for s, m, st, c, wl in rows]
    lines.append(f"\nlog-log slope of the measured error: {k_s:.3f} against samples (1/sqrt: -0.5), "
                 f"{k_c:.3f} against CPU-seconds.\n")
    append_run(RESULTS / "path_noise.md", "# The path tracer's stated noise against its measured error\n\n"
               "Written by benchmarks/accuracy/path_noise.py; a section per run.\n", "".join(lines))
    print("".join(lines[-1:]), end="")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5.5, 4))
        ax.loglog(C, M, "o-", label="measured RMSE against the reference")
        ax.loglog(C, [r[2] for r in rows], "s--", label="stated noise (RMS)")
        for s, m, _, c, _ in rows:
            ax.annotate(f"{s}", (c, m), textcoords="offset points", xytext=(4, 4), fontsize=8)
        ax.set_xlabel("CPU-seconds")
        ax.set_ylabel("luminance error")
        ax.set_title("Path tracer: error against time (samples per pixel marked)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(RESULTS / "path_noise.png", dpi=110)


if __name__ == "__main__":
    main()
