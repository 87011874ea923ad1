"""pyjulia4d beside POV-Ray's julia_fractal and Mandelbulber2: pixels per CPU-second on the same scene.

The scene is pyjulia4d's default (c = -0.2 + 0.8i, quaternion sqr, 12 iterations, the eye
at (1.8, 1.6, -2.2) looking at the origin, 40 degrees vertical field of view, a light at the
eye, no shadows, no ambient occlusion: pyjulia4d's default with ``MATCHED``), written as POV-Ray 3.7 SDL (POV-Ray 3.6 documentation's julia_fractal: `max_iteration 12`, POV-Ray's
default `precision 20`; a shadowless light, since pyjulia4d traces no shadow rays; the
horizontal angle POV-Ray wants from the vertical one) and as a Mandelbulber2 2.20 settings
file (formula 5 "quaternion", julia_mode, N 12, bailout 4 as pyjulia4d's escape radius;
that formula is 3D, z -> (x^2-y^2-z^2, 2xy, 2xz) + c, which is the quaternion square on the
w = 0 slice exactly, since a k component that starts at 0 with c's at 0 stays 0.
Mandelbulber is z-up and right-handed where pyjulia4d and POV-Ray are y-up and left-handed,
so points go over as (x, y, z) -> (x, z, y); its quaternion then reads x + z i + y j, so c
goes over with i and j swapped (julia_c = (c0, c2, c1)): swapping i and j (with k -> -k) is
an automorphism of the quaternions, so the set lands exactly where (x, z, y) puts it.  Its
fov is 2 tan(vertical angle / 2); one directional light from the camera (main_light_alpha
= beta = 0, relative), no shadows, no ambient occlusion, glow, fog, reflections, DOF or
anti-aliasing; a black background and a 16-bit PNG with alpha).  Runs alternate, --repeats
each:

* POV-Ray (Debian's `povray`, never a dependency): its own report of the trace's CPU
  seconds ("Trace Time ... using N thread(s) with X CPU-seconds total"), which leaves
  out start-up and parsing;
* Mandelbulber2 (Debian's `mandelbulber2` 2.20, never a dependency; headless with
  `QT_QPA_PLATFORM=offscreen mandelbulber2 --nogui --format png16alpha --res WxH
  --output STEM --override KEY=V#... FILE.fract`): it reports only wall-clock time, so
  its CPU seconds are getrusage(RUSAGE_CHILDREN) around the process, minus those of the
  same command at 8x6 pixels run just before (start-up, loading and the OpenCL build are
  left out by that difference; writing the larger PNG stays in).  Each kind is run once
  at 8x6 first, the OpenCL ones at the full size too, to warm caches (PoCL builds a
  kernel per work-group size into its disk cache).  Its CPU path (its own threads, double
  precision) and, where its OpenCL path starts, that too (`opencl_enabled=1`, device type
  cpu: the system's PoCL through the ICD loader; its defaults: mode full, single
  precision).  Each at two surface thresholds: its default (detail_level 1: the distance
  estimate below one pixel's footprint, about 5e-3 at this distance and size) and a
  constant 1e-3, pyjulia4d's march.epsilon (constant_DE_threshold) - the finer one gives
  nearly pyjulia4d's silhouette;
* ``--look default``: pyjulia4d's default look (its point light, soft shadows, ambient
  occlusion) against POV-Ray lit by the same point light with its shadows on (hard shadow
  rays; POV-Ray traces no occlusion); Mandelbulber2 is left out;
* pyjulia4d: a child process renders once to build and warm up, then the scene; the CPU
  seconds of that render (user + system of the whole process, PoCL's threads included,
  getrusage) - start-up, imports and the build left out; `march.quality` presets too.  It
  keeps the outputs that ``pyjulia4d render -o picture.png`` keeps, colour and alpha (with
  the counts and the error report every render makes), since the peers write a picture
  alone: the depth, normal and position images an EXR holds cost about a tenth more.

Reports pixels per CPU-second, the ratio to POV-Ray, the ratio of pyjulia4d's default to
each row, and the share of pixels hit (POV-Ray's and Mandelbulber2's from the alpha of
their PNGs).  POV-Ray and Mandelbulber2 are each skipped with a message where they are not
installed (Mandelbulber2's OpenCL rows too where its OpenCL does not start).
Writes benchmarks/results/peers.md (appends a section per run).

    python benchmarks/peers/peers.py [--size 640x480] [--repeats 3] [--set fractal.max_iter=20] [--look default]
"""
from __future__ import annotations

