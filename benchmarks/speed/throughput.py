"""Quaternion iterations per second inside the march, against the device's FMA peak.

For each scene and precision it counts the iterations of f = q^2 + c that the march's set
tests make - the same kernel source built with -D COUNT_ITERATIONS, which adds a per-ray
counter (kernels/common/lanes.cl), summed on the host - and times the march kernel alone in the
normal build (median of --repeats after a warm-up launch, rays made once), one ray per
work-item and in packets (the width pyjulia4d.lanes probes for the device and precision),
and, in single precision, in packets of rays shuffled across the image (what divergence
costs: neighbouring pixels' rays take similar paths, random ones do not).  Iterations per
second = counted iterations / march seconds.

The peak: a kernel of independent FMA chains (8 chains of 512 dependent fma's per
work-item) on float, float4, float8 and float16 (double likewise), each width in a child
process, because PyPI's PoCL 3.0 killed the process with SIGSEGV on float16 and double8
kernels (a crash is recorded, never taken down with the benchmark).  flop/s = 2 x lanes x
chains x steps x work-items / s; the device's peak is the best width's.  One iteration of
q -> q^2 + c with its escape test is counted as 20 flops (the square: 4 products, 3
differences and 3 doubled products; + c: 4 adds; |q|^2: 4 fma's; the estimate's
derivative: 2 more), so the share of peak is it/s x 20 / peak.

Writes benchmarks/results/throughput.md (appends a section per run: device, date, commit).

    python benchmarks/speed/throughput.py [--repeats 5] [--device SPEC] [--size 640x480] [--widths 1,4,8,16]
                                          [--scenes 3] [--peak-items 65536]
"""
from __future__ import annotations

import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

import pyopencl as cl  # noqa: E402
import pyopencl.array as cla  # noqa: E402

from pyjulia4d.opencl import build  # noqa: E402
from pyjulia4d.pipeline import kernel_config  # noqa: E402
from pyjulia4d.geometry.camera import camera_frame, march_radius  # noqa: E402
from pyjulia4d.opencl.devices import select_device  # noqa: E402
from pyjulia4d.opencl.lanes import lanes_for, packet_pairs  # noqa: E402
from pyjulia4d.opencl.records import Precision  # noqa: E402
from pyjulia4d.opencl.runner import launch, march_items, queue_for  # noqa: E402
from pyjulia4d.scene.model import Scene  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

FLOPS_PER_ITERATION = 20
SCENES = {
    "default (de, epsilon 1e-3, 4 ITP steps)": [],
    "march.quality=normal": ["march.quality=normal"],
    "fixed z = 250 + 10 ITP steps": ["march.method=fixed", "march.z_resolution=250", "march.post_steps=10"],
}

FMA_SOURCE = """
#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)      /* expands W before pasting */
#ifdef DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double T1;
#define VT(n) CAT(double, n)
#else
typedef float T1;
#define VT(n) CAT(float, n)
#endif
#if W == 1
typedef T1 V;
#else
typedef VT(W) V;
#endif
__kernel void fma_peak(__global T1 *out, const T1 a, const T1 b)
{
    size_t i = get_global_id(0);
    V x0 = (V)(i * 1e-9), x1 = x0 + (V)(1), x2 = x0 + (V)(2), x3 = x0 + (V)(3);
    V x4 = x0 + (V)(4), x5 = x0 + (V)(5), x6 = x0 + (V)(6), x7 = x0 + (V)(7);
    for (int k = 0; k < 512; ++k) {
        x0 = fma(x0, (V)(a), (V)(b)); x1 = fma(x1, (V)(a), (V)(b));
        x2 = fma(x2, (V)(a), (V)(b)); x3 = fma(x3, (V)(a), (V)(b));
        x4 = fma(x4, (V)(a), (V)(b)); x5 = fma(x5, (V)(a), (V)(b));
        x6 = fma(x6, (V)(a), (V)(b)); x7 = fma(x7, (V)(a), (V)(b));
    }
    V s = x0 + x1 + x2 + x3 + x4 + x5 + x6 + x7;
    T1 acc = 0;
    for (int k = 0; k < W; ++k)     /* every lane feeds the output: nothing is dead code */
        acc += ((T1 *)&s)[k];
    out[i] = acc;
}
"""

