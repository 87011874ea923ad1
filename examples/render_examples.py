"""Render the three example animations with ``python -m pyjulia4d animate``: frames and an
MP4 each, a strip of 8 frames each into benchmarks/results/animation/, and a GIF of one (every other frame, 160x120).

    python examples/render_examples.py [--size 320x240] [--out DIR] [--workers N]

DIR (default: a temporary folder, removed at the end) receives the frames and the videos;
each video's first frames are read back through imageio and compared with the frames.
"""
from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ("c_morph", "w_rotation", "slice_sweep")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--out", help="folder for frames and videos (default: a temporary one)")
    ap.add_argument("--workers", default=None, help="as animate's --workers (default: animate's)")
    ap.add_argument("--results", default=str(ROOT / "benchmarks" / "results" / "animation"))
    args = ap.parse_args(argv)
    import imageio.v2 as imageio
    from PIL import Image

    from pyjulia4d.app import cli
    from pyjulia4d.app.animation import strip
    from pyjulia4d.app.video import read_frame

    w, h = args.size.split("x")
    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="pyjulia4d-examples-"))
    out.mkdir(parents=True, exist_ok=True)
    results = Path(args.results)
    results.mkdir(parents=True, exist_ok=True)
    try:
        for name in EXAMPLES:
            frames = out / name
            video = out / f"{name}.mp4"
            cmd = ["animate", str(ROOT / "examples" / f"{name}.toml"), "-o", str(frames / "f_####.png"),
                   "--video", str(video), "--width", w, "--height", h]
            if args.workers is not None:
                cmd += ["--workers", args.workers]
            if cli.main(cmd) != 0:
                return 1
            files = sorted(frames.glob("f_*.png"))
            picks = [files[round(k * (len(files) - 1) / 7)] for k in range(8)]
            strip(picks, results / f"{name}.png", columns=8)
            reader = imageio.get_reader(str(video), format="FFMPEG")
            try:
                played = [f for _, f in zip(range(3), reader)]
                count = reader.count_frames()
            finally:
                reader.close()
            err = [float(np.abs(p.astype(float) - read_frame(f).astype(float)).mean())
                   for p, f in zip(played, files)]
            print(f"{name}: {len(files)} frames, video {video.stat().st_size} bytes, {count} frames; "
                  f"first 3 played back, mean |error| {', '.join(f'{e:.2f}' for e in err)} (of 255); "
                  f"strip {results / (name + '.png')}")
            if name == "c_morph":
                gif = [Image.fromarray(read_frame(f)).resize((160, 120), Image.LANCZOS) for f in files[::2]]
                gif[0].save(results / "c_morph.gif", save_all=True, append_images=gif[1:], duration=1000 // 12,
                            loop=0, optimize=True)
    finally:
        if not args.out:
            shutil.rmtree(out, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