import json
import math
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, add_look, size_of  # noqa: E402

POV_SCENE = """#version 3.7;
global_settings {{ assumed_gamma 1.0 }}
camera {{ perspective location <{px}, {py}, {pz}> look_at <0, 0, 0> up y right x*{aspect} angle {hfov} }}
{light}
julia_fractal {{
  <{c0}, {c1}, {c2}, {c3}>
  quaternion
  sqr
  max_iteration {max_iter}
  precision 20
  pigment {{ color rgb <0.95, 0.72, 0.42> }}
  finish {{ ambient 0.08 diffuse 0.92 specular 0.35 }}
}}
"""

# The peers trace no shadows and light from the camera: pyjulia4d's default scene with the
# light at the eye, no shadows and no ambient occlusion (matched lighting).
MATCHED = ["shading.light=eye", "shading.shadow=none", "shading.ao=0"]
SCENE_SET: list[str] = []   # --set: more overrides, for all three renderers (e.g. fractal.max_iter=20)
LOOK = list(MATCHED)        # --look default: [] (pyjulia4d's soft shadows and occlusion, POV-Ray's shadows)

CHILD = r"""
import json, resource, sys, time, warnings
warnings.simplefilter("ignore")
from pyjulia4d import Scene, render
from pyjulia4d.app.cli import CHANNEL_GROUPS
PNG = CHANNEL_GROUPS["RGBA"]   # what `render -o picture.png` keeps
over = sys.argv[1:]
s = Scene.default().with_overrides(over)
render(s, outputs=PNG)
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
c0, t0 = cpu(), time.perf_counter()
r = render(s, outputs=PNG)
print(json.dumps({"cpu": cpu() - c0, "wall": time.perf_counter() - t0, "hit": r.hit_fraction,
                  "device": r.device_name}))
"""

# Mandelbulber2 2.20 settings ("only modified parameters"; the rest keep their defaults)
MB_SETTINGS = """# Mandelbulber settings file
# version 2.20
# only modified parameters
[main_parameters]
ambient_occlusion_enabled false;
antialiasing_enabled false;
background_3_colors_enable false;
background_color_1 0000 0000 0000;
background_color_2 0000 0000 0000;
background_color_3 0000 0000 0000;
bailout {bailout};
basic_fog_enabled false;
camera {camera};
camera_top {top};
DOF_enabled false;
fov {fov};
formula_1 5;
glow_enabled false;
image_height {h};
image_width {w};
julia_c {julia_c};
julia_mode true;
main_light_alpha 0;
main_light_beta 0;
main_light_position_relative true;
main_light_visibility 0;
mat1_specular 1;
mat1_surface_color {color};
mat1_surface_gradient_enable false;
N {max_iter};
raytraced_reflections false;
shadows_enabled false;
target {target};
use_default_bailout false;
volumetric_fog_enabled false;
[fractal_1]
[fractal_2]
[fractal_3]
[fractal_4]
[fractal_5]
[fractal_6]
[fractal_7]
[fractal_8]
[fractal_9]
"""

MB_CPU = "opencl_enabled=0"
MB_OPENCL = "opencl_enabled=1#opencl_platform=0#opencl_device_type=3"  # 3: "cpu" (PoCL)
MB_FINE = "constant_DE_threshold=1#DE_thresh=0.001"                   # pyjulia4d's march.epsilon
MB_VARIANTS = {"Mandelbulber2 2.20 CPU, threshold 1 px (default)": (MB_CPU, False),
               "Mandelbulber2 2.20 CPU, threshold 1e-3": (MB_CPU + "#" + MB_FINE, False),
               "Mandelbulber2 2.20 OpenCL (PoCL), threshold 1 px (default)": (MB_OPENCL, True),
               "Mandelbulber2 2.20 OpenCL (PoCL), threshold 1e-3": (MB_OPENCL + "#" + MB_FINE, True)}
