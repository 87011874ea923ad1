"""What two levers on the packet march could give, modelled on the default scene's own rays.

The packet march (kernels/common/lanes.cl) runs LANES neighbouring rays of a 4x4 block in the
vector lanes: each step of the distance-estimate march (kernels/march/de.cl) iterates every
live lane until the last one's orbit escapes, and the packet steps until its last ray ends.
So a packet's cost, in lane-slots of iterations, is

    LANES x sum over its steps of (the most iterations any of its live rays takes there),

and the work done is the sum of the iterations alone; their ratio is the lanes' use.  This
script marches the default scene's rays with the float64 twin's estimate
(pyjulia4d/reference/iterate.py julia_distance_formula, the over-relaxed steps of
reference/march.py march_de without its ulp guard, which never fires here), records every
ray's iterations at every step, and replays them through these schedules:

* blocks: the packets as the kernel runs them (one 4x4 block per work-item);
* refill: compaction - a work-item keeps LANES lanes busy from a queue of Q blocks' rays, a
  lane taking the next ray as soon as its own ends (one step of every busy lane per round,
  a round costing its slowest lane's iterations);
* own pace: each lane marches its own ray without waiting for the packet's other lanes at each
  step (the orbit loop and the march's steps fused: a lane whose orbit has ended takes its
  estimate, its step and its next point's orbit at once).  Its cost is its slowest lane's
  iterations summed over that ray's steps, and the estimate (log, sqrt, the step) is then
  taken in every round where any lane's orbit ends, where the blocks take it once a step;
* wavefront: every ray's march in launches of K steps, the rays still marching after each
  launch packed again, 16 to a packet in the blocks' order (a global compaction between
  launches, as a wavefront path tracer does; the launches, the state kept between them and
  the packing are left out).
* coarse to fine: a cone march per B x B block finds the depth where the estimate first
  falls below the block's footprint (B pixels at that distance) on any of its rays; every
  ray of the block starts there, and the steps in front of it are skipped.  The coarse
  pass is counted as one ray's steps to that depth per block.
* blocks and refill again after 4x4 cone starts (the kernel's march/cone.cl, modelled by the
  rule above): each ray's steps in front of its block's start left out, so the rays a refilled
  lane takes begin near the surface, as they do in the kernel.

--march proven models the proven march (kernels/march/proven.cl) instead: a step there is one
segment's enclosure, costing 1 (its start and tests) plus the iterations its lane stays live
(until the enclosure is proven outside or no longer hopeful), recorded from the float64 twin
(reference/march.py march_proven) at the normal preset; the coarse-to-fine rows, which rest on
the estimate, are then left out.

What is left out, so these are upper bounds of the gain: the refinement of each hit
(march/refine.cl, the same in every schedule), the per-step work that does not iterate (the
estimate's log and sqrt), the refill's own cost (a scalar gather per refilled lane), and the
incoherence refill brings (neighbouring rays share memory and branches; rays from all over
the image run 2.3-2.8x slower in packets, benchmarks/speed/throughput.py "rays shuffled").

Writes benchmarks/results/march_levers.md (appends a section per run).

    python benchmarks/studies/march_levers.py [--size 320x240] [--march de|proven] [--set KEY=VALUE ...]
"""
from __future__ import annotations

import importlib
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from pyjulia4d.geometry.camera import camera_frame, march_radius  # noqa: E402
from pyjulia4d.reference.iterate import julia_distance_formula  # noqa: E402
from pyjulia4d.pipeline.plan import march_args  # noqa: E402
from pyjulia4d.reference.formula import formula_of  # noqa: E402
from pyjulia4d.reference.march import DE_OVER_RELAX  # noqa: E402
from pyjulia4d.reference.rays import generate_rays  # noqa: E402
from pyjulia4d.scene.model import Scene  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

LANES, BLOCK = 16, 4


def iterations(p: np.ndarray, c: np.ndarray, max_iter: int, bailout: float) -> np.ndarray:
    """Iterations of q -> q^2 + c each point takes before it escapes (max_iter if never): the
    loop count of the estimate's loop (kernels/iterate.cl)."""
    q = p.copy()
    n = np.zeros(len(q), np.int64)
    live = (q * q).sum(1) <= bailout * bailout
    for _ in range(max_iter):
        if not live.any():
            break
        x, y, z, w = q.T
        nq = np.stack([x * x - y * y - z * z - w * w, 2 * x * y, 2 * x * z, 2 * x * w], 1) + c
        q = np.where(live[:, None], nq, q)
        n += live
        live &= (q * q).sum(1) <= bailout * bailout
    return n


