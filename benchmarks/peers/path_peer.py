"""The path tracer beside Mandelbulber2's Monte Carlo light, at equal noise.

Both render the matched default scene (peers.py: Mandelbulber2's quaternion Julia set of the
same c, camera and colour) lit by a white sky alone, with global illumination and depth of
field: pyjulia4d with shading.integrator = "path" (a uniform environment of radiance 1, 3
bounces, a lens of radius --aperture focused on the target), Mandelbulber2 2.20 with its
Monte Carlo algorithm (DOF_monte_carlo, DOF_MC_global_illumination, white background, main
light off, DOF_radius --mb-dof, focus on the target), on its CPU path and its OpenCL path.

Each renderer is measured against its own converged reference (--reference samples per
pixel), rendered independently of the sweep (pyjulia4d's from sample 2^30 on, so no path is
shared; Mandelbulber2 seeds each run afresh): the relative RMSE over the pixels the
reference covers (its alpha above 0.5; both pictures linear, Mandelbulber2's decoded from its
sRGB PNG).  Against an independent reference of N_ref samples the measured error is
sqrt(e^2 + e_ref^2), and where both fall as 1/sqrt(samples), e_ref^2 = e^2 N / N_ref, so

    e = measured x sqrt(N_ref / (N + N_ref))

is each renderer's own error at N samples (the same correction for both; printed beside the
measured one).  The sample count where each reaches --target (2 %) is interpolated log-log
between the counts around it, and its CPU-seconds likewise (the render's for pyjulia4d, the
child's for Mandelbulber2); the result is each renderer's pixels per CPU-second at that noise,
and their ratio.  Mandelbulber2 runs on its CPU path and, where its OpenCL path starts (a
system OpenCL driver such as Debian's pocl-opencl-icd), on that too.  It is never a
dependency: where it is not installed (Debian: apt-get install mandelbulber2) the script
says so and measures pyjulia4d alone.  Appends a section to benchmarks/results/path_peer.md.

    python benchmarks/peers/path_peer.py [--size 80x60] [--reference 1024] [--samples 4 8 16 32 64]
"""
from __future__ import annotations

import math
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.peers.peers import MATCHED, MB_CPU, MB_OPENCL, _mb_render, mb_env, mb_settings, mb_warm  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402
from pyjulia4d.pipeline.colormap import srgb_to_linear  # noqa: E402

FOCUS = math.sqrt(1.8 ** 2 + 1.6 ** 2 + 2.2 ** 2)   # the default camera's distance to its target


def pj_scene(w: int, h: int, samples: int, aperture: float) -> Scene:
    return Scene.default().with_overrides(MATCHED + [
        "shading.integrator=path", "shading.environment=uniform", "shading.ambient=1", "shading.sky=1,1,1",
        "shading.light_color=0,0,0", "shading.bounces=3", "shading.background=1,1,1", f"camera.aperture={aperture}",
        f"camera.focus={FOCUS}", f"image.width={w}", f"image.height={h}", f"image.samples={samples}"])


REF_FIRST = 2 ** 30   # the reference's first sample: past any sweep's, so none is shared


def pj_render(w, h, samples, aperture, first=0):
    c0 = os.times()
    r = render(pj_scene(w, h, samples, aperture), calibrate=False, first_sample=first)
    c1 = os.times()
    return r.color.astype(np.float64), r.alpha, (c1.user - c0.user) + (c1.system - c0.system)


def mb_fract(w: int, h: int, samples: int, dof: float) -> str:
    s = mb_settings(w, h)
    s = s.replace("DOF_enabled false;", "\n".join([
        "DOF_enabled true;", "DOF_monte_carlo true;", "DOF_MC_global_illumination true;", f"DOF_samples {samples};",
        f"DOF_min_samples {samples};", "DOF_max_noise 0,001;", f"DOF_radius {dof};",
        f"DOF_focus {str(FOCUS).replace('.', ',')};"]))
    for k in (1, 2, 3):
        s = s.replace(f"background_color_{k} 0000 0000 0000;", f"background_color_{k} ffff ffff ffff;")
    return s.replace("[main_parameters]\n", "[main_parameters]\nmain_light_intensity 0;\n")


def mb_render(w, h, samples, dof, tmp: Path, over: str = MB_CPU):
    from PIL import Image
    src = tmp / f"s{samples}.fract"
    src.write_text(mb_fract(w, h, samples, dof))
    cpu, _ = _mb_render(src, w, h, over, tmp / f"o{samples}", mb_env(tmp))
    with Image.open(tmp / f"o{samples}.png") as im:
        a = np.asarray(im).astype(np.float64)
    top = 65535.0 if a.max() > 255 else 255.0
    return srgb_to_linear(a[..., :3] / top), a[..., 3] / top, cpu


def rel_rmse(img, ref, mask) -> float:
    return float(np.sqrt(np.mean((img[mask] - ref[mask]) ** 2)) / np.mean(ref[mask]))