CHILD = r"""
import json, sys, time
import numpy as np
import pyopencl as cl
from pyjulia4d.opencl.devices import build, select_device
spec, width, double, n, src = sys.argv[1] or None, int(sys.argv[2]), sys.argv[3] == "1", int(sys.argv[4]), sys.stdin.read()
dev = select_device(spec)
ctx = cl.Context([dev]); q = cl.CommandQueue(ctx)
opts = [f"-DW={width}"] + (["-DDOUBLE"] if double else [])
prg = build(cl.Program(ctx, src), opts)
k = prg.fma_peak
dt = np.float64 if double else np.float32
out = cl.Buffer(ctx, cl.mem_flags.WRITE_ONLY, n * 8)
k(q, (n,), (64,), out, dt(0.999999), dt(1e-7)); q.finish()
ts = []
for _ in range(5):
    t = time.perf_counter(); k(q, (n,), (64,), out, dt(0.999999), dt(1e-7)); q.finish()
    ts.append(time.perf_counter() - t)
t = sorted(ts)[len(ts) // 2]
print(json.dumps({"flops": 2.0 * width * 8 * 512 * n / t, "seconds": t}))
"""


def fma_peak(spec: str | None, width: int, double: bool, items: int = 1 << 16) -> dict:
    """flop/s of the FMA kernel at one width over ``items`` work-items, measured in a child
    process (a crash of the OpenCL compiler or runtime is reported, not suffered)."""
    w = 1 if width == 1 else width
    p = subprocess.run([sys.executable, "-c", CHILD, spec or "", str(w), "1" if double else "0", str(items)],
                       input=FMA_SOURCE, capture_output=True, text=True, cwd=ROOT, timeout=300)
    if p.returncode != 0:
        why = f"signal {-p.returncode}" if p.returncode < 0 else (p.stderr.strip().splitlines() or ["?"])[-1]
        return {"flops": float("nan"), "error": why[:120]}
    return json.loads(p.stdout)