MB_TINY = (8, 6)  # the start-up run: its CPU seconds are taken from the full render's

VARIANTS = {"pyjulia4d default": [], "pyjulia4d march.quality=draft": ["march.quality=draft"],
            "pyjulia4d march.quality=normal": ["march.quality=normal"]}


def pov_scene(w: int, h: int) -> str:
    from pyjulia4d.scene.model import Scene

    s = Scene.default().with_overrides(LOOK + SCENE_SET)
    px, py, pz = s.camera.position[:3]
    if s.shading.light == "eye":   # the matched look: pyjulia4d's light at the eye casts no shadow
        light = f"light_source {{ <{px}, {py}, {pz}> color rgb 1 shadowless }}"
    else:                          # the default look: its positioned light, POV-Ray's shadows on
        lx, ly, lz = s.shading.light[:3]
        light = f"light_source {{ <{lx}, {ly}, {lz}> color rgb 1 }}"
    hfov = math.degrees(2 * math.atan(math.tan(math.radians(s.camera.fov) / 2) * w / h))
    c = s.fractal.c
    return POV_SCENE.format(light=light, px=px, py=py, pz=pz, aspect=f"{w}/{h}", hfov=f"{hfov:.4f}", c0=c[0], c1=c[1],
                            c2=c[2], c3=c[3], max_iter=s.fractal.max_iter)


def run_povray(w: int, h: int, tmp: Path) -> dict:
    src = tmp / "julia.pov"
    src.write_text(pov_scene(w, h))
    out = tmp / "julia.png"
    p = subprocess.run(["povray", f"+I{src}", f"+O{out}", f"+W{w}", f"+H{h}", "-D", "-A", "+UA"],
                       capture_output=True, text=True, cwd=tmp, timeout=3600)
    m = re.search(r"Trace Time:.*?with ([0-9.]+) CPU-seconds total", p.stdout + p.stderr, re.S)
    if p.returncode != 0 or not m:
        raise RuntimeError(f"povray failed: {(p.stderr.strip().splitlines() or ['?'])[-1]}")
    from PIL import Image

    alpha = np.asarray(Image.open(out).convert("RGBA"))[..., 3]
    return {"cpu": float(m.group(1)), "hit": float(np.mean(alpha > 0))}


def mb_settings(w: int, h: int) -> str:
    """pyjulia4d's default scene as a Mandelbulber2 settings file (see the docstring: y-up
    left-handed (x, y, z) -> z-up right-handed (x, z, y), c's i and j swapped)."""
    from pyjulia4d.scene.model import Scene

    s = Scene.default().with_overrides(MATCHED + SCENE_SET)
    cam, f = s.camera, s.fractal
    if (f.c[3] != 0 or cam.position[3] != 0 or cam.target[3] != 0 or cam.up[3] != 0
            or tuple(s.slice.normal) != (0, 0, 0, 1) or s.slice.distance != 0 or s.shading.light != "eye"):
        raise ValueError("the default scene is no longer a w = 0 slice with c's k at 0 and a light "
                         "at the eye: Mandelbulber2's 3D quaternion formula cannot render it")

    def num(x) -> str:
        return repr(float(x))

    def vec(v) -> str:  # pyjulia4d (x, y, z) -> Mandelbulber2 (x, z, y); for c: i <-> j
        return f"{num(v[0])} {num(v[2])} {num(v[1])}"

    color = " ".join(f"{round(min(max(x, 0.0), 1.0) * 65535):04x}" for x in s.shading.color)
    return MB_SETTINGS.format(bailout=num(f.bailout), camera=vec(cam.position), top=vec(cam.up),
                              target=vec(cam.target), fov=num(2 * math.tan(math.radians(cam.fov) / 2)),
                              w=w, h=h, julia_c=vec(f.c), color=color, max_iter=f.max_iter)


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _mb_render(src: Path, w: int, h: int, over: str, out: Path, env: dict) -> tuple[float, str]:
    """One mandelbulber2 --nogui render to out.png: (CPU seconds of the process, its output)."""
    out.with_suffix(".png").unlink(missing_ok=True)
    c0 = _children_cpu()
    p = subprocess.run(["mandelbulber2", "--nogui", "--format", "png16alpha", "--res", f"{w}x{h}",
                        "--output", str(out), "--override", over, str(src)],
                       capture_output=True, text=True, cwd=src.parent, env=env, timeout=3600)
    cpu = _children_cpu() - c0
    log = (p.stdout + p.stderr).replace("\r", "\n")
    if p.returncode != 0 or not out.with_suffix(".png").exists():
        last = [ln for ln in log.splitlines() if ln.strip()] or ["?"]
        raise RuntimeError(f"mandelbulber2 failed (exit {p.returncode}): {last[-1].strip()}")
    return cpu, log


