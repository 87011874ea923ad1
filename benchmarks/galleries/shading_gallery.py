"""README's shading gallery: the default scene plain, with shadows and ambient occlusion,
with each colouring, antialiased, cut open, in a gradient of its own and turned through w,
rendered side by side.

Writes benchmarks/results/shading/<name>.png (320x240 by default), a contact sheet
sheet.png with the name under each picture, and appends a section with each picture's
render time to benchmarks/results/shading.md.

    python benchmarks/galleries/shading_gallery.py [--size 320x240]
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402

PLAIN = ["shading.light=eye", "shading.shadow=none", "shading.ao=0", "shading.ambient=0.08"]
SCENES = {
    "plain (light at the eye)": PLAIN,
    "soft shadows + occlusion (default)": [],
    "iteration colouring (c -0.75+0.11i)": ["shading.coloring=iteration", "shading.colormap=YlOrBr",
                                            "fractal.c=-0.75,0.11,0,0", "camera.fit=true"],
    "orbit trap colouring": ["shading.coloring=trap", "shading.colormap=viridis"],
    "w colouring (camera at w 0.6)": ["shading.coloring=w", "shading.colormap=coolwarm",
                                      "camera.position=1.8,1.6,-2.2,0.6"],
    "three lights and a blue sky": ["shading.sky=0.45,0.55,0.8", "shading.ambient=0.25",
                                    "shading.lights=position 3,1,-2 color 0.3,0.5,1 intensity 0.9; "
                                    "direction 0,-1,0.3 color 1,0.45,0.2 intensity 0.35"],
    "mirror reflection 0.35 (dark blue background)": ["shading.reflection=0.35",
                                                       "shading.background=0.05,0.07,0.12"],
    "antialiased (9 samples), on a gradient": [
        "image.samples=9", "shading.background_gradient=[[0, 0.1, 0.13, 0.25], [0.7, 0.45, 0.42, 0.5], [1, 0.75, 0.62, 0.5]]"],
    "cut open (z >= 0 kept)": ["clip.planes=0,0,-1,0"],
    "cut open, orbit trap, 4 samples": ["clip.planes=0,0,-1,0", "shading.coloring=trap",
                                        "shading.colormap=inferno", "image.samples=4"],
    "own gradient, mirrored 3 times (trap)": [
        "shading.coloring=trap", "shading.color_scale=3", "shading.color_repeat=mirror",
        "shading.gradient=[[0, 0.05, 0.02, 0.1], [0.5, 0.8, 0.3, 0.1], [1, 1, 0.9, 0.6]]"],
    "turned 30 degrees from x into w": ["slice.turn=0,0,30,0,0,0"],
}


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    from PIL import Image, ImageDraw

    w, h = size_of(a.size, "--size")
    folder = a.out / "shading"
    folder.mkdir(parents=True, exist_ok=True)
    rows, tiles = [], []
    for name, over in SCENES.items():
        # framed (camera.fit from the default camera's direction): the whole set in each picture
        s = Scene.default().with_overrides(["camera.fit=true"] + over + [f"image.width={w}", f"image.height={h}"])
        render(s)                                   # build
        t0 = time.perf_counter()
        r = render(s)
        sec = time.perf_counter() - t0
        path = folder / (name.split(" (")[0].replace(",", "").replace(" ", "_").replace("+", "and") + ".png")
        r.save(path)
        rows.append(f"| {name} | `{' '.join(over) or '(defaults)'}` | {sec:.3f} |")
        print(rows[-1], flush=True)
        tiles.append((name, Image.open(path).convert("RGB")))
    cols = 4
    sheet = Image.new("RGB", (cols * w, -(-len(tiles) // cols) * (h + 22)), (16, 16, 20))
    draw = ImageDraw.Draw(sheet)
    for i, (name, im) in enumerate(tiles):
        x, y = (i % cols) * w, (i // cols) * (h + 22)
        sheet.paste(im, (x, y))
        draw.text((x + 6, y + h + 4), name, fill=(220, 220, 220))
    sheet.save(folder / "sheet.png")
    head = (f"\n## {utc_now()}, {tiles and r.device_name}, commit {git_commit()}, {w}x{h}\n\n"
            "| picture | overrides on the default scene | render s |\n|---|---|---|\n")
    append_run(a.out / "shading.md", "# Shading gallery\n\nWritten by `python benchmarks/galleries/shading_gallery.py`.\n",
               head + "\n".join(rows) + "\n")
    print(f"wrote {folder / 'sheet.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
