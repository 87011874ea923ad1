"""Depth error against run time for the algebras and functions beyond the quaternion square.

One scene per algebra beyond the quaternion square and per hypercomplex function named in
the README's "Algebras and functions" (quaternion cube, CQuat and commutative sqr,
hypercomplex sqr and cube, and the hypercomplex exp, sin, cosh, atan, ln, pwr),
each against a float64 ground truth that does not come from the setting under test:
``truth.ground_truth`` - for these pairs the double-precision kernels' fixed scan with 20
post-steps, its z-resolution doubled until two doublings in a row move at most 0.2 % of
the pixels by more than 1e-6 (then polished in float64 with the numpy reference's set
test), plus, for the quaternion cube (which has a distance estimate), the float64 de
search of the same module.  Every single-precision setting of a small grid is timed
(kernels alone, median of --repeats) and measured: silhouette error (pixels whose
hit/miss differs from the truth), depth error p50/p99/max on pixels both hit, the
certified bracket's p99, and the Jacobian normal's median angle to the truth's.

Writes benchmarks/results/algebra_error.md (a section per run: device, date, commit)
and algebra_error.csv (this run's rows).

    python benchmarks/algebra_error.py [--scenes q_cube,hc_exp] [--size 64x48] [--repeats 3]
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path


ROOT = Path(__file__).resolve().parent.parent
for p in (ROOT, ROOT / "benchmarks"):
    if str(p) not in sys.path:
        sys.path.insert(0, str(p))

from bench_args import Parser, size_of  # noqa: E402
from error_vs_time import measure_settings, write_error_tables  # noqa: E402

from pyjulia4d.measure import truth  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from pyjulia4d.scene.quality import PRESETS  # noqa: E402
from pyjulia4d.scene.model import Scene  # noqa: E402
from pyjulia4d.fractal.registry import has_distance_estimate

HC = ["fractal.algebra=hypercomplex"]
SCENES = {
    "q_cube": (["fractal.function=cube", "fractal.c=0.4,0.3,0,0", "fractal.max_iter=10"],
               "quaternion cube, c = 0.4+0.3i, max_iter 10"),
    "hc_sqr": (HC + ["fractal.function=sqr", "fractal.c=-0.2,0.8,0,0", "fractal.max_iter=10"],
               "hypercomplex sqr, c = -0.2+0.8i, max_iter 10"),
    "hc_cube": (HC + ["fractal.function=cube", "fractal.c=0.4,0,-0.6,0", "fractal.max_iter=8"],
                "hypercomplex cube, c = 0.4-0.6j, max_iter 8"),
    "hc_exp": (HC + ["fractal.function=exp", "fractal.c=0.5,0.8,0.2,0.1", "fractal.max_iter=8",
                     "camera.position=3.6,3.2,-4.4,0"],
               "hypercomplex exp, c = (0.5, 0.8, 0.2, 0.1), max_iter 8"),
    "hc_sin": (HC + ["fractal.function=sin", "fractal.c=0.5,0.8,0.2,0.1", "fractal.max_iter=8",
                     "camera.position=3.6,3.2,-4.4,0"],
               "hypercomplex sin, c = (0.5, 0.8, 0.2, 0.1), max_iter 8"),
    "hc_cosh": (HC + ["fractal.function=cosh", "fractal.c=0.3,0.2,0,0", "fractal.max_iter=8",
                      "camera.position=3.6,3.2,-4.4,0"],
                "hypercomplex cosh, c = 0.3+0.2i, max_iter 8"),
    "hc_atan": (HC + ["fractal.function=atan", "fractal.c=-0.5,0.3,0.1,0", "fractal.max_iter=8",
                      "fractal.bailout=2", "camera.position=5.4,4.8,-6.6,0"],
                "hypercomplex atan, c = (-0.5, 0.3, 0.1, 0), bailout 2, max_iter 8"),
    "hc_ln": (HC + ["fractal.function=ln", "fractal.c=0.3,0.2,0,0", "fractal.max_iter=8",
                    "fractal.bailout=2", "camera.position=5.4,4.8,-6.6,0"],
              "hypercomplex ln, c = 0.3+0.2i, bailout 2, max_iter 8"),
    "hc_pwr": (HC + ["fractal.function=pwr", "fractal.exponent=2.5,0.5", "fractal.c=-0.5,0.3,0.1,0",
                     "fractal.max_iter=8"],
               "hypercomplex pwr(2.5, 0.5), c = (-0.5, 0.3, 0.1, 0), max_iter 8"),
    "cquat_sqr": (["fractal.algebra=cquat", "fractal.c=-0.7323,-0.2179,0.1,0", "fractal.max_iter=12",
                   "camera.position=-2,1,5,0"],
                  "CQuat sqr, c = -0.7323-0.2179i+0.1j, max_iter 12"),
    "comm_sqr": (["fractal.algebra=commutative", "fractal.c=-0.7323,-0.2179,0.1,0", "fractal.max_iter=12",
                  "camera.position=-2,1,5,0"],
                 "commutative sqr, Ödegaard & Wennergren Fig. 7's c = -0.7323-0.2179i+0.1j, max_iter 12"),
}

FIXED = [(z, p) for z in (70, 250, 1000, 4000) for p in (0, 4, 10)]
DE = [(e, p) for e in (1e-3, 1e-4, 1e-5) for p in (4, 10)]


def settings(scene: Scene) -> list[tuple[str, list[str]]]:
    """(label, march overrides) of the grid; de and the presets where the pair has an estimate."""
    out = [(f"fixed z={z} post={p}", ["march.method=fixed", f"march.z_resolution={z}", f"march.post_steps={p}"])
           for z, p in FIXED]
    if has_distance_estimate(scene.fractal):
        out += [(f"de eps={e:g} post={p}", ["march.method=de", f"march.epsilon={e}", f"march.post_steps={p}"])
                for e, p in DE]
        if scene.fractal.algebra == "quaternion":   # the presets were measured on quaternions
            out += [(f"preset {q}", [f"march.quality={q}"]) for q in PRESETS]
    return out


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--size", default="64x48")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore", RuntimeWarning)
    w, h = size_of(a.size, "--size")
    dev = select_device(None)
    t_all = time.perf_counter()
    rows, truths = [], {}
    for name in a.scenes.split(","):
        over, desc = SCENES[name]
        base = Scene.default().with_overrides(over + [f"image.width={w}", f"image.height={h}",
                                                      "normals.method=jacobian"])
        tr = truth.ground_truth(base, z_start=4000, max_z=128000)
        conv = tr.record.get("converged", "")
        truths[name] = (tr, desc)
        print(f"[{time.perf_counter() - t_all:6.0f} s] {name}: truth {tr.kind} in {tr.seconds:.1f} s, "
              f"hit {tr.hit.mean():.3f}, converged {conv}", flush=True)
        rows += measure_settings(name, base, settings(base), tr, dev, a.repeats)
    a.out.mkdir(parents=True, exist_ok=True)
    write_error_tables(a.out, "algebra_error", "Depth error against run time, algebras and functions",
                       "algebra_error.py", rows, truths, dev.name.strip(), (w, h), time.perf_counter() - t_all)
    print(f"wrote {a.out / 'algebra_error.md'} in {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
