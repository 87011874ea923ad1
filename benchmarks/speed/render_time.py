"""How long the default scene takes to render, per device: the number README quotes.

    python benchmarks/speed/render_time.py [--repeats 5] [--device SPEC] [--out benchmarks/results]

The first render builds the OpenCL program (reported separately as "first");
the median of the following renders is the steady-state time, whole render and
kernels alone; a path-traced scene's paths per second (width x height x image.samples over
the median) beside its keys.  Writes render_time.md (appends a row per run) with device, date
and git commit; with no --set it also saves default.png, README's picture.
"""
from __future__ import annotations

import datetime
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from pyjulia4d import Scene, render  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from pyjulia4d.app.output import write_png  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit  # noqa: E402
from benchmarks.lib.args import Parser  # noqa: E402


def main(argv=None) -> None:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--device", default=None)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    scene = Scene.default().with_overrides(a.set)
    dev = select_device(a.device)
    t0 = time.perf_counter()
    first = render(scene, device=dev)
    first_s = time.perf_counter() - t0
    runs = [render(scene, device=dev) for _ in range(a.repeats)]
    whole = statistics.median(r.seconds for r in runs)
    kern = statistics.median(r.kernel_seconds for r in runs)
    w, h = scene.image.width, scene.image.height
    what = ' '.join(a.set) or 'default'
    if scene.shading.integrator == "path":   # the path tracer's rate: every pixel's paths over the median
        what += f" ({w * h * scene.image.samples / whole:.3g} paths/s)"
    row = (f"| {datetime.date.today()} | {git_commit()} | {first.device_name} | {w}x{h} | "
           f"{what} | {first_s:.2f} | {whole:.3f} | {kern:.3f} | "
           f"{first.hit_fraction:.1%} |")
    head = ("| date | commit | device | size | overrides | first render s (with build) | "
            "median render s | median kernels s | hit |\n|---|---|---|---|---|---|---|---|---|\n")
    append_run(a.out / "render_time.md", "# Default-scene render time\n\n" + head, row + "\n")
    if not a.set:  # the README's picture is this render
        write_png(a.out / "default.png", first.color, first.alpha)
    print(head + row)


if __name__ == "__main__":
    main()