def at_target(rows, target):
    """(samples, CPU-s) where the relative RMSE crosses ``target``, log-log between the
    counts around it; None where no count reached it."""
    for (s0, e0, c0), (s1, e1, c1) in zip(rows, rows[1:]):
        if e0 > target >= e1:
            f = math.log(e0 / target) / math.log(e0 / e1)
            return s0 * (s1 / s0) ** f, c0 * (c1 / c0) ** f
    if rows and rows[0][1] <= target:
        return rows[0][0], rows[0][2]
    return None


def own_error(measured: float, samples: int, reference: int) -> float:
    """The render's own error, less its independent reference's: measured x sqrt(N_ref / (N + N_ref))."""
    return measured * math.sqrt(reference / (samples + reference))


def sweep(name, run, run_ref, counts, reference, target):
    ref, alpha, ref_cpu = run_ref(reference)
    mask = alpha > 0.5
    rows, measured = [], []
    for s in counts:
        img, _, cpu = run(s)
        m = rel_rmse(img, ref, mask)
        measured.append(m)
        rows.append((s, own_error(m, s, reference), cpu))
        print(f"{name:18s} {s:5d} samples: relative RMSE {100 * m:6.2f} % measured, {100 * rows[-1][1]:6.2f} % its own  "
              f"{cpu:7.2f} CPU-s", flush=True)
    return rows, measured, at_target(rows, target), ref_cpu, int(mask.sum())


def main() -> None:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="80x60")
    ap.add_argument("--reference", type=int, default=1024)
    ap.add_argument("--samples", type=int, nargs="+", default=[4, 8, 16, 32, 64, 128])
    ap.add_argument("--target", type=float, default=0.02)
    ap.add_argument("--aperture", type=float, default=0.05, help="pyjulia4d's lens radius (default 0.05)")
    ap.add_argument("--mb-dof", type=float, default=4.0, help="Mandelbulber2's DOF_radius (default 4)")
    a = ap.parse_args()
    w, h = size_of(a.size)
    render(pj_scene(16, 12, 1, a.aperture))   # programs built before any timing
    results = {"pyjulia4d": sweep("pyjulia4d", lambda s: pj_render(w, h, s, a.aperture),
                                  lambda s: pj_render(w, h, s, a.aperture, REF_FIRST), a.samples, a.reference, a.target)}
    if shutil.which("mandelbulber2"):
        with tempfile.TemporaryDirectory() as td:
            for name, over, opencl in (("Mandelbulber2 CPU", MB_CPU, False), ("Mandelbulber2 OpenCL", MB_OPENCL, True)):
                why = mb_warm(w, h, Path(td), over, opencl)
                if why is not None:
                    print(f"{name} skipped: {why}")
                    continue
                run = lambda s, over=over: mb_render(w, h, s, a.mb_dof, Path(td), over)  # noqa: E731
                results[name] = sweep(name, run, run, a.samples, a.reference, a.target)
    else:
        print("mandelbulber2 not installed (Debian: apt-get install mandelbulber2): measured pyjulia4d alone")
    lines = [f"\n## {utc_now()}, commit {git_commit()}\n\n",
             f"`python benchmarks/peers/path_peer.py --size {w}x{h} --reference {a.reference} --samples "
             f"{' '.join(map(str, a.samples))}`: the matched default scene under a white sky, global illumination and "
             f"depth of field; each renderer against its own {a.reference}-sample reference; equal noise = "
             f"{100 * a.target:.0f} % relative RMSE.\n\n",
             "| renderer | samples | relative RMSE measured | its own | CPU-s |\n| --- | ---: | ---: | ---: | ---: |\n"]
    speed = {}
    for name, (rows, measured, hit, ref_cpu, px) in results.items():
        lines += [f"| {name} | {s} | {100 * m:.2f} % | {100 * e:.2f} % | {c:.2f} |\n"
                  for (s, e, c), m in zip(rows, measured)]
        if hit is not None:
            speed[name] = w * h / hit[1]
    lines.append("\n")
    for name, (rows, measured, hit, ref_cpu, px) in results.items():
        lines.append(f"- {name}: reference {ref_cpu:.1f} CPU-s; " + (
            f"{100 * a.target:.0f} % at about {hit[0]:.0f} samples, {hit[1]:.2f} CPU-s: {speed[name]:.0f} pixels per "
            f"CPU-second\n" if hit else f"did not reach {100 * a.target:.0f} % within the counts measured\n"))
    for name in speed:
        if name != "pyjulia4d" and "pyjulia4d" in speed:
            lines.append(f"- ratio at equal noise: pyjulia4d {speed['pyjulia4d'] / speed[name]:.1f}x {name}'s pixels "
                         f"per CPU-second\n")
    text = "".join(lines)
    print(text, end="")
    append_run(ROOT / "benchmarks" / "results" / "path_peer.md",
               "# The path tracer beside Mandelbulber2 at equal noise\n\nWritten by benchmarks/peers/path_peer.py; "
               "a section per run.\n", text)


if __name__ == "__main__":
    main()
