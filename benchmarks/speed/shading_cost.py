"""What each shading term costs: the default scene at 640x480, plain (light at the eye, no
shadows, no occlusion) and with each term
of kernels/shade/light.cl (shadows, ambient occlusion, colour maps), alone and together.

Every variant renders once to build (or load) its program, then --repeats times; the
median render time and the kernels' own time (profiled events) are reported, with the
ratio to the plain default scene measured in the same run.  Writes
benchmarks/results/shading_cost.md (a section per run: device, date, commit).

    python benchmarks/speed/shading_cost.py [--size 640x480] [--repeats 5]
"""
from __future__ import annotations

import statistics
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402

# every variant starts from the plain look (the default scene has soft shadows and occlusion on)
PLAIN = ["shading.light=eye", "shading.shadow=none", "shading.ao=0"]
LIGHT = ["shading.light=-3,4,-2"]
VARIANTS = {
    "plain (light at the eye)": [],
    "positioned light": LIGHT,
    "hard shadows": LIGHT + ["shading.shadow=hard"],
    "soft shadows": LIGHT + ["shading.shadow=soft"],
    "ambient occlusion 0.8": ["shading.ao=0.8"],
    "coloring iteration": ["shading.coloring=iteration"],
    "coloring trap": ["shading.coloring=trap"],
    "coloring w": ["shading.coloring=w"],
    "fog 0.8": ["shading.fog=0.8"],
    "soft shadows + AO + trap": LIGHT + ["shading.shadow=soft", "shading.ao=0.8", "shading.coloring=trap"],
    "the default look (soft shadows, AO 0.6)": ["shading.light=-2,5,-4", "shading.shadow=soft", "shading.ao=0.6"],
    "fixed scan, hard shadows + AO": LIGHT + ["march.method=fixed", "shading.shadow=hard", "shading.ao=0.8"],
    "three lights (2 in shading.lights), soft shadows": LIGHT + [
        "shading.shadow=soft", "shading.lights=position 3,1,-2 color 0.3,0.5,1 intensity 0.8; "
        "direction 0,-1,0.3 color 1,0.45,0.2 intensity 0.35"],
    "reflection 0.35": ["shading.reflection=0.35"],
    "the default look + reflection 0.35": ["shading.light=-2,5,-4", "shading.shadow=soft", "shading.ao=0.6",
                                           "shading.reflection=0.35"],
}


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    w, h = size_of(a.size, "--size")
    rows, base, device = [], None, "?"
    for name, over in VARIANTS.items():
        s = Scene.default().with_overrides(PLAIN + over + [f"image.width={w}", f"image.height={h}"])
        render(s)
        runs = [render(s) for _ in range(a.repeats)]
        sec = statistics.median(r.seconds for r in runs)
        ks = statistics.median(r.kernel_seconds for r in runs)
        device = runs[0].device_name
        base = base or sec
        rows.append(f"| {name} | {sec:.3f} | {ks:.3f} | {sec / base:.2f} |")
        print(rows[-1], flush=True)
    head = (f"\n## {utc_now()}, {device}, commit {git_commit()}, {w}x{h}, median of {a.repeats}\n\n"
            "| variant | render s | kernels s | / plain |\n|---|---|---|---|\n")
    append_run(a.out / "shading_cost.md", "# What each shading term costs\n\nWritten by "
               "`python benchmarks/speed/shading_cost.py`.\n", head + "\n".join(rows) + "\n")
    print(f"wrote {a.out / 'shading_cost.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
