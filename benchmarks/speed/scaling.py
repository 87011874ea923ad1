"""Render time and peak memory against image size, the default scene.

Each size runs in its own child process (so its peak resident memory, ru_maxrss, is its
own): a warm-up render at 64x48 builds the program, then one render at the size, timed,
every output kept (or only --outputs, e.g. ``depth``; --force for sizes whose work estimate
is refused).  Reports
pixels per second and peak memory per pixel above the warm process's baseline.

Writes benchmarks/results/scaling.md (appends a section per run: device, date, commit).

    python benchmarks/speed/scaling.py [--sizes 160x120,640x480,1920x1080,3840x2160] [--set KEY=VALUE ...]
    python benchmarks/speed/scaling.py --sizes 20000x20000 --outputs depth --force   # bounded memory
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser  # noqa: E402

CHILD = r"""
import json, resource, sys, time, warnings
warnings.simplefilter("ignore")
from pyjulia4d import Scene, render
w, h = (int(x) for x in sys.argv[1].split("x"))
outputs = None if sys.argv[2] == "all" else sys.argv[2].split(",")
force = sys.argv[3] == "force"
over = sys.argv[4:]
render(Scene.default().with_overrides(over + ["image.width=64", "image.height=48"]), outputs=outputs)
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
t = time.perf_counter()
r = render(Scene.default().with_overrides(over + [f"image.width={w}", f"image.height={h}"]),
           outputs=outputs, force=force)
sec = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"seconds": sec, "kernel_seconds": r.kernel_seconds, "peak": peak, "base": base,
                  "device": r.device_name, "hit": r.hit_fraction}))
"""


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="160x120,320x240,640x480,1280x960,1920x1080,3840x2160")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--outputs", default="all", help="comma-separated render outputs kept (default all)")
    ap.add_argument("--force", action="store_true", help="render sizes whose work estimate is refused")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    rows, device = [], "?"
    for size in a.sizes.split(","):
        p = subprocess.run([sys.executable, "-c", CHILD, size, a.outputs,
                            "force" if a.force else "-", *a.set], capture_output=True, text=True,
                           cwd=ROOT, timeout=3600)
        if p.returncode != 0:
            print(f"{size}: failed: {(p.stderr.strip().splitlines() or ['?'])[-1]}", file=sys.stderr)
            return 1
        r = json.loads(p.stdout)
        device = r["device"]
        w, h = (int(x) for x in size.split("x"))
        px = w * h
        extra = max(r["peak"] - r["base"], 0)
        rows.append(f"| {size} | {px:,} | {r['seconds']:.3f} | {r['kernel_seconds']:.3f} | {px / r['seconds']:.3g} | "
                    f"{r['peak'] / 2**20:.0f} | {extra / px:.0f} | {100 * r['hit']:.1f} % |")
        print(rows[-1], flush=True)
    head = (f"\n## {utc_now()}, {device}, commit {git_commit()}"
            f"{', ' + ' '.join(a.set) if a.set else ''}, outputs {a.outputs}\n\n"
            "| size | pixels | render s | kernels s | pixels/s | peak RSS MiB | bytes/pixel above the warm process | hit |\n"
            "|---|---|---|---|---|---|---|---|\n")
    md = a.out / "scaling.md"
    append_run(md, "# Render time and peak memory against image size\n\nWritten by "
               "`python benchmarks/speed/scaling.py`.\n", head + "\n".join(rows) + "\n")
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
