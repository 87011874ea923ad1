"""Where a path-traced picture's noise comes from: the default set under the shipped sky
(benchmarks/speed/path_clean.py's scene), rendered with one light or bounce taken away at a
time, and for each the relative standard deviation of one path, sqrt(mean over the set's
pixels of n x the stated variance of the mean) over the mean colour there, with the paths
per CPU-second.

A pixel's relative noise after n paths is that deviation over sqrt(n), so the table says
how many paths a target needs before any denoiser: about (deviation / target)^2.

Appends a section to benchmarks/results/path_noise_sources.md.

    python benchmarks/studies/path_noise_sources.py [--size 160x120] [--samples 64]
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.lib.runlog import append_study, git_commit, utc_now  # noqa: E402
from benchmarks.speed.path_clean import KEYS  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402

VARIANTS = [
    ("as path_clean.py renders it", []),
    ("the sky alone (no key light)", ["shading.light_color=0,0,0"]),
    ("the key light alone (no sky)", ["shading.ambient=0"]),
    ("a uniform sky instead of the shipped one", ["shading.environment=uniform"]),
    ("direct light alone (bounces 1)", ["shading.bounces=1"]),
    ("the key light alone, direct (bounces 1)", ["shading.ambient=0", "shading.bounces=1"]),
    ("the sky alone, direct (bounces 1)", ["shading.light_color=0,0,0", "shading.bounces=1"]),
]


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size)
    base = KEYS + [f"image.width={w}", f"image.height={h}", f"image.samples={a.samples}"]
    render(Scene.default().with_overrides(base[:-3] + ["image.width=16", "image.height=12"]))   # built before timing
    rows, device = [], ""
    for name, extra in VARIANTS:
        sc = Scene.default().with_overrides(base + extra)
        c0 = os.times()
        r = render(sc, calibrate=False)
        c1 = os.times()
        cpu = (c1.user - c0.user) + (c1.system - c0.system)
        m = r.film.covered
        n = r.film.paths[m].astype(np.float64)[:, None]
        dev = float(np.sqrt(np.mean(r.film.variance[m] * n)) / np.mean(r.color[m]))
        rows.append((name, float(np.mean(r.color[m])), dev, w * h * a.samples / cpu))
        device = r.device_name
        print(f"{name:45s} mean {rows[-1][1]:.3f}  one path's relative deviation {dev:.2f}  "
              f"{rows[-1][3]:.3g} paths/CPU-s", flush=True)
    text = [f"\n## {utc_now()}, commit {git_commit()}, {device}\n\n",
            f"`python benchmarks/studies/path_noise_sources.py --size {w}x{h} --samples {a.samples}`\n\n",
            "| light | mean colour | one path's relative deviation | paths for 2 % | paths per CPU-second |\n",
            "| --- | ---: | ---: | ---: | ---: |\n"]
    text += [f"| {nm} | {mu:.3f} | {dv:.2f} | {(dv / 0.02) ** 2:.0f} | {pps:.3g} |\n" for nm, mu, dv, pps in rows]
    append_study(a.out, "benchmarks/studies/path_noise_sources.py", "Where a path-traced picture's noise comes from", "".join(text))
    return 0


if __name__ == "__main__":
    sys.exit(main())
