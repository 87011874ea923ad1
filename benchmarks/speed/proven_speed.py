"""What proving empty space costs: the proven march (march.quality = "normal") against the
fixed scan at z_resolution 1000 and the distance estimate, side by side in one run, as
ratios (this machine is shared and noisy), on the scenes the proof was asked to be fast on:
hypercomplex sin, cosh and pwr, and the quaternion default.

The proven march runs in packets of 8 rays (opencl/lanes.py PROVEN_LANES) or of the device's
widest, whichever its timed probe found faster; rows at 8 and at 16 lanes, where the device
takes them, keep that choice measured.
For each scene and march: the whole render's kernel seconds (median of --repeats after a
warm-up) and its CPU-seconds (the least of them; getrusage: the host's work and the kernels'
threads), also as a multiple of the estimate's (custom's) CPU-seconds, the tests per ray
(set tests for the scan, estimates for de, enclosures for proven), and what each render
states: the p99 of its stated error (bracket plus unresolved, RenderResult.error_stats; the
scan and the estimate state the whole ray in front of their hits) and its unresolved pixels.
The share of enclosures that proved their segment, per ray, comes from the float64 twin on
a 40x30 view (reference/march.py enc_prove counted).

    python benchmarks/speed/proven_speed.py [--size 320x240] [--repeats 3] [--device SPEC] [--only NAME ...]

Writes benchmarks/results/proven_speed.md (a section per run: commit, device, date).
"""
from __future__ import annotations

import importlib
import resource
import statistics
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from pyjulia4d import Scene, reference as ref, render  # noqa: E402
from pyjulia4d.geometry.camera import camera_frame  # noqa: E402
from pyjulia4d.pipeline.plan import march_args  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from pyjulia4d.opencl.lanes import lanes_for  # noqa: E402
from pyjulia4d.reference.formula import formula_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

SCENES = {"hypercomplex sin": {"algebra": "hypercomplex", "function": "sin"},
          "hypercomplex cosh": {"algebra": "hypercomplex", "function": "cosh"},
          "hypercomplex pwr": {"algebra": "hypercomplex", "function": "pwr"},
          "quaternion sqr (default)": {}}
MARCHES = {"proven, quality normal": ["march.quality=normal"],
           "proven, quality normal, 8 lanes": ["march.quality=normal"],    # opencl/lanes.py PROVEN_LANES
           "proven, quality normal, 16 lanes": ["march.quality=normal"],
           "fixed, z_resolution 1000": ["march.method=fixed", "march.z_resolution=1000"],
           "custom (the estimate, else the scan at 250)": ["march.quality=custom"]}
ESTIMATE = "custom (the estimate, else the scan at 250)"   # the CPU-seconds the others are set against


def proof_share(scene: Scene) -> float:
    """The share of enclosures that proved their segment, over a 40x30 view (the twin)."""
    M = importlib.import_module("pyjulia4d.reference.march")
    s = scene.with_overrides(["image.width=40", "image.height=30"])
    o, d = ref.generate_rays(camera_frame(s), 40, 30)
    F = formula_of(s.fractal)
    counts = [0, 0]
    original = M.enc_prove

    def counted(*a, **k):
        proven, margin, prefix = original(*a, **k)
        counts[0] += int(proven.sum())
        counts[1] += proven.size
        return proven, margin, prefix

    M.enc_prove = counted
    try:
        M.march(o, d, march_args(s, method="proven"), None, None, F, None)
    finally:
        M.enc_prove = original
    return counts[0] / max(counts[1], 1)


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def run(scene: Scene, dev, repeats: int, lanes: int | None = None) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = render(scene, device=dev, lanes=lanes)            # warm-up: builds, camera.fit
        fixed = r.scene
        ts, cpu = [], []
        for _ in range(repeats):
            c0 = _cpu()
            r = render(fixed, device=dev, lanes=lanes)
            cpu.append(_cpu() - c0)
            ts.append(r.kernel_seconds)
    hit = r.status == 1
    e = r.error_stats()
    un = r.unresolved_counts()
    return {"kernel_s": statistics.median(ts), "cpu_s": min(cpu), "tests": float(np.mean(r.samples[np.isfinite(r.depth) | ~hit])),
            "p99": e["p99"], "unresolved": un["hit"] + un["miss"], "pixels": r.status.size,
            "proven": r.proven, "scene": fixed}


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--device", default=None)
    ap.add_argument("--only", nargs="*", default=[], help="scenes by name, e.g. 'hypercomplex sin'")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")
    dev = select_device(a.device)
    head = ("| scene | march | kernel s | x the fixed scan | render CPU-s | x the estimate's | tests per ray | "
            "stated p99 error | unresolved pixels | enclosures that proved |\n|---|---|---|---|---|---|---|---|---|---|\n")
    print(head, end="")
    rows = []
    for name, fractal in SCENES.items():
        if a.only and name not in a.only:
            continue
        got = {}
        for mname, over in MARCHES.items():
            s = Scene.from_dict({"fractal": fractal} if fractal else {}, [f"image.width={w}", f"image.height={h}"] + over)
            width = lanes_for(dev, s.render.variant, False)
            forced = next((k for k in (8, 16) if f", {k} lanes" in mname and width >= k), None)
            got[mname] = run(s, dev, a.repeats, forced)
        base = got["fixed, z_resolution 1000"]["kernel_s"]
        est = got[ESTIMATE]["cpu_s"]
        for mname, g in got.items():
            share = f"{100 * proof_share(g['scene']):.0f} %" if g["proven"] else ""
            row = (f"| {name} | {mname} | {g['kernel_s']:.3f} | {g['kernel_s'] / base:.2f} | {g['cpu_s']:.3f} | "
                   f"{g['cpu_s'] / est:.2f} | {g['tests']:.1f} | "
                   f"{g['p99']:.2g} | {100 * g['unresolved'] / g['pixels']:.1f} % | {share} |")
            rows.append(row)
            print(row, flush=True)
    note = ("\nStated p99 error: bracket plus unresolved; the fixed scan and the estimate prove nothing in front of "
            "their hits, so they state the whole ray in front (their brackets alone are in pair_accuracy.md).\n")
    section = (f"\n## {utc_now()}, commit {git_commit()}, {dev.name.strip()} ({dev.platform.name.strip()}), {w}x{h}\n\n"
               + head + "\n".join(rows) + "\n" + note)
    append_run(a.out / "proven_speed.md", "# What proving empty space costs\n", section)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
