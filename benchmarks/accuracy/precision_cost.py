"""What double precision buys a proven render, and what it costs: each pair's default view
rendered at render.float = "single" and "double", side by side in one run, with the p99 of
the error each render states (bracket plus unresolved reach, RenderResult.error_stats), its
unresolved hit pixels, and the least CPU-seconds (user + system of this process) of
--repeats renders after a warm-up.

Where an orbit stretches its points apart fast (the commutative rules, the CQuats, the
hypercomplex sin and cos), the rounding bounds a proof must carry (kernels/enclose/disc.cl:
a few ulps of the working precision, amplified by every iteration) outgrow what the last
iteration leaves beyond the bailout, and no segment near the surface can be proven in single
precision; double's bounds are 2^-28 of single's.  The real error is the same either way
(benchmarks/accuracy/pair_accuracy.py --set render.float=double).  Appends a section to
benchmarks/results/precision_cost.md.

    python benchmarks/accuracy/precision_cost.py [--size 320x240] [--repeats 3] [--only NAME ...]
"""
from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402

PAIRS = ["hypercomplex_sin", "hypercomplex_cos", "hypercomplex_cosh", "hypercomplex_cube", "quaternion_cube",
         "cquat_sqr", "cquat_cube", "commutative_sqr", "commutative_cube"]


def cpu_seconds(scene: Scene, dev, repeats: int):
    """The least CPU-seconds of ``repeats`` renders after a warm-up one, and the last result."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = render(scene, device=dev, calibrate=False)   # programs built, camera.fit resolved
        scene = result.scene
        best = float("inf")
        for _ in range(repeats):
            c0 = os.times()
            result = render(scene, device=dev, calibrate=False)
            c1 = os.times()
            best = min(best, (c1.user - c0.user) + (c1.system - c0.system))
    return best, result


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", nargs="*", default=[], help="pairs as algebra_function, e.g. hypercomplex_sin")
    ap.add_argument("--device", default=None)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size)
    dev = select_device(a.device)
    head = ("| pair | stated p99, single | stated p99, double | unresolved hits, single | double | "
            "CPU-s, single | double | double / single |\n|---|---|---|---|---|---|---|---|\n")
    print(head, end="")
    rows = []
    for name in a.only or PAIRS:
        algebra, function = name.split("_", 1)
        got = {}
        for fl in ("single", "double"):
            s = Scene.from_dict({"fractal": {"algebra": algebra, "function": function}},
                                [f"image.width={w}", f"image.height={h}", f"render.float={fl}"])
            sec, r = cpu_seconds(s, dev, a.repeats)
            got[fl] = (sec, r.error_stats()["p99"], r.unresolved_counts()["hit"])
        (s1, p1, u1), (s2, p2, u2) = got["single"], got["double"]
        ratio = f"{s2 / s1:.2f}" if s1 > 0 else "-"   # os.times counts in clock ticks: a tiny render may read 0
        row = f"| {algebra} {function} | {p1:.2g} | {p2:.2g} | {u1} | {u2} | {s1:.2f} | {s2:.2f} | {ratio} |"
        rows.append(row)
        print(row, flush=True)
    section = (f"\n## {utc_now()}, commit {git_commit()}, {dev.name.strip()} ({dev.platform.name.strip()}), "
               f"{w}x{h}\n\n`python benchmarks/accuracy/precision_cost.py --size {a.size} --repeats {a.repeats}`"
               f"{' --only ' + ' '.join(a.only) if a.only else ''}: each pair's default view, least CPU-seconds "
               f"of {a.repeats} renders after a warm-up.\n\n" + head + "\n".join(rows) + "\n")
    append_run(a.out / "precision_cost.md",
               "# What double precision buys a proven render, and what it costs\n", section)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
