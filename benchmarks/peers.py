"""pyjulia4d beside POV-Ray's julia_fractal: pixels per CPU-second on the same scene.

The scene is pyjulia4d's default (c = -0.2 + 0.8i, quaternion sqr, 12 iterations, the eye
at (1.8, 1.6, -2.2) looking at the origin, 40 degrees vertical field of view, a light at the
eye), written as POV-Ray 3.7 SDL (seed 003's julia_fractal: `max_iteration 12`, POV-Ray's
default `precision 20`; a shadowless light, since pyjulia4d traces no shadow rays; the
horizontal angle POV-Ray wants from the vertical one).  Runs alternate, --repeats each:

* POV-Ray (Debian's `povray`, never a dependency): its own report of the trace's CPU
  seconds ("Trace Time ... using N thread(s) with X CPU-seconds total"), which leaves
  out start-up and parsing;
* pyjulia4d: a child process renders once to build and warm up, then the scene; the CPU
  seconds of that render (user + system of the whole process, PoCL's threads included,
  getrusage) - start-up, imports and the build left out; `march.quality` presets too.

Reports pixels per CPU-second, the ratio to POV-Ray, and the share of pixels hit (POV-Ray's
from the alpha of its PNG).  POV-Ray is skipped with a message where it is not installed.
Writes benchmarks/results/peers.md (appends a section per run).

    python benchmarks/peers.py [--size 640x480] [--repeats 3]
"""
from __future__ import annotations

import argparse
import json
import math
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "benchmarks") not in sys.path:
    sys.path.insert(0, str(ROOT / "benchmarks"))

from run_log import append_run, git_commit, utc_now  # noqa: E402

POV_SCENE = """#version 3.7;
global_settings {{ assumed_gamma 1.0 }}
camera {{ perspective location <{px}, {py}, {pz}> look_at <0, 0, 0> up y right x*{aspect} angle {hfov} }}
light_source {{ <{px}, {py}, {pz}> color rgb 1 shadowless }}
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

CHILD = r"""
import json, resource, sys, time, warnings
warnings.simplefilter("ignore")
from pyjulia4d import Scene, render
over = sys.argv[1:]
s = Scene.default().with_overrides(over)
render(s)
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
c0, t0 = cpu(), time.perf_counter()
r = render(s)
print(json.dumps({"cpu": cpu() - c0, "wall": time.perf_counter() - t0, "hit": r.hit_fraction,
                  "device": r.device_name}))
"""

VARIANTS = {"pyjulia4d default": [], "pyjulia4d march.quality=draft": ["march.quality=draft"],
            "pyjulia4d march.quality=normal": ["march.quality=normal"]}


def pov_scene(w: int, h: int) -> str:
    from pyjulia4d.scene import Scene

    s = Scene.default()
    px, py, pz = s.camera.position[:3]
    hfov = math.degrees(2 * math.atan(math.tan(math.radians(s.camera.fov) / 2) * w / h))
    c = s.fractal.c
    return POV_SCENE.format(px=px, py=py, pz=pz, aspect=f"{w}/{h}", hfov=f"{hfov:.4f}", c0=c[0], c1=c[1],
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


def run_pyjulia4d(over: list[str]) -> dict:
    p = subprocess.run([sys.executable, "-c", CHILD, *over], capture_output=True, text=True, cwd=ROOT,
                       timeout=3600)
    if p.returncode != 0:
        raise RuntimeError((p.stderr.strip().splitlines() or ["?"])[-1])
    return json.loads(p.stdout)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = (int(x) for x in a.size.split("x"))
    size = [f"image.width={w}", f"image.height={h}"]
    have_pov = shutil.which("povray") is not None
    if not have_pov:
        print("povray not installed (Debian: apt-get install povray): POV-Ray skipped", file=sys.stderr)
    runs: dict[str, list[dict]] = {}
    device = "?"
    with tempfile.TemporaryDirectory() as td:
        for _ in range(a.repeats):  # alternate, so the shared machine's load falls on all alike
            if have_pov:
                runs.setdefault("POV-Ray 3.7 julia_fractal (precision 20)", []).append(run_povray(w, h, Path(td)))
            for name, over in VARIANTS.items():
                r = run_pyjulia4d(over + size)
                device = r["device"]
                runs.setdefault(name, []).append(r)
    px = w * h
    pov = runs.get("POV-Ray 3.7 julia_fractal (precision 20)")
    pov_cpu = statistics.median(r["cpu"] for r in pov) if pov else 0.0
    pov_rate = px / pov_cpu if pov_cpu > 0 else None   # a tiny image can report 0.000 s
    lines = [f"\n## {utc_now()}, {w}x{h}, pyjulia4d on {device}, "
             f"commit {git_commit()}, median of {a.repeats} alternating runs\n",
             "| renderer | CPU s (median) | pixels per CPU-second | / POV-Ray | pixels hit |", "|---|---|---|---|---|"]
    for name, rs in runs.items():
        cpu = statistics.median(r["cpu"] for r in rs)
        rate = px / cpu if cpu > 0 else float("inf")
        ratio = f"{rate / pov_rate:.2f}" if pov_rate else "-"
        lines.append(f"| {name} | {cpu:.3f} | {rate:.3g} | {ratio} | {100 * statistics.median(r['hit'] for r in rs):.1f} % |")
        print(lines[-1], flush=True)
    md = a.out / "peers.md"
    append_run(md, "# pyjulia4d beside its peers\n\nWritten by `python benchmarks/peers.py` (see its "
               "docstring: the scene, what is timed, what is left out).\n", "\n".join(lines) + "\n")
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