def mb_env(tmp: Path) -> dict:
    return {**os.environ, "QT_QPA_PLATFORM": "offscreen", "XDG_RUNTIME_DIR": str(tmp)}


def mb_warm(w: int, h: int, tmp: Path, over: str, opencl: bool) -> str | None:
    """Warm-up renders at MB_TINY and, with OpenCL, at w x h too (PoCL compiles a kernel per
    work-group size, into its disk cache); None if they rendered (with OpenCL where asked),
    else why not."""
    src = tmp / "julia.fract"
    src.write_text(mb_settings(w, h))
    for size in [MB_TINY, (w, h)] if opencl else [MB_TINY]:
        try:
            _, log = _mb_render(src, *size, over, tmp / "mb_warm", mb_env(tmp))
        except RuntimeError as e:
            return str(e)
        if opencl and "OpenCl - rendering" not in log:
            errs = [ln.strip() for ln in log.splitlines() if "opencl" in ln.lower() or "error" in ln.lower()]
            return "its OpenCL path did not start" + (f" ({errs[-1]})" if errs else "")
    return None


def run_mandelbulber(w: int, h: int, tmp: Path, over: str) -> dict:
    """CPU seconds of a w x h render less those of the same render at MB_TINY just before."""
    src = tmp / "julia.fract"
    src.write_text(mb_settings(w, h))
    env = mb_env(tmp)
    tiny, _ = _mb_render(src, *MB_TINY, over, tmp / "mb_tiny", env)
    full, _ = _mb_render(src, w, h, over, tmp / "mb", env)
    from PIL import Image

    alpha = np.asarray(Image.open(tmp / "mb.png").convert("RGBA"))[..., 3]
    return {"cpu": max(full - tiny, 0.0), "cpu_process": full, "cpu_startup": tiny,
            "hit": float(np.mean(alpha > 0))}


