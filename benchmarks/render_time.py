"""How long the default scene takes to render, per device: the number README quotes.

    python benchmarks/render_time.py [--repeats 5] [--device SPEC] [--out benchmarks/results]

The first render builds the OpenCL program (reported separately as "first");
the median of the following renders is the steady-state time, whole render and
kernels alone.  Writes render_time.md (appends a row per run) with device, date
and git commit; with no --set it also saves default.png, README's picture.
"""
from __future__ import annotations

import argparse
import datetime
import statistics
import subprocess
import time
from pathlib import Path

from pyjulia4d import Scene, render
from pyjulia4d.devices import select_device
from pyjulia4d.output import write_png


def git_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--device", default=None)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
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
    row = (f"| {datetime.date.today()} | {git_commit()} | {first.device_name} | {w}x{h} | "
           f"{' '.join(a.set) or 'default'} | {first_s:.2f} | {whole:.3f} | {kern:.3f} | "
           f"{first.hit_fraction:.1%} |")
    head = ("| date | commit | device | size | overrides | first render s (with build) | "
            "median render s | median kernels s | hit |\n|---|---|---|---|---|---|---|---|---|\n")
    a.out.mkdir(parents=True, exist_ok=True)
    md = a.out / "render_time.md"
    text = md.read_text() if md.exists() else "# Default-scene render time\n\n" + head
    md.write_text(text + row + "\n")
    if not a.set:  # the README's picture is this render
        write_png(a.out / "default.png", first.color, first.alpha)
    print(head + row)


if __name__ == "__main__":
    main()
