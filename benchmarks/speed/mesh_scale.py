"""Meshes at several grid sizes: time by phase, peak memory, triangles, watertightness, and the
enclosed volume against a float64 count of the set on the same grid.

    python benchmarks/speed/mesh_scale.py [--resolutions 128,512] [--set KEY=VALUE ...] [--no-twin]
                                    [--preview PNG]

Each resolution runs in a child process (`pyjulia4d mesh`'s own build_mesh and write_mesh to
a temporary STL), so its peak resident memory is its own.  The parent then counts the grid
points inside the set with the float64 twin of the sampling kernel (reference/mesh.py, in
blocks of layers), unless --no-twin: the mesh's volume, the float32 kernel's grid count and
the float64 count, each in scene units cubed.  --preview draws the first resolution's mesh
with matplotlib (docs/mesh.md's picture).  Writes benchmarks/results/mesh_scale.md (a
section per run, with commit, device and date).
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results" / "mesh_scale.md"

CHILD = r"""
import json, resource, sys, time
from pathlib import Path
from pyjulia4d.scene.model import Scene
from pyjulia4d.app.mesh import build_mesh, write_mesh
from pyjulia4d.opencl.devices import select_device
n, overrides, out = int(sys.argv[1]), json.loads(sys.argv[2]), Path(sys.argv[3])
dev = select_device(None)
scene = Scene.default().with_overrides(overrides)
build_mesh(scene, 16, dev)   # the kernels built, outside the timing
t = time.perf_counter()
r = build_mesh(scene, n, dev)
write_mesh(out, r)
total = time.perf_counter() - t
m = r.mesh
print(json.dumps({"seconds": {**r.seconds, "with_write": total}, "triangles": len(m.faces),
                  "vertices": len(m.vertices), "watertight": bool(m.is_watertight),
                  "volume": float(m.volume) if m.is_watertight else None, "inside": r.inside_points,
                  "spacing": r.plan.spacing, "widest": r.widest_bracket, "bytes": out.stat().st_size,
                  "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, "device": dev.name.strip()}))
"""


def twin_count(overrides: list[str], n: int) -> int:
    """Grid points inside by the float64 twin, in blocks of layers."""
    import numpy as np

    from pyjulia4d.pipeline.mesh_plan import make_mesh_plan
    from pyjulia4d.reference.mesh import mesh_sample
    from pyjulia4d.scene.model import Scene

    plan = make_mesh_plan(Scene.default().with_overrides(overrides), n)
    step = max(1, (1 << 21) // (n * n))
    return sum(int(np.count_nonzero(mesh_sample(plan, k0, min(step, n - k0)))) for k0 in range(0, n, step))


def preview(path: Path, overrides: list[str], n: int) -> None:
    """The mesh drawn by matplotlib's plot_trisurf, lit from the upper left."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import LightSource

    from pyjulia4d.app.mesh import build_mesh
    from pyjulia4d.scene.model import Scene

    m = build_mesh(Scene.default().with_overrides(overrides), n).mesh
    v = m.vertices
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(111, projection="3d")
    ax.plot_trisurf(v[:, 0], v[:, 2], v[:, 1], triangles=m.faces, color=m.visual.vertex_colors[0, :3] / 255, shade=True,
                    lightsource=LightSource(azdeg=225, altdeg=45), linewidth=0, antialiased=False)
    mid = (v.max(axis=0) + v.min(axis=0)) / 2
    r = float((v.max(axis=0) - v.min(axis=0)).max()) / 2
    ax.set_xlim(mid[0] - r, mid[0] + r), ax.set_ylim(mid[2] - r, mid[2] + r), ax.set_zlim(mid[1] - r, mid[1] + r)
    ax.view_init(20, -50)
    ax.set_axis_off()
    ax.set_box_aspect((1, 1, 1), zoom=1.4)
    fig.savefig(path, dpi=100, bbox_inches="tight")


def main(argv=None) -> int:
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--resolutions", default="128,512")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--no-twin", action="store_true", help="skip the float64 count of the grid")
    ap.add_argument("--preview", type=Path, default=None, metavar="PNG")
    ap.add_argument("--out", type=Path, default=RESULTS)
    a = ap.parse_args(argv)
    sizes = [int(x) for x in a.resolutions.split(",")]
    rows, device = [], ""
    for n in sizes:
        with tempfile.TemporaryDirectory() as tmp:
            out = subprocess.run([sys.executable, "-c", CHILD, str(n), json.dumps(a.overrides), f"{tmp}/m.stl"],
                                 capture_output=True, text=True, check=True).stdout
        r = json.loads(out.strip().splitlines()[-1])
        device = r["device"]
        t = time.perf_counter()
        r["twin"] = None if a.no_twin else twin_count(a.overrides, n)
        r["twin_seconds"] = time.perf_counter() - t
        rows.append((n, r))
    lines = ["| grid | sample s | cubes s | vertices s | orient, normals, colour s | whole, with the STL s | peak MiB "
             "| triangles | watertight | mesh volume | float32 grid count | float64 grid count | STL MiB |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for n, r in rows:
        s, h3 = r["seconds"], r["spacing"] ** 3
        vol = f"{r['volume']:.5g}" if r["volume"] is not None else "-"
        twin = f"{r['twin'] * h3:.5g}" if r["twin"] is not None else "-"
        lines.append(f"| {n}^3 | {s['sample']:.2f} | {s['cubes']:.2f} | {s['vertices']:.2f} | {s['finish']:.2f} | "
                     f"{s['with_write']:.2f} | {r['peak_mib']:.0f} | {r['triangles']} | "
                     f"{'yes' if r['watertight'] else 'no'} | {vol} | {r['inside'] * h3:.5g} | {twin} | "
                     f"{r['bytes'] / 2 ** 20:.1f} |")
    text = "\n".join(lines) + f"\n\nDevice {device}; vertices within {max(r['widest'] for _, r in rows):.2g} " \
                              f"(scene units) of the surface by their brackets.\n"
    print(text)
    scene = f" with {' '.join(a.overrides)}" if a.overrides else " (the default scene)"
    append_run(a.out, "# Meshes by grid size (benchmarks/speed/mesh_scale.py)\n",
               f"\n## {utc_now()}, commit {git_commit()}{scene}\n\n`python benchmarks/speed/mesh_scale.py --resolutions "
               f"{a.resolutions}{''.join(' --set ' + o for o in a.overrides)}{' --no-twin' if a.no_twin else ''}`"
               f"\n\n{text}")
    if a.preview is not None:
        preview(a.preview, a.overrides, sizes[0])
    return 0


if __name__ == "__main__":
    sys.exit(main())