def run_pyjulia4d(over: list[str]) -> dict:
    p = subprocess.run([sys.executable, "-c", CHILD, *LOOK, *over], capture_output=True, text=True, cwd=ROOT,
                       timeout=3600)
    if p.returncode != 0:
        raise RuntimeError((p.stderr.strip().splitlines() or ["?"])[-1])
    return json.loads(p.stdout)


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="change the scene for all three renderers (fractal.max_iter=20; keys POV-Ray's "
                         "and Mandelbulber2's translations take: fractal.c, fractal.max_iter, camera.*)")
    add_look(ap, " (Mandelbulber2 left out; matched: all three renderers)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    SCENE_SET[:] = a.set
    LOOK[:] = MATCHED if a.look == "matched" else []
    w, h = size_of(a.size, "--size")
    size = [f"image.width={w}", f"image.height={h}"] + a.set
    have_pov = shutil.which("povray") is not None
    if not have_pov:
        print("povray not installed (Debian: apt-get install povray): POV-Ray skipped", file=sys.stderr)
    have_mb = shutil.which("mandelbulber2") is not None and a.look == "matched"
    if a.look != "matched":
        print("--look default: Mandelbulber2 left out (its settings file is written for the matched look)",
              file=sys.stderr)
    elif not have_mb:
        print("mandelbulber2 not installed (Debian: apt-get install mandelbulber2): Mandelbulber2 skipped",
              file=sys.stderr)
    runs: dict[str, list[dict]] = {}
    device = "?"
    with tempfile.TemporaryDirectory() as td:
        mb_variants = {}
        if have_mb:  # warm up each kind once (PoCL's kernel cache); drop what does not start
            for name, (over, opencl) in MB_VARIANTS.items():
                why = mb_warm(w, h, Path(td), over, opencl)
                if why is None:
                    mb_variants[name] = over
                else:
                    print(f"{name} skipped: {why}", file=sys.stderr)
        for _ in range(a.repeats):  # alternate, so the shared machine's load falls on all alike
            if have_pov:
                runs.setdefault("POV-Ray 3.7 julia_fractal (precision 20)", []).append(run_povray(w, h, Path(td)))
            for name, over in mb_variants.items():
                runs.setdefault(name, []).append(run_mandelbulber(w, h, Path(td), over))
            for name, over in VARIANTS.items():
                r = run_pyjulia4d(over + size)
                device = r["device"]
                runs.setdefault(name, []).append(r)
    px = w * h

    def rate_of(rs: list[dict]) -> float:
        cpu = statistics.median(r["cpu"] for r in rs)
        return px / cpu if cpu > 0 else float("inf")  # a tiny image can report 0.000 s

    pov = runs.get("POV-Ray 3.7 julia_fractal (precision 20)")
    pov_rate = rate_of(pov) if pov else None
    pj_rate = rate_of(runs["pyjulia4d default"])
    scene = f", the scene with {', '.join(a.set)}" if a.set else ""
    if a.look == "default":
        scene += (", pyjulia4d's default look (soft shadows, ambient occlusion 0.6) against POV-Ray's "
                  "shadows from the same point light")
    lines = [f"\n## {utc_now()}, {w}x{h}{scene}, pyjulia4d on {device}, "
             f"commit {git_commit()}, median of {a.repeats} alternating runs\n",
             "| renderer | CPU s (median) | pixels per CPU-second | / POV-Ray | pyjulia4d default / this "
             "| pixels hit |", "|---|---|---|---|---|---|"]
    for name, rs in runs.items():
        cpu = statistics.median(r["cpu"] for r in rs)
        rate = rate_of(rs)
        ratio = f"{rate / pov_rate:.2f}" if pov_rate and math.isfinite(pov_rate) and rate > 0 else "-"
        pj = f"{pj_rate / rate:.2f}" if math.isfinite(rate) and math.isfinite(pj_rate) and rate > 0 else "-"
        lines.append(f"| {name} | {cpu:.3f} | {rate:.3g} | {ratio} | {pj} "
                     f"| {100 * statistics.median(r['hit'] for r in rs):.1f} % |")
        print(lines[-1], flush=True)
    mb_rows = {n: rs for n, rs in runs.items() if n.startswith("Mandelbulber2")}
    if mb_rows:
        notes = ", ".join(f"{n.removeprefix('Mandelbulber2 2.20 ')} {statistics.median(r['cpu_process'] for r in rs):.3f}"
                          f" - {statistics.median(r['cpu_startup'] for r in rs):.3f}" for n, rs in mb_rows.items())
        lines.append(f"\nMandelbulber2 reports only wall-clock time: its CPU s are those of the process at "
                     f"{w}x{h} less those of the same command at {MB_TINY[0]}x{MB_TINY[1]} just before "
                     f"(start-up, loading, OpenCL build; medians, s: {notes}).")
        print(lines[-1].strip(), flush=True)
    md = a.out / "peers.md"
    append_run(md, "# pyjulia4d beside its peers\n\nWritten by `python benchmarks/peers/peers.py` (see its "
               "docstring: the scene, what is timed, what is left out).\n", "\n".join(lines) + "\n")
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