def march_throughput(scene: Scene, dev, repeats: int, lanes: int = 1, shuffle: bool = False) -> dict:
    """Counted iterations of f in the march (one ray per work-item: the count is the
    algorithm's, whatever the variant), the march kernel's median time with ``lanes`` rays
    per work-item, and their ratio.  ``shuffle`` permutes the rays (seeded), so a packet
    holds rays from all over the image instead of neighbouring pixels: what divergence
    costs."""
    ctx, queue = queue_for(dev)
    pr = Precision(scene.render.float == "double")
    cfg = kernel_config.scene_config(scene, ray_buffers=True)
    counted = kernel_config.KernelConfig(cfg.pieces, cfg.defines + ("COUNT_ITERATIONS",))
    w, h = scene.image.width, scene.image.height
    n = w * h
    frame = camera_frame(scene)
    f, m = scene.fractal, scene.march
    origins, dirs, point = (cla.empty(queue, n, pr.vec_dtype) for _ in range(3))
    depth, bracket, unresolved = (cla.empty(queue, n, pr.scalar) for _ in range(3))
    status, samples, flags = (cla.empty(queue, n, np.int32) for _ in range(3))
    counts = cla.zeros(queue, n, np.int32)
    eye, fwd, right, up = (pr.v4(v) for v in (frame.position, frame.forward, frame.right, frame.up))
    near = -1.0 if m.near == "auto" else float(m.near)
    far = -1.0 if m.far == "auto" else float(m.far)
    args = (origins.data, dirs.data, pr.v4(f.c), np.int32(f.max_iter), pr.scalar(f.bailout),
            pr.scalar(m.epsilon), pr.scalar(march_radius(scene)), pr.scalar(near), pr.scalar(far),
            np.int32(m.z_resolution), np.int32(m.post_steps), np.int32(m.max_steps), depth.data,
            point.data, status.data, samples.data, flags.data, bracket.data, unresolved.data)
    prg = build.program(ctx, cfg)
    mcfg = kernel_config.march_config(scene, lanes, ray_buffers=True, pairs=packet_pairs(dev, lanes, scene.render.float == "double"))
    mprg = prg if lanes == 1 else build.program(ctx, mcfg)
    launch(queue, cl.Kernel(prg, "generate_rays"), n, eye, fwd, right, up, pr.scalar(frame.tan_half_fov),
           np.int32(w), np.int32(h), np.int32(0), np.int32(0), np.int32(w), origins.data, dirs.data)
    if shuffle:
        perm = np.random.default_rng(0).permutation(n)
        dirs.set(dirs.get()[perm])
    march = cl.Kernel(mprg, "march")
    items = march_items(n, w, lanes, kernel_config.config_packets(mcfg))
    launch(queue, march, n, np.int32(w), *args, items=items)  # warm-up: PoCL specialises the work-group function
    queue.finish()
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        launch(queue, march, n, np.int32(w), *args, items=items)
        queue.finish()
        ts.append(time.perf_counter() - t0)
    launch(queue, cl.Kernel(build.program(ctx, counted), "march"), n, np.int32(w), *args, counts.data)
    queue.finish()
    iters = int(counts.get().astype(np.int64).sum())
    sec = statistics.median(ts)
    return {"iterations": iters, "seconds": sec, "its": iters / sec,
            "hit": float(np.mean(status.get() == 1))}


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--device", default=None)
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--widths", default="1,4,8,16")
    ap.add_argument("--scenes", type=int, default=len(SCENES), help=f"the first N of the {len(SCENES)} scenes")
    ap.add_argument("--peak-items", type=int, default=1 << 16,
                    help="work-items of the FMA peak kernel (default 65536; a simulator takes a few hundred)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")
    dev = select_device(a.device)
    lines = [f"\n## {utc_now()}, {dev.name.strip()} "
             f"({dev.platform.name.strip()} {dev.platform.version.strip()}), commit {git_commit()}, {w}x{h}\n",
             "| precision | FMA kernel width | flop/s |", "|---|---|---|"]
    peak = {}
    for prec in ("single", "double"):
        for width in (int(x) for x in a.widths.split(",")):
            r = fma_peak(a.device, width, prec == "double", max(64, a.peak_items // 64 * 64))
            label = "float" if prec == "single" else "double"
            lines.append(f"| {prec} | {label}{'' if width == 1 else width} | "
                         + (f"{r['flops']:.3g}" if "error" not in r else f"failed: {r['error']}") + " |")
            if r["flops"] == r["flops"]:
                peak[prec] = max(peak.get(prec, 0.0), r["flops"])
            print(lines[-1], flush=True)
    lines += ["", "| scene | precision | rays per work-item | iterations of f in the march | "
              "march kernel s (median) | iterations/s | share of the FMA peak (20 flops each) | "
              "pixels hit |", "|---|---|---|---|---|---|---|---|"]
    auto = {prec: lanes_for(dev, "packet", prec == "double") for prec in ("single", "double")}
    for name, over in list(SCENES.items())[:max(1, a.scenes)]:
        for prec in ("single", "double"):
            s = Scene.default().with_overrides(over + [f"image.width={w}", f"image.height={h}",
                                                       f"render.float={prec}"])
            wide = auto[prec]
            runs = [(1, False)] + ([(wide, False)] if wide > 1 else []) + \
                ([(wide, True)] if prec == "single" and wide > 1 else [])
            for lanes, shuffle in runs:
                r = march_throughput(s, dev, a.repeats, lanes, shuffle)
                share = r["its"] * FLOPS_PER_ITERATION / peak[prec] if prec in peak else float("nan")
                label = f"{lanes}" + (", rays shuffled" if shuffle else "")
                lines.append(f"| {name} | {prec} | {label} | {r['iterations']:.4g} | {r['seconds']:.4f} | "
                             f"{r['its']:.3g} | {100 * share:.1f} % | {100 * r['hit']:.1f} % |")
                print(lines[-1], flush=True)
    md = a.out / "throughput.md"
    append_run(md, "# Iterations per second inside the march\n\nWritten by `python benchmarks/speed/throughput.py` "
               "(see its docstring for what is counted and how).\n", "\n".join(lines) + "\n")
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