def record(scene: Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every ray's iterations, depth and estimate at each step of its march: (n, steps)
    arrays, 0 / inf beyond its last step."""
    W, H = scene.image.width, scene.image.height
    o, d = (np.asarray(a, np.float64) for a in generate_rays(camera_frame(scene), W, H)[:2])
    f, eps = scene.fractal, scene.march.epsilon
    c = np.asarray(f.c, np.float64)
    b = (o * d).sum(1)
    perp = o - b[:, None] * d
    disc = march_radius(scene) ** 2 - (perp * perp).sum(1)
    s = np.sqrt(np.maximum(disc, 0))
    t, far = np.maximum(-b - s, 0), -b + s
    n = len(o)
    active = disc >= 0
    omega, step, r_prev = np.full(n, DE_OVER_RELAX), np.zeros(n), np.zeros(n)
    its, ts, ds = [], [], []
    for _ in range(scene.march.max_steps):
        active &= t <= far
        idx = np.nonzero(active)[0]
        if idx.size == 0:
            break
        p = o[idx] + t[idx, None] * d[idx]
        dist, esc = julia_distance_formula(p, c, f.max_iter, f.bailout)
        row_i, row_t, row_d = np.zeros(n, np.int64), np.full(n, np.inf), np.full(n, np.inf)
        row_i[idx], row_t[idx], row_d[idx] = iterations(p, c, f.max_iter, f.bailout), t[idx], np.where(esc, dist, 0)
        its.append(row_i), ts.append(row_t), ds.append(row_d)
        r = np.where(esc, dist, 0.0)
        gap = (omega[idx] > 1) & (r + r_prev[idx] < step[idx])
        got = ~esc & ~gap
        active[idx[got]] = False
        k, g = idx[~got], gap[~got]
        step[k] = np.where(g, step[k] * (1 - omega[k]), np.maximum(dist[~got], eps) * omega[k])
        omega[k] = np.where(g, 1.0, omega[k])
        r_prev[k] = np.where(g, r_prev[k], r[~got])
        t[k] += step[k]
    return np.stack(its, 1), np.stack(ts, 1), np.stack(ds, 1)


def record_proven(scene: Scene) -> np.ndarray:
    """Every ray's cost at each step of the proven march, from the float64 twin's own march at
    the scene's preset (reference/march.py enc_prove counts 1 plus the iterations its lane
    stays live): an (n, steps) array, 0 beyond its last step.  The twin's enc_prove is wrapped
    for the run; rays are told apart by their directions (one ray a pixel)."""
    rm = importlib.import_module("pyjulia4d.reference.march")
    W, H = scene.image.width, scene.image.height
    o, d = (np.asarray(a, np.float64) for a in generate_rays(camera_frame(scene), W, H)[:2])
    index = {row.tobytes(): i for i, row in enumerate(d)}
    rows: list[list[int]] = [[] for _ in range(len(d))]
    original = rm.enc_prove

    def counted(o_, d_, t0, t1, c, max_iter, bailout, formula):
        slots = np.zeros(len(o_), np.int64)
        out = original(o_, d_, t0, t1, c, max_iter, bailout, formula, iterations=slots)
        for row, k in zip(d_, slots):
            rows[index[row.tobytes()]].append(int(k))
        return out

    rm.enc_prove = counted
    try:
        rm.march(o, d, march_args(scene, method="proven"), None, None, formula_of(scene.fractal), None)
    finally:
        rm.enc_prove = original
    its = np.zeros((len(d), max(map(len, rows), default=0) or 1), np.int64)
    for i, r in enumerate(rows):
        its[i, :len(r)] = r
    return its


def block_order(W: int, H: int) -> np.ndarray:
    """Ray indices block by block (BLOCK x BLOCK, row-major blocks): the packets' order."""
    return np.arange(W * H).reshape(H // BLOCK, BLOCK, W // BLOCK, BLOCK).transpose(0, 2, 1, 3).reshape(-1)


def cost_blocks(its: np.ndarray, order: np.ndarray) -> int:
    return int(its[order].reshape(-1, LANES, its.shape[1]).max(axis=1).sum())


def cost_refill(its: np.ndarray, order: np.ndarray, queue_blocks: int) -> int:
    """Rounds of one step of every busy lane, each costing its slowest lane; a lane whose ray
    ends takes the next ray of its work-item's queue."""
    lengths = (its > 0).sum(1)
    cost, per = 0, LANES * queue_blocks
    for q0 in range(0, len(order), per):
        queue = [r for r in order[q0:q0 + per] if lengths[r] > 0][::-1]
        lane, pos = [-1] * LANES, [0] * LANES
        for j in range(LANES):
            lane[j] = queue.pop() if queue else -1
        while any(r >= 0 for r in lane):
            m = 0
            for j in range(LANES):
                r = lane[j]
                if r >= 0:
                    m = max(m, its[r, pos[j]])
                    pos[j] += 1
                    if pos[j] >= lengths[r]:
                        lane[j], pos[j] = (queue.pop() if queue else -1), 0
            cost += int(m)
    return cost


def cost_wavefront(its: np.ndarray, order: np.ndarray, k: int) -> tuple[int, int]:
    """(cost, launches) of launches of ``k`` steps, the rays still marching packed again after
    each, LANES to a packet in ``order`` (cost_blocks within a launch)."""
    lengths = (its > 0).sum(1)
    alive, pos, cost, launches = order[lengths[order] > 0], np.zeros(len(its), np.int64), 0, 0
    cols = np.arange(k)
    while alive.size:
        launches += 1
        pad = (-alive.size) % LANES
        rays = np.concatenate([alive, np.full(pad, -1)])
        idx = pos[rays][:, None] + cols
        part = np.where((rays[:, None] >= 0) & (idx < its.shape[1]),
                        its[rays[:, None], np.minimum(idx, its.shape[1] - 1)], 0)
        cost += int(part.reshape(-1, LANES, k).max(axis=1).sum())
        pos[alive] += k
        alive = alive[pos[alive] < lengths[alive]]
    return cost, launches


def cost_own_pace(its: np.ndarray, order: np.ndarray) -> tuple[int, int]:
    """(rounds, estimate rounds) of the own-pace schedule: a packet's rounds are its slowest
    lane's iterations over all its ray's steps; its estimate rounds, the rounds in which some
    lane's orbit ends (a step's end, where the lane takes its estimate)."""
    packets = its[order].reshape(-1, LANES, its.shape[1])
    rounds = int(packets.sum(2).max(1).sum())
    ends = 0
    for p in packets:
        done = np.cumsum(p, 1)[p > 0]   # the round at which each of the lanes' steps ends
        ends += len(np.unique(done))
    return rounds, ends


def coarse_to_fine(its, ts, ds, W: int, H: int, side: int, pixel: float) -> tuple[float, float]:
    """(share of iterations skipped, share the coarse pass costs) with side x side blocks."""
    total = its.sum()
    skipped = coarse = 0
    cols = np.arange(its.shape[1])
    for by in range(0, H - side + 1, side):
        for bx in range(0, W - side + 1, side):
            rays = (np.arange(by, by + side)[:, None] * W + np.arange(bx, bx + side)).ravel()
            t, d = ts[rays], ds[rays]
            below = d < t * pixel * side * (math.sqrt(2) / 2)   # the footprint's half diagonal
            first = np.where(below.any(1), below.argmax(1), its.shape[1])
            tb = min((t[i, k] for i, k in enumerate(first) if k < its.shape[1]), default=math.inf)
            front = t < tb
            skipped += its[rays][front].sum()
            mid = len(rays) // 2
            coarse += its[rays[mid]][front[mid] & (cols < its.shape[1])].sum()
    return skipped / total, coarse / total


def schedules(its: np.ndarray, order: np.ndarray, title: str) -> list[str]:
    """The table of the blocks' schedule, refill from queues of 4, 16 and 64 blocks, each lane at
    its own pace, and every lane busy: lanes' use and modelled time against the blocks'."""
    total, base = int(its.sum()), cost_blocks(its, order)
    rows = [f"| {title} | lanes' use | modelled march time vs blocks |", "|---|---|---|",
            f"| blocks (as the kernel runs) | {total / (LANES * base):.1%} | 1.00 |"]
    for q in (4, 16, 64):
        c = cost_refill(its, order, q)
        rows.append(f"| refill from a queue of {q} blocks | {total / (LANES * c):.1%} | {c / base:.2f} |")
        print(rows[-1], flush=True)
    for k in (4, 8, 16):
        c, n = cost_wavefront(its, order, k)
        rows.append(f"| wavefront: launches of {k} steps, packed again after each ({n} launches) | "
                    f"{total / (LANES * c):.1%} | {c / base:.2f} |")
        print(rows[-1], flush=True)
    rounds, ends = cost_own_pace(its, order)
    steps = int((its[order].reshape(-1, LANES, its.shape[1]).max(1) > 0).sum())
    rows.append(f"| each lane at its own pace (steps' ends - estimates, proofs' outcomes - in {ends / steps:.1f}x "
                f"the blocks' rounds) | "
                f"{total / (LANES * rounds):.1%} | {rounds / base:.2f} |")
    print(rows[-1], flush=True)
    rows.append(f"| every lane always busy (the bound of any compaction) | 100 % | {total / (LANES * base):.2f} |")
    return rows


def cone_trim(its, ts, ds, W: int, H: int, side: int, pixel: float) -> np.ndarray:
    """``its`` with each ray's steps in front of its block's start (coarse_to_fine's rule) left
    out and the rest moved to the front: the march each ray runs after a cone start."""
    out = np.zeros_like(its)
    for by in range(0, H - side + 1, side):
        for bx in range(0, W - side + 1, side):
            rays = (np.arange(by, by + side)[:, None] * W + np.arange(bx, bx + side)).ravel()
            t, d = ts[rays], ds[rays]
            below = d < t * pixel * side * (math.sqrt(2) / 2)
            first = np.where(below.any(1), below.argmax(1), its.shape[1])
            tb = min((t[i, k] for i, k in enumerate(first) if k < its.shape[1]), default=math.inf)
            for r in rays:
                kept = its[r][(ts[r] >= tb) & (its[r] > 0)]
                out[r, :len(kept)] = kept
    return out


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="scene overrides (e.g. fractal.max_iter=20 march.epsilon=0.05)")
    ap.add_argument("--march", choices=("de", "proven"), default="de",
                    help="the distance-estimate march (default) or the proven march at the normal preset")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    W, H = size_of(a.size, "--size")
    if W % BLOCK or H % BLOCK:
        raise SystemExit(f"--size: width and height must be multiples of {BLOCK}, got {a.size}")
    quality = ["march.quality=normal"] if a.march == "proven" else []
    scene = Scene.default().with_overrides([f"image.width={W}", f"image.height={H}", *quality, *a.set])
    order = block_order(W, H)
    what = f"the default scene with {', '.join(a.set)}" if a.set else "default scene"
    if a.march == "proven":
        its = record_proven(scene)
        total = int(its.sum())
        base = cost_blocks(its, order)
        lines = [f"\n## {utc_now()}, commit {git_commit()}, the proven march (normal preset), {what} {W}x{H}, "
                 f"{LANES} lanes\n",
                 f"{total:.4g} lane-slots in the march ({(its > 0).sum() / (W * H):.1f} enclosures and "
                 f"{total / (W * H):.0f} slots per ray, each enclosure 1 plus its iterations; refinement and "
                 f"floor tests left out); packets of 4x4 blocks use {total / (LANES * base):.1%} of them.\n"]
        lines += schedules(its, order, "schedule")
    else:
        its, ts, ds = record(scene)
        total = int(its.sum())
        base = cost_blocks(its, order)
        lines = [f"\n## {utc_now()}, commit {git_commit()}, {what} {W}x{H}, {LANES} lanes\n",
                 f"{total:.4g} iterations in the march ({total / (W * H):.0f} per ray, refinement left out); "
                 f"packets of 4x4 blocks use {total / (LANES * base):.1%} of their lanes' iteration slots.\n"]
        lines += schedules(its, order, "schedule")
        pixel = 2 * math.tan(math.radians(scene.camera.fov) / 2) / H
        lines += ["", "| coarse to fine, block | iterations skipped | coarse pass | net |", "|---|---|---|---|"]
        for side in (4, 8, 16):
            skip, coarse = coarse_to_fine(its, ts, ds, W, H, side, pixel)
            lines.append(f"| {side}x{side} | {skip:.1%} | {coarse:.1%} | {skip - coarse:.1%} |")
            print(lines[-1], flush=True)
        cut = cone_trim(its, ts, ds, W, H, BLOCK, pixel)
        left = int(cut.sum())
        lines += ["", f"After 4x4 cone starts: {left:.4g} iterations ({left / total:.1%} of the above), "
                  f"the blocks' lanes' use {left / (LANES * cost_blocks(cut, order)):.1%}.", ""]
        lines += schedules(cut, order, "schedule after the cone starts")
    md = a.out / "march_levers.md"
    append_run(md, "# Compaction and coarse-to-fine, modelled on the default scene's rays\n\nWritten by "
               "`python benchmarks/studies/march_levers.py` (its docstring says what is modelled and what is "
               "left out).\n", "\n".join(lines) + "\n")
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
