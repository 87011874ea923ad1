"""Compaction tried in a kernel: lanes refilled from a queue of blocks, against the blocks.

``march_levers.py`` models refill on the float64 twin's iteration counts; this runs it.  The
trial kernel (benchmarks/studies/refill_trial.cl, appended to the scene's own march program) marches
the camera rays of one tile covering the image by the estimate from the cone's starts (the
real cone kernel runs first), without refinement and one packet per work-item, each
work-item feeding its lanes from a queue of Q blocks: Q = 1 is the blocks' own schedule,
larger Q refills a lane as soon as its ray ends.  Reports each Q's kernel time (the least
and the median of --repeats launches) against Q = 1, and checks that every Q gives the same
depth, status and step count bit for bit.  Writes benchmarks/results/refill_trial.md (a
section per run: scene, device, commit, date).

    python benchmarks/studies/refill_trial.py [--size 640x480] [--set KEY=VALUE ...] [--queues 1,4,16,64]
"""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402

MATCHED = ["shading.light=eye", "shading.shadow=none", "shading.ao=0"]   # peers.py's plain look


def queues_of(text: str) -> list[int]:
    """--queues: block counts in [1, 4096], 1 first (the baseline); ValueError naming the flag."""
    try:
        qs = [int(x) for x in text.split(",")]
    except ValueError:
        raise ValueError(f"--queues: expected integers such as 1,4,16, got {text!r}") from None
    if any(q < 1 or q > 4096 for q in qs):
        raise ValueError(f"--queues: each count in [1, 4096], got {text!r}")
    return [1] + [q for q in dict.fromkeys(qs) if q != 1]


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--queues", default="1,4,16,64")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")
    try:
        queues = queues_of(a.queues)
    except ValueError as e:
        ap.error(str(e))
    if not 1 <= a.repeats <= 1000:
        ap.error(f"--repeats: expected 1 to 1000, got {a.repeats}")
    warnings.simplefilter("ignore")
    import pyopencl as cl
    import pyopencl.array as cla

    from pyjulia4d import Scene, render
    from pyjulia4d.opencl.build import options
    from pyjulia4d.opencl.devices import build, device_of
    from pyjulia4d.opencl.runner import TileRunner, launch
    from pyjulia4d.pipeline import kernel_config
    from pyjulia4d.pipeline.plan import CONE_BLOCK, make_plan

    scene = Scene.default().with_overrides(MATCHED + [f"image.width={w}", f"image.height={h}", *a.set])
    dev = device_of(None)
    lanes = render(scene).lanes
    if lanes < 16:
        print(f"refill_trial.py: the march runs {lanes} lane(s) a work-item here; the trial needs packets of 16")
        return 0
    plan = make_plan(scene, dev, lanes, tile=max(w, h), pairs=False)
    if not plan.march.cone or plan.march.method != "de":
        raise SystemExit("refill_trial.py: the scene must take the estimate's march with the cone "
                         "(march.method=de; march.quality=custom where the default is another)")
    runner = TileRunner(plan, dev)
    q, tile = runner.queue, plan.tiles[0]
    cfg = plan.march_config
    src = kernel_config.source(cfg) + "\n" + (Path(__file__).resolve().parent / "refill_trial.cl").read_text()
    prg = build(cl.Program(runner.ctx, src), options(cfg, runner.ctx.devices[0]))
    cone = runner.slots[0][0]["cone"]
    bx0, by0, bw, bh = tile.cone_blocks()
    launch(q, runner.cone_k, bw * bh, *runner.cone_args(blocks_w=bw, bx0=bx0, by0=by0, cone=cone), lanes=lanes).wait()
    fr, pr = plan.frame, runner.pr
    camera = tuple(pr.v4(v) for v in (fr.position, fr.forward, fr.right, fr.up)) + (pr.scalar(fr.tan_half_fov),)
    n = tile.n
    n_blocks = -(-tile.aw // CONE_BLOCK) * -(-tile.ah // (lanes // CONE_BLOCK))
    outs = [cla.empty(q, n, np.float32), cla.empty(q, n, np.int32), cla.empty(q, n, np.int32)]
    kernel, ma = prg.march_refill, plan.march
    rows, first, times = [], None, {}
    for qb in queues:
        runs = []
        for _ in range(a.repeats):
            items = -(-n_blocks // qb)
            kernel.set_args(np.int32(n_blocks), np.int32(n), np.int32(tile.aw), *camera,
                            np.int32(w), np.int32(h), np.int32(tile.ax0), np.int32(tile.ay0), pr.v4(ma.c),
                            np.int32(ma.max_iter), np.float32(ma.bailout), np.float32(ma.epsilon), np.float32(ma.radius),
                            np.float32(ma.near), np.float32(ma.far), np.int32(ma.max_steps), cone.data, np.int32(bw),
                            np.int32(qb), *(o.data for o in outs))
            e = cl.enqueue_nd_range_kernel(q, kernel, (-(-items // 64) * 64,), (64,))
            e.wait()
            runs.append((e.profile.end - e.profile.start) * 1e-9)
        got = [o.get() for o in outs]
        first = first or got
        same = all(np.array_equal(x, y) for x, y in zip(got, first))
        times[qb] = min(runs)
        rows.append(f"| {qb} | {-(-n_blocks // qb)} | {min(runs) * 1e3:.2f} | {np.median(runs) * 1e3:.2f} | "
                    f"{min(runs) / times[1]:.2f} | {'yes' if same else 'NO'} |")
        print(rows[-1], flush=True)
        if not same:
            raise SystemExit(f"refill_trial.py: queue {qb} changed the march's results")
    what = f"the default scene, plain look, with {', '.join(a.set)}" if a.set else "the default scene, plain look"
    st = first[1]
    section = (f"\n## {utc_now()}, {what}, {w}x{h}, {dev.name.strip()}, commit {git_commit()}\n\n"
               f"{np.mean(st == 1):.1%} of the rays hit, {first[2].mean():.2f} steps a ray from the cone's starts; "
               f"{a.repeats} launches of each queue.\n\n"
               "| blocks a work-item's queue holds | work-items | kernel ms (least) | median | / one block | "
               "the same results |\n|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")
    append_run(a.out / "refill_trial.md", "# Compaction tried in a kernel\n\nWritten by "
               "`python benchmarks/studies/refill_trial.py` (its docstring says what is run).\n", section)
    print(f"wrote {a.out / 'refill_trial.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
