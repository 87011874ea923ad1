"""Gallery pictures and depth error against run time for the sets beside the Julia set:
quaternion and hypercomplex Mandelbrot sets (fractal.kind = "mandelbrot"), rotated
quaternion Julia sets (fractal.theta, Hart, Sandin & Kauffman 1989 §2.3), Julia set stacks (fractal.kind =
"julia_stack", Hart, Sandin & Kauffman 1989 §5.1; its "de" rows are the empirical estimate) and the cubic
connectedness locus (fractal.kind = "cubic_locus", Hart, Sandin & Kauffman 1989 §5.2; fixed scan only).

Pictures: each scene of GALLERY rendered from the CLI's code path (pyjulia4d.render) at
--picture size, written to benchmarks/results/kinds/<name>.png.

Error table: each scene of ERROR against ``truth.ground_truth`` (the double-precision
kernels' fixed scan with 20 post-steps, its z-resolution doubled until converged, polished
in float64 by the numpy twin's set test; plus the float64 de search where the pair has an
estimate) - never the single-precision setting under test - for a small grid of march
settings, timed (kernels alone, median of --repeats) and measured as in
benchmarks/accuracy/error_vs_time.py: silhouette error, depth error p50/p99/max on pixels both hit,
the certified bracket's p99, the Jacobian normal's median angle to the truth's.

Writes benchmarks/results/kinds/<name>.png, kinds_error.csv (this run's rows) and
kinds_error.md (a section per run: device, date, commit).

    python benchmarks/galleries/kinds_gallery.py [--size 64x48] [--picture 480x360] [--repeats 3]
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path


ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.accuracy.error_vs_time import measure_settings, write_error_tables  # noqa: E402

from pyjulia4d.measure import truth  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from pyjulia4d.opencl.executor import render  # noqa: E402
from pyjulia4d.scene.model import Scene  # noqa: E402
from pyjulia4d.fractal.registry import has_distance_estimate

MANDEL = ["fractal.kind=mandelbrot"]
# camera looking at the Mandelbrot sets' centre (-0.5, 0, 0, 0) from above and in front
M_CAM = ["camera.position=-0.5,1.6,-2.9,0", "camera.target=-0.5,0,0,0"]
J_CAM = ["camera.position=2.3,2.05,-2.8,0", "camera.target=0,0,0,0"]
STACK = ["fractal.kind=julia_stack"]
LOCUS = ["fractal.kind=cubic_locus"]
GALLERY = {
    "mandelbrot_quaternion_sqr": (MANDEL + ["camera.position=-1.3,1.5,-2.6,0", "camera.target=-0.5,0,0,0",
                                            "fractal.max_iter=20", "march.epsilon=2e-4",
                                            "clip.planes=0,0,-1,0", "shading.shadow=none"],
                                  "quaternion Mandelbrot set q^2 + c, max_iter 20, cut open at z = 0: "
                                  "the cut face is the complex Mandelbrot set, the solid its revolution "
                                  "about the real axis"),
    "mandelbrot_quaternion_cube": (MANDEL + ["fractal.function=cube", "fractal.max_iter=14",
                                             "camera.position=-1.6,1.2,-2.4,0", "camera.fit=true",
                                             "march.epsilon=2e-4"],
                                   "quaternion Mandelbrot set q^3 + c, max_iter 14"),
    "mandelbrot_hypercomplex_sqr": (MANDEL + ["fractal.algebra=hypercomplex", "fractal.max_iter=14",
                                              "camera.position=-2.2,1.8,-2.6,0", "camera.target=-0.5,0,0,0",
                                              "camera.fit=true"],
                                    "hypercomplex Mandelbrot set h^2 + c (the product M x M in the "
                                    "split coordinates), max_iter 14"),
    "julia_theta_0": (J_CAM + ["fractal.c=-0.2,0.8,0,0"], "quaternion Julia set, c = -0.2+0.8i, theta 0"),
    "julia_theta_45": (J_CAM + ["fractal.c=-0.2,0.8,0,0", "fractal.theta=45"], "the same map rotated by 45 degrees"),
    "julia_theta_90": (J_CAM + ["fractal.c=-0.2,0.8,0,0", "fractal.theta=90"],
                       "rotated by 90 degrees: the complex Julia set turned a quarter, its quaternion "
                       "superset cut by another 3D space (Hart, Sandin & Kauffman 1989 Fig. 1)"),
    "julia_stack": (STACK + ["fractal.max_iter=20", "camera.position=2.0,2.4,-3.2,0", "image.samples=4"],
                    "Julia set stack (the default c-line): z^2 + c(u), c from -1 (the basilica, the cap "
                    "in front) to -0.1+0.75i (near the rabbit, at the back), max_iter 20"),
    "julia_stack_real": (STACK + ["fractal.c_from=0.25,0", "fractal.c_to=-1.3,0", "fractal.max_iter=20",
                                  "camera.position=2.2,2.6,-3.0,0", "image.samples=4"],
                         "Julia set stack along the real axis (Hart, Sandin & Kauffman 1989 Fig. 4, Im c = 0): c from 1/4 "
                         "(the cauliflower, in front) to -1.3, max_iter 20"),
    "cubic_locus_plus": (LOCUS + ["fractal.max_iter=8", "camera.fit=true", "image.samples=4"],
                         "cubic connectedness locus C+ (the orbit of +a bounded under z^3 - 3a^2 z + b), "
                         "the 3D slice Im b = 0 (Re a, Im a, Re b), within |(a, b)| <= 2, max_iter 8"),
    "cubic_locus_minus": (LOCUS + ["fractal.component=minus", "fractal.max_iter=8", "camera.fit=true",
                                   "image.samples=4"],
                          "C- (the orbit of -a), the same slice: C+ mirrored in a"),
    "cubic_locus_im_a": (LOCUS + ["fractal.max_iter=8", "slice.normal=0,1,0,0", "camera.position=-2.7,3.2,-4.0,0",
                                  "image.samples=4"],
                         "C+, the 3D slice Im a = 0 (Re a, Re b, Im b), max_iter 8"),
}
ERROR = {
    "mandel_q_sqr": (MANDEL + M_CAM + ["fractal.max_iter=12"], "quaternion Mandelbrot q^2 + c, max_iter 12"),
    "mandel_q_cube": (MANDEL + ["fractal.function=cube", "fractal.max_iter=10", "camera.position=0.2,1.7,-2.6,0"],
                      "quaternion Mandelbrot q^3 + c, max_iter 10"),
    "mandel_hc_sqr": (MANDEL + M_CAM + ["fractal.algebra=hypercomplex", "fractal.max_iter=10",
                                        "camera.position=-0.5,2.2,-3.4,0"],
                      "hypercomplex Mandelbrot h^2 + c, max_iter 10"),
    "julia_theta_90": (["fractal.c=-0.2,0.8,0,0", "fractal.theta=90", "fractal.max_iter=12"],
                       "quaternion Julia, c = -0.2+0.8i, theta 90, max_iter 12"),
    "stack": (STACK + ["fractal.max_iter=12", "camera.position=2.0,2.4,-3.2,0"],
              "Julia set stack, c from -1 to -0.1+0.75i (the defaults), max_iter 12; de: the empirical estimate"),
    "locus_plus": (LOCUS + ["fractal.max_iter=8", "camera.position=2.4,2.2,-3.0,0"],
                   "cubic locus C+, slice Im b = 0, max_iter 8 (fixed scan only: no estimate is known)"),
}
FIXED = [(250, 4), (1000, 4), (1000, 10)]
DE = [(1e-3, 4), (1e-4, 4), (1e-4, 10)]


def settings(scene: Scene) -> list[tuple[str, list[str]]]:
    # the locus has no estimate: a finer scan shows what the fixed scan needs for its thin tubes
    fixed = FIXED + [(4000, 10)] if scene.fractal.kind == "cubic_locus" else FIXED
    out = [(f"fixed z={z} post={p}", ["march.method=fixed", f"march.z_resolution={z}", f"march.post_steps={p}"])
           for z, p in fixed]
    # the stack's "de" is its empirical estimate (kernels/kind/julia_stack.cl), measured here
    if has_distance_estimate(scene.fractal) or scene.fractal.kind == "julia_stack":
        out += [(f"de eps={e:g} post={p}", ["march.method=de", f"march.epsilon={e}", f"march.post_steps={p}"])
                for e, p in DE]
    return out


def sheet(out: Path, names: list[str], cell=(320, 240), cols=3) -> None:
    """The pictures side by side, in GALLERY's order, on a dark ground: <out>/sheet.png."""
    from PIL import Image
    rows = -(-len(names) // cols)
    img = Image.new("RGB", (cell[0] * cols, cell[1] * rows), (24, 24, 28))
    for i, name in enumerate(names):
        im = Image.open(out / f"{name}.png").convert("RGBA").resize(cell, Image.LANCZOS)
        img.paste(im, (cell[0] * (i % cols), cell[1] * (i // cols)), im)
    img.save(out / "sheet.png")


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="64x48", help="error table image size")
    ap.add_argument("--picture", default="480x360", help="gallery picture size")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--skip-gallery", action="store_true")
    ap.add_argument("--skip-error", action="store_true")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "kinds")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore", RuntimeWarning)
    dev = select_device(None)
    a.out.mkdir(parents=True, exist_ok=True)
    t_all = time.perf_counter()
    if not a.skip_gallery:
        pw, ph = size_of(a.picture, "--picture")
        for name, (over, desc) in GALLERY.items():
            s = Scene.default().with_overrides(over + [f"image.width={pw}", f"image.height={ph}"])
            r = render(s, device=dev)
            r.save(a.out / f"{name}.png")
            print(f"{name}: {r.seconds:.2f} s, {100 * r.hit_fraction:.1f} % hit, guards {r.guards} - {desc}",
                  flush=True)
        sheet(a.out, list(GALLERY))
    if a.skip_error:
        return 0
    w, h = size_of(a.size, "--size")
    rows, truths = [], {}
    for name, (over, desc) in ERROR.items():
        base = Scene.default().with_overrides(over + [f"image.width={w}", f"image.height={h}",
                                                      "normals.method=jacobian", "camera.fit=false"])
        tr = truth.ground_truth(base, z_start=4000, max_z=128000)
        truths[name] = (tr, desc)
        print(f"[{time.perf_counter() - t_all:6.0f} s] {name}: truth {tr.kind} in {tr.seconds:.1f} s, "
              f"hit {tr.hit.mean():.3f}, converged {tr.record.get('converged', '')}", flush=True)
        rows += measure_settings(name, base, settings(base), tr, dev, a.repeats)
    write_error_tables(a.out, "kinds_error", "Depth error against run time: Mandelbrot sets and rotated Julia sets",
                       "kinds_gallery.py", rows, truths, dev.name.strip(), (w, h), time.perf_counter() - t_all)
    print(f"wrote {a.out} in {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
