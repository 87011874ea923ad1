"""Frames per second of an animation in this process and on local Dask clusters of 1 and 2
workers, one large frame whole against in tiles, and the cost of a work unit.

The animation is examples/c_morph.toml at --size; each configuration first renders one
warm-up frame per worker (the OpenCL build), then --frames frames, timed from the client:
submitted, rendered and encoded as PNG by the worker, sent back, written (what ``animate``
does).  The overhead per
unit is the client's wall time per frame less the worker's own time per frame (render and
all), with one worker, so nothing overlaps.  Writes benchmarks/results/animation_scaling.md
(a section per run: device, date, commit).

    python benchmarks/speed/animation_scaling.py [--size 320x240] [--frames 48] [--big 1920x1080]
"""
from __future__ import annotations

import logging
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402


def _frames_run(client, anim, frames, out: Path):
    """(wall seconds, worker seconds summed) of rendering and writing ``frames``."""
    from pyjulia4d.app.cluster import render_many
    from pyjulia4d.files import atomic_write

    worker = []

    def write(n, encoded, info):
        with atomic_write(out / f"f_{n:04d}.png") as tmp:
            tmp.write_bytes(encoded.data)
        worker.append(info.seconds)

    units = [(n, anim.scene(n), {"outputs": ("color", "alpha"),
                                 "encode": (".png", {"pyjulia4d.scene": anim.scene(n).to_toml()})})
             for n in frames]
    t = time.perf_counter()
    render_many(client, units, write)
    return time.perf_counter() - t, sum(worker)


def _median(fn, repeats: int = 3) -> float:
    """Median wall seconds of ``fn()`` after one untimed call."""
    fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return sorted(times)[len(times) // 2]


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240", help="frame size of the animation")
    ap.add_argument("--frames", type=int, default=48, help="frames timed per configuration")
    ap.add_argument("--big", default="1920x1080", help="size of the one frame rendered whole and in tiles")
    ap.add_argument("--tile", type=int, default=512, help="tile size (plan.TILE by default)")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results"))
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    from distributed import Client, LocalCluster

    from pyjulia4d.scene import keyframes
    from pyjulia4d import render
    from pyjulia4d.app.cluster import render_tiled
    from pyjulia4d.opencl.devices import select_device
    from pyjulia4d.app.output import write_image

    w, h = size_of(args.size, "--size")
    anim = keyframes.load(ROOT / "examples" / "c_morph.toml", [f"image.width={w}", f"image.height={h}"])
    frames = [round(k * (anim.frames - 1) / max(args.frames - 1, 1)) for k in range(args.frames)]
    frames = list(dict.fromkeys(frames))
    dev = select_device(None)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        # in this process
        _frames_run(None, anim, frames[:1], tmp)
        wall, work = min(_frames_run(None, anim, frames, tmp) for _ in range(2))
        rows.append(("in this process", 0.0, len(frames) / wall, wall / len(frames), work / len(frames)))
        # PNG encoding and writing alone (a worker's share of every frame besides the render)
        r = render(anim.scene(frames[-1]), device=dev, outputs=("color", "alpha"))
        t = time.perf_counter()
        for k in range(5):
            write_image(tmp / f"w_{k}.png", r, {"pyjulia4d.scene": anim.scene(frames[-1]).to_toml()})
        write_s = (time.perf_counter() - t) / 5
        overhead = None
        for n in (1, 2):
            t = time.perf_counter()
            lc = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0",
                              silence_logs=logging.ERROR)
            client = Client(lc, set_as_default=False)
            client.wait_for_workers(n)
            start = time.perf_counter() - t
            try:
                _frames_run(client, anim, frames[:n], tmp)   # warm-up: each worker builds once
                wall, work = min(_frames_run(client, anim, frames, tmp) for _ in range(2))
                rows.append((f"local cluster, {n} worker{'s' if n > 1 else ''}", start, len(frames) / wall,
                             wall / len(frames), work / len(frames)))
                if n == 1:
                    overhead = (wall - work) / len(frames)
                if n == 2:
                    bw, bh = size_of(args.big, "--big")
                    big = anim.scene(frames[-1]).replace(**{"image.width": bw, "image.height": bh})
                    png = ("color", "alpha")
                    whole_local = _median(lambda: render(big, device=dev, outputs=png))
                    tiled, _ = render_tiled(client, big, outputs=png, tile=args.tile)
                    tiled_s = _median(lambda: render_tiled(client, big, outputs=png, tile=args.tile))
                    one_unit = _median(lambda: render_tiled(client, big, outputs=png, tile=max(bw, bh)))
                    ntiles = int(tiled.device_name.split("(")[-1].split()[0])
            finally:
                client.close()
                lc.close()
    table = ["| configuration | cluster start (s) | frames per second | wall s per frame | worker s per frame |",
             "|---|---|---|---|---|"]
    for name, start, fps, per, work in rows:
        table.append(f"| {name} | {start:.2f} | {fps:.2f} | {per:.3f} | {work:.3f} |")
    big_table = [f"| one {args.big} frame, colour and alpha (a PNG's outputs), median of 3 | seconds |",
                 "|---|---|",
                 f"| whole, in this process | {whole_local:.3f} |",
                 f"| whole, one unit on the 2-worker cluster | {one_unit:.3f} |",
                 f"| {ntiles} tiles of {args.tile} px on 2 workers | {tiled_s:.3f} |"]
    section = (f"\n## {utc_now()}, commit `{git_commit()}`\n\n"
               f"device: {dev.name.strip()}; {os.cpu_count()} CPU cores; animation examples/c_morph.toml "
               f"at {args.size}, {len(frames)} frames timed (the faster of 2 runs) after one warm-up frame per worker\n\n"
               + "\n".join(table) + "\n\n"
               f"overhead per frame unit (1 worker: client wall less worker time): {overhead * 1e3:.1f} ms; "
               f"PNG encoding and write (output.write_image): {write_s * 1e3:.1f} ms per frame\n\n"
               + "\n".join(big_table) + "\n")
    out = Path(args.out)
    append_run(out / "animation_scaling.md", "# Animation and distributed rendering: frames per second\n\n"
               "Written by benchmarks/speed/animation_scaling.py.\n", section)
    print(section)
    return 0


if __name__ == "__main__":
    sys.exit(main())
