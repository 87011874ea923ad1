"""Render the path tracer's gallery: showpieces of the algebras, lit by the shipped sky, with
the lens, metal, glossy and glowing materials (docs/lighting.md).

Each scene is a gallery.py showpiece (its fractal, camera and colour) with path-tracing
overrides on top (PATH below); every one is rendered with image.samples paths per pixel, a
noise target, the ACES tone map and the denoiser, and written as
benchmarks/results/gallery/path/<name>.png, plus a contact sheet over a dark grey,
benchmarks/results/gallery/path/sheet.png.  Prints one line per picture (name, seconds,
stated noise) and appends a section to benchmarks/results/path_gallery.md (device, date,
commit, every picture with its time and noise).

    python benchmarks/galleries/path_gallery.py [--size 400x300] [--samples 128] [--only NAME ...]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.galleries.gallery import SCENES, srgb  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402

COMMON = ["shading.integrator=path", "shading.environment=sky", "shading.ambient=0.7", "shading.sky=1,1,1",
          "shading.light_color=0.45,0.43,0.4", "shading.bounces=4", "image.tonemap=aces", "image.denoise=true"]

# name -> (gallery.py scene, overrides, what it shows)
PATH: dict[str, tuple[str, list[str], str]] = {
    "satin_shell": ("quaternion_sqr", ["shading.roughness=0.4"], "quaternion sqr, satin, daylight"),
    "gold": ("quaternion_cube", ["shading.metallic=1", "shading.roughness=0.18", srgb(1.0, 0.78, 0.34)],
             "quaternion cube, polished gold"),
    "lens": ("hypercomplex_sqr", ["camera.aperture=0.12", "camera.focus=auto", "shading.roughness=0.5"],
             "hypercomplex sqr, depth of field (focus auto)"),
    "gloss": ("hypercomplex_ln", ["shading.roughness=0.06", "shading.specular=0.5", srgb(0.75, 0.85, 0.95)],
              "hypercomplex ln, glossy glaze"),
    "glow": ("cquat_sqr", ["shading.coloring=trap", "shading.colormap=inferno", "shading.trap=0,0,0,0",
                           "shading.emission=3", "shading.ambient=0.15", "shading.light_color=0.2,0.2,0.2"],
             "CQuat, orbit-trap colours glowing"),
    "iteration": ("hypercomplex_cube", ["shading.coloring=iteration", "shading.colormap=viridis",
                                        "shading.roughness=0.3"], "hypercomplex cube, escape-time colours"),
    "soft": ("commutative_sqr", ["shading.environment=uniform", "shading.ambient=0.8", "shading.light_color=0.3,0.3,0.3"],
             "commutative rules, uniform sky"),
    "brushed": ("hypercomplex_asinh", ["shading.metallic=1", "shading.roughness=0.45", srgb(0.8, 0.82, 0.85)],
                "hypercomplex asinh, rough steel"),
}
OUT = ROOT / "benchmarks" / "results" / "gallery" / "path"


def main() -> None:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="400x300", help="WIDTHxHEIGHT of each picture (default 400x300)")
    ap.add_argument("--samples", type=int, default=128, help="paths per pixel at most (default 128)")
    ap.add_argument("--noise", type=float, default=0.01, help="image.noise, the stated noise to stop at (default 0.01)")
    ap.add_argument("--only", nargs="+", default=[], help=f"names among {', '.join(PATH)}")
    a = ap.parse_args()
    w, h = size_of(a.size)
    names = a.only or list(PATH)
    for n in names:
        if n not in PATH:
            ap.error(f"--only {n}: no such picture (one of {', '.join(PATH)})")
    OUT.mkdir(parents=True, exist_ok=True)
    rows, tiles = [], []
    for name in names:
        base, over, what = PATH[name]
        keys = SCENES[base] + COMMON + over + [f"image.width={w}", f"image.height={h}",
                                               f"image.samples={a.samples}", f"image.noise={a.noise}"]
        sc = Scene.default().with_overrides(keys)
        t0 = time.perf_counter()
        r = render(sc)
        dt = time.perf_counter() - t0
        r.save(OUT / f"{name}.png")
        st = r.film.noise_stats()
        print(f"{name:10s} {dt:7.1f} s  noise p50 {st['p50']:.4f} p99 {st['p99']:.4f}  {what}", flush=True)
        rows.append(f"| {name} | {what} | {dt:.1f} | {st['p50']:.4f} | {st['p99']:.4f} | "
                    f"{int(r.film.paths.min())}-{int(r.film.paths.max())} |\n")
        tiles.append(OUT / f"{name}.png")
    sheet(tiles, w, h)
    section = (f"\n## {utc_now()}, commit {git_commit()}, {r.device_name}\n\n"
               f"`python benchmarks/galleries/path_gallery.py --size {w}x{h} --samples {a.samples} --noise {a.noise}`"
               f"\n\n| picture | what | seconds | noise p50 | noise p99 | paths |\n| --- | --- | ---: | ---: | ---: | --- |\n"
               + "".join(rows))
    append_run(ROOT / "benchmarks" / "results" / "path_gallery.md",
               "# The path tracer's gallery\n\nWritten by benchmarks/galleries/path_gallery.py; a section per run.\n",
               section)


def sheet(paths: list[Path], w: int, h: int, cols: int = 4) -> None:
    """The pictures over a dark grey, ``cols`` to a row."""
    from PIL import Image
    n = len(paths)
    rows = -(-n // cols)
    out = Image.new("RGB", (cols * w, rows * h), (28, 28, 30))
    for i, p in enumerate(paths):
        with Image.open(p) as im:
            tile = Image.new("RGBA", im.size, (28, 28, 30, 255))
            tile.alpha_composite(im.convert("RGBA"))
            out.paste(tile.convert("RGB"), ((i % cols) * w, (i // cols) * h))
    out.save(OUT / "sheet.png")


if __name__ == "__main__":
    main()
