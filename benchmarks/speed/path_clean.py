"""How soon a path-traced picture is clean: the default set path-traced at 640x480, at each
sample count of --samples, with and without the denoiser, against a converged reference.

Per count: the CPU-seconds of the render (user + system of this process, the denoiser
included) and the relative RMSE of the picture against the --reference-sample render of
the same scene: the RMS over the set's pixels and the three channels of the difference,
over the reference's mean there.  Both pictures go through the same ACES tone map first
(what a viewer sees), and the reference's own noise (its stated standard error) is
printed beside them, the floor of what the measurement can tell.  The target: denoised
within 2 % in at most 10 CPU-seconds on the 2-core development machine.  Appends a section
to benchmarks/results/path_clean.md.

    python benchmarks/speed/path_clean.py [--size 640x480] [--reference 1024] [--samples 4 8 16 32]
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
from pyjulia4d.pipeline.tonemap import display  # noqa: E402

KEYS = ["shading.integrator=path", "shading.ambient=0.7", "shading.light_color=0.45,0.43,0.4",
        "image.tonemap=aces", "camera.position=2.036,1.77,-2.468,0"]


def scene(w: int, h: int, samples: int, denoise: bool) -> Scene:
    return Scene.default().with_overrides(KEYS + [f"image.width={w}", f"image.height={h}", f"image.samples={samples}",
                                                  f"image.denoise={'true' if denoise else 'false'}"])


def timed(sc: Scene):
    c0, t0 = os.times(), time.perf_counter()
    r = render(sc, calibrate=False)
    c1 = os.times()
    return r, (c1.user - c0.user) + (c1.system - c0.system), time.perf_counter() - t0


def rel_rmse(img, ref, mask) -> float:
    a, b = display(img, 0, "aces")[mask], display(ref, 0, "aces")[mask]
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.mean(b))


def main() -> None:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--reference", type=int, default=1024, help="the reference's paths per pixel (default 1024)")
    ap.add_argument("--samples", type=int, nargs="+", default=[4, 8, 16, 32])
    a = ap.parse_args()
    w, h = size_of(a.size)
    render(scene(32, 24, 1, True))   # the programs built and the denoiser loaded before any timing
    ref, ref_cpu, _ = timed(scene(w, h, a.reference, False))
    mask = ref.film.covered
    floor = float(np.sqrt(np.mean(ref.film.variance[mask])) / np.mean(ref.color[mask]))
    rows = []
    for s in a.samples:
        for dn in (False, True):
            r, cpu, wall = timed(scene(w, h, s, dn))
            e = rel_rmse(r.color, ref.color, mask)
            rows.append((s, dn, e, cpu, wall))
            print(f"{s:5d} paths {'denoised' if dn else 'noisy   '}: relative RMSE {100 * e:6.2f} %  {cpu:6.1f} CPU-s  "
                  f"{wall:5.1f} s", flush=True)
    text = [f"\n## {utc_now()}, commit {git_commit()}, {ref.device_name}\n\n",
            f"`python benchmarks/speed/path_clean.py --size {w}x{h} --reference {a.reference} --samples "
            f"{' '.join(map(str, a.samples))}`: the default set path-traced under the shipped sky, against a "
            f"{a.reference}-path render ({ref_cpu:.0f} CPU-s; its own relative noise {100 * floor:.2f} %), both through "
            f"the ACES tone map, over its {int(mask.sum())} covered pixels. Target: denoised within 2 % in 10 CPU-s.\n\n",
            "| paths | denoised | relative RMSE | CPU-s | wall s |\n| ---: | --- | ---: | ---: | ---: |\n"]
    text += [f"| {s} | {'yes' if dn else 'no'} | {100 * e:.2f} % | {c:.1f} | {wl:.1f} |\n" for s, dn, e, c, wl in rows]
    append_run(ROOT / "benchmarks" / "results" / "path_clean.md",
               "# How soon a path-traced picture is clean\n\nWritten by benchmarks/speed/path_clean.py; a section per run.\n",
               "".join(text))


if __name__ == "__main__":
    main()
