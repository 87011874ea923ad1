"""Render the README gallery: one picture per algebra x function pair.

Twenty scenes - quaternion sqr and cube, and the hypercomplex algebra's 18 functions
(POV-Ray's julia_fractal: sqr cube exp reciprocal sin asin sinh asinh cos acos cosh acosh
tan atan tanh atanh ln pwr) - each with a Julia constant, iteration count, bailout,
camera, slice, colour and light chosen by looking at the pictures, so that each shows the
structure of its set.  The scenes are the table SCENES below (``--set`` overrides on top of
the default scene).

Each scene is rendered with pyjulia4d's Python API at --ss times the size in each direction
and box-filtered down (the hypercomplex sets' surfaces are ruled by fine parallel ridges,
which alias into speckle at one sample per pixel), then written as
benchmarks/results/gallery/<algebra>_<function>.png (RGBA, alpha = coverage, the resolved
scene and the render's report in the PNG text chunks), plus a contact sheet of all of them
with their names, benchmarks/results/gallery/sheet.png.  Prints one line per picture (name,
render seconds, share of the supersampled pixels hit) and appends a section to
benchmarks/results/gallery.md (device, date, commit, every picture with its time).

    python benchmarks/galleries/gallery.py [--size 320x240] [--only NAME ...] [--ss 3]

NAME is a table key (``hypercomplex_sin``) or its function (``sin``; ``sqr`` and ``cube``
pick both algebras).
"""
from __future__ import annotations

import dataclasses
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

# Keys every scene shares (a scene's own keys come after and win); the shading keys are
# pinned so that a change of the scene defaults does not change the gallery.  The march is
# the normal preset, the proven march: the fixed scan at 250 stepped over the thin parts of
# the hypercomplex sin, cos and cosh and of the CQuats and the commutative rules
# (benchmarks/results/pair_accuracy.md).
COMMON = ["march.quality=normal", "shading.coloring=flat", "shading.ambient=0.04",
          "shading.diffuse=0.92", "shading.specular=0.35", "shading.shininess=40", "shading.shadow=none",
          "shading.ao=0"]

HC = ["fractal.algebra=hypercomplex"]


def srgb(r: float, g: float, b: float) -> str:
    """The shading.color override for a colour given as it shows in the PNG (sRGB): shading
    is in linear light and the PNG is written sRGB-encoded, so the table's colours are
    decoded here."""
    lin = [x / 12.92 if x <= 0.04045 else ((x + 0.055) / 1.055) ** 2.4 for x in (r, g, b)]
    return "shading.color=" + ",".join(f"{x:.4f}" for x in lin)


# name -> --set overrides.  Hypercomplex numbers split into two complex numbers,
# a = (x + w) + (y - z) i and b = (x - w) + (y + z) i (kernels/algebra/hypercomplex.cl), so a
# set is nearly the product of two planar filled Julia sets of f(z) + c_a and f(z) + c_b (the
# escape test on |h|^2 = (|a|^2 + |b|^2) / 2 couples them), inside the bailout ball; in the 3D
# slice w = 0 its surfaces are cylinders over the planar sets' edges, ruled along (0, 1, 1)
# and (0, 1, -1).  c = (x, y, z, w) gives c_a = (x + w) + (y - z) i,
# c_b = (x - w) + (y + z) i.
SCENES: dict[str, list[str]] = {
    # POV-Ray's julia_fractal example c, 8 iterations: the whorled shell, seen from its side
    "quaternion_sqr": [
        "fractal.c=-0.083,0,-0.83,-0.025", "fractal.max_iter=8",
        "camera.position=0,1.5,-3.3", "shading.light=3,4,-3", "shading.shadow=soft",
        srgb(0.95, 0.72, 0.42)],
    # q^3 + c with a c off the complex plane: twisted three-lobed swirls, no rotation symmetry
    "quaternion_cube": [
        "fractal.function=cube", "fractal.c=-0.3,0.6,0.2,0.1", "fractal.max_iter=6",
        "camera.position=2,2,-3.2", "shading.light=3,4,-3", "shading.shadow=soft",
        srgb(0.55, 0.75, 0.95)],
    # Douady's rabbit and its mirror image (c_a, c_b = -0.123 +- 0.745i): a crystal of stepped walls
    "hypercomplex_sqr": HC + [
        "fractal.c=-0.123,0,-0.745,0", "fractal.max_iter=12",
        "camera.position=2.2,2,-2.8", "camera.fov=35", "shading.light=3,4,-3",
        srgb(0.85, 0.85, 0.9)],
    # cubic Julia sets 0.4 +- 0.6i, seen from +x: a stepped pyramid of ruled terraces
    "hypercomplex_cube": HC + [
        "fractal.function=cube", "fractal.c=0.4,0,-0.6,0", "fractal.max_iter=6",
        "camera.position=4.4,1.5,-1", "camera.fov=36", "shading.light=5,4,-3",
        srgb(0.45, 0.85, 0.55)],
    # exp is 2 pi i periodic: a lattice of carved blocks on the +x side of the bailout ball
    "hypercomplex_exp": HC + [
        "fractal.function=exp", "fractal.c=0,0.8,0,0", "fractal.bailout=8", "fractal.max_iter=10",
        "camera.position=15.5,11,-20", "shading.light=12,20,-20", srgb(0.95, 0.55, 0.3)],
    # 1/z + c is a Moebius map: a chain of round tunnels, shrinking to a fixed point, seen
    # down their axis (0, 1, -1)
    "hypercomplex_reciprocal": HC + [
        "fractal.function=reciprocal", "fractal.c=-0.5,0.4,0,0", "fractal.bailout=2",
        "fractal.max_iter=30", "camera.position=1,4.9,-4.9", "shading.light=3,8,-6",
        srgb(0.7, 0.6, 0.95)],
    # sin: a bar along x (|Im| bounded), its sides cut by a spiral notch
    "hypercomplex_sin": HC + [
        "fractal.function=sin", "fractal.c=-0.5,0.4,0,0", "fractal.max_iter=6",
        "camera.position=6,6,-8", "shading.light=6,10,-10", srgb(0.95, 0.8, 0.35)],
    # asin, seen from +x: a four-pointed star hollowed into the ball
    "hypercomplex_asin": HC + [
        "fractal.function=asin", "fractal.c=1,0,0,0", "fractal.bailout=2.5", "fractal.max_iter=12",
        "camera.position=7.3,2.8,-3.4", "shading.light=8,6,-8", srgb(0.6, 0.9, 0.9)],
    # sinh: a slab across x; its face, seen head-on, is carved like a city plan
    "hypercomplex_sinh": HC + [
        "fractal.function=sinh", "fractal.c=0,0.8,0,0", "fractal.max_iter=6",
        "camera.position=11.5,3.5,-4.6", "shading.light=10,8,-6", srgb(0.9, 0.45, 0.45)],
    # asinh: half a shell, its inside scalloped by nested bubbles
    "hypercomplex_asinh": HC + [
        "fractal.function=asinh", "fractal.c=0.5,0.8,0,0", "fractal.bailout=2.5", "fractal.max_iter=12",
        "camera.position=3,-7,-3.5", "shading.light=-2,-8,-6", "shading.ambient=0.12",
        srgb(0.55, 0.8, 0.45)],
    # cos (sin shifted by pi/2): the bar along x seen from above, an ornamented column
    "hypercomplex_cos": HC + [
        "fractal.function=cos", "fractal.c=0,0.8,0,0", "fractal.max_iter=6",
        "camera.position=2,11,-3", "shading.light=4,8,-4", srgb(0.4, 0.6, 0.9)],
    # acos, seen from +x: a pebble pinched by four concave cuts, one ending in a curl
    "hypercomplex_acos": HC + [
        "fractal.function=acos", "fractal.c=-0.4,0.7,0,0", "fractal.bailout=1.5", "fractal.max_iter=16",
        "camera.position=4.2,1.6,-2", "shading.light=4,6,-8", srgb(0.9, 0.6, 0.8)],
    # cosh, bailout 2.5: a slab across x, its face moulded into rounded blocks, loose fragments around
    "hypercomplex_cosh": HC + [
        "fractal.function=cosh", "fractal.c=0,0.8,0,0", "fractal.bailout=2.5", "fractal.max_iter=6",
        "camera.position=7,2.3,-2.9", "shading.light=10,8,-6", srgb(0.8, 0.8, 0.5)],
    # acosh: the ball cut by crossed wedges, with a round tunnel (the planar set is a ring)
    "hypercomplex_acosh": HC + [
        "fractal.function=acosh", "fractal.c=0,0.8,0,0", "fractal.bailout=2.5", "fractal.max_iter=20",
        "camera.position=-4,3.8,-5.2", "shading.light=-4,8,-8", srgb(0.95, 0.65, 0.5)],
    # tan: the poles bore two crossed chains of tunnels, seen from +x
    "hypercomplex_tan": HC + [
        "fractal.function=tan", "fractal.c=-1,0,0,0", "fractal.bailout=2", "fractal.max_iter=8",
        "camera.position=6.2,1.7,-2.3", "shading.light=10,8,-6", srgb(0.3, 0.75, 0.75)],
    # atan: two lobes along a seam of spiral curls
    "hypercomplex_atan": HC + [
        "fractal.function=atan", "fractal.c=0.5,0,0,0", "fractal.bailout=1.5", "fractal.max_iter=12",
        "camera.position=0.75,3.6,-3.6", "shading.light=6,10,-10", srgb(0.75, 0.5, 0.9)],
    # tanh: scalloped bites in a chain along a great circle of the ball (the poles i pi/2 + k pi i)
    "hypercomplex_tanh": HC + [
        "fractal.function=tanh", "fractal.c=0,1,0,0", "fractal.bailout=2", "fractal.max_iter=8",
        "camera.position=1.7,6.3,-2.3", "shading.light=10,8,-6", srgb(0.9, 0.75, 0.6)],
    # atanh, seen from +x: a cross of concave cuts ending in curls
    "hypercomplex_atanh": HC + [
        "fractal.function=atanh", "fractal.c=0,0.4,0,0", "fractal.bailout=1.5", "fractal.max_iter=12",
        "camera.position=4.1,1.4,-2.1", "shading.light=6,10,-10", srgb(0.6, 0.8, 1.0)],
    # ln: the attracting fixed point's spiral, cut into the ball like a nautilus shell
    "hypercomplex_ln": HC + [
        "fractal.function=ln", "fractal.c=0.5,0.4,0,0", "fractal.bailout=2.5", "fractal.max_iter=20",
        "camera.position=1.7,5.7,-5.7", "shading.light=6,10,-10", srgb(0.95, 0.9, 0.75)],
    # pwr: q^(3 + 0.5i) in the slice x + w = 0 (a's real part fixed): petals cut straight by
    # the branch cut of log; z-buffer normals, since the analytic ones do not hold on the cut
    "hypercomplex_pwr": HC + [
        "normals.method=zbuffer",
        "fractal.function=pwr", "fractal.exponent=3,0.5", "fractal.c=-0.7,0,0,0", "fractal.max_iter=8",
        "slice.normal=1,0,0,1", "camera.position=0.6,3.8,-1.7", "camera.target=0,0.25,0",
        "camera.fov=38", "shading.light=3,4,-3", srgb(0.95, 0.5, 0.65)],
    # Gintz's CQuats (Ödegaard & Wennergren eq. 14) at Ödegaard & Wennergren Fig. 7's c: square angles and square holes
    "cquat_sqr": [
        "fractal.algebra=cquat", "fractal.c=-0.7323,-0.2179,0.1,0", "fractal.max_iter=12",
        "camera.position=-1.4,0.7,3.5", "shading.light=-3,4,4", "shading.shadow=hard",
        srgb(0.8, 0.85, 0.55)],
    # Ödegaard & Wennergren eq. 15, the naive commutative rules, Fig. 7's c: "highly irregular shapes"
    "commutative_sqr": [
        "fractal.algebra=commutative", "fractal.c=-0.7323,-0.2179,0.1,0", "fractal.max_iter=12",
        "camera.position=-1.4,0.7,3.5", "shading.light=-3,4,4", "shading.shadow=hard",
        srgb(0.9, 0.6, 0.5)],
}


def select(only: list[str]) -> list[str]:
    """The table keys ``--only`` names (a key, or a function name for every algebra's)."""
    if not only:
        return list(SCENES)
    picked = []
    for n in only:
        keys = [k for k in SCENES if k == n or k.split("_", 1)[1] == n]
        if not keys:
            raise SystemExit(f"gallery.py: error: --only {n}: no such scene (one of {', '.join(SCENES)})")
        picked += [k for k in keys if k not in picked]
    return picked


def downsample(result, ss: int):
    """(colour, alpha) box-filtered by ss x ss; colour averaged over the hit samples only,
    so the edges carry coverage in alpha and no background in colour (straight alpha)."""
    c, a = result.color.astype(np.float64), result.alpha.astype(np.float64)
    if ss == 1:
        return result.color, result.alpha
    h, w = a.shape[0] // ss, a.shape[1] // ss
    a4 = a.reshape(h, ss, w, ss)
    cov = a4.mean(axis=(1, 3))
    ca = (c * a[..., None]).reshape(h, ss, w, ss, 3).sum(axis=(1, 3))
    bg = c.reshape(h, ss, w, ss, 3).mean(axis=(1, 3))
    n = a4.sum(axis=(1, 3))[..., None]
    color = np.where(n > 0, ca / np.maximum(n, 1e-30), bg)
    return color.astype(np.float32), cov.astype(np.float32)


def sheet(paths: dict[str, Path], out: Path, tile_w: int, tile_h: int, cols: int = 5) -> None:
    """A grid of the pictures on a dark ground, each named below."""
    from PIL import Image, ImageDraw, ImageFont

    label_h = max(14, tile_h // 10)
    try:
        font = ImageFont.truetype("DejaVuSans.ttf", int(label_h * 0.7))
    except OSError:
        font = ImageFont.load_default()
    rows = (len(paths) + cols - 1) // cols
    pad = 4
    ground = (18, 18, 22)
    img = Image.new("RGB", (cols * (tile_w + pad) + pad, rows * (tile_h + label_h + pad) + pad), ground)
    draw = ImageDraw.Draw(img)
    for i, (name, path) in enumerate(paths.items()):
        x = pad + (i % cols) * (tile_w + pad)
        y = pad + (i // cols) * (tile_h + label_h + pad)
        pic = Image.open(path).convert("RGBA")
        if pic.size != (tile_w, tile_h):
            pic = pic.resize((tile_w, tile_h), Image.LANCZOS)
        back = Image.new("RGBA", pic.size, ground + (255,))
        img.paste(Image.alpha_composite(back, pic).convert("RGB"), (x, y))
        text = name.replace("_", " ")
        tw = draw.textlength(text, font=font)
        draw.text((x + (tile_w - tw) / 2, y + tile_h + label_h * 0.12), text, fill=(225, 225, 225), font=font)
    tmp = out.with_name(f".{out.name}.tmp.png")
    img.save(tmp, optimize=True)
    tmp.replace(out)


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240", help="picture size WxH (default 320x240)")
    ap.add_argument("--only", nargs="+", default=[], metavar="NAME", help="render only these scenes")
    ap.add_argument("--ss", type=int, default=3,
                    help="supersampling: samples per pixel along each axis (default 3)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    try:
        w, h = size_of(a.size, "--size")
    except ValueError:
        ap.error(f"--size {a.size}: expected WxH, e.g. 320x240")
    if w < 1 or h < 1 or a.ss < 1:
        ap.error("--size and --ss must be positive")
    names = select(a.only)

    warnings.simplefilter("ignore")
    from pyjulia4d import Scene, render
    from pyjulia4d.app.output import write_image

    folder = a.out / "gallery"
    folder.mkdir(parents=True, exist_ok=True)
    rows, device, total = [], "?", time.perf_counter()
    for name in names:
        scene = Scene.default().with_overrides(
            COMMON + SCENES[name] + [f"image.width={w * a.ss}", f"image.height={h * a.ss}"])
        result = render(scene)
        device = result.device_name
        report, _ = result.report()
        color, alpha = downsample(result, a.ss)
        header = {"pyjulia4d.scene": scene.to_toml(), **report,
                  "pyjulia4d.gallery": f"{w}x{h}, {a.ss}x{a.ss} samples per pixel, box filter"}
        path = folder / f"{name}.png"
        write_image(path, dataclasses.replace(result, color=color, alpha=alpha), header)
        nan = int(np.isnan(result.color).sum())
        print(f"{name:24s} {result.seconds:6.2f} s  hit {100 * result.hit_fraction:5.1f} %"
              + (f"  NaN in {nan} colour values" if nan else ""), flush=True)
        keys = " ".join(f"`{o}`" for o in SCENES[name] if o not in HC)
        rows.append(f"| {name} | {result.seconds:.2f} | {100 * result.hit_fraction:.1f} % | {keys} |")
    total = time.perf_counter() - total
    pictures = {n: folder / f"{n}.png" for n in SCENES}
    if all(p.exists() for p in pictures.values()):  # with --only, the others from earlier runs
        scale = min(1.0, 320 / w, 240 / h)
        sheet(pictures, folder / "sheet.png", max(1, round(w * scale)), max(1, round(h * scale)))
        print(f"wrote {folder / 'sheet.png'}")
    head = (f"\n## {utc_now()}, {device}, commit {git_commit()}, {w}x{h}, {a.ss}x{a.ss} samples per pixel"
            f"{', only ' + ' '.join(names) if len(names) < len(SCENES) else ''}; {total:.1f} s in all\n\n"
            f"Every scene also takes `{' '.join(COMMON)}`; render seconds include building "
            "the program on its first use (programs are cached on disk).\n\n"
            "| picture | render s | hit | scene keys |\n|---|---|---|---|\n")
    md = a.out / "gallery.md"
    append_run(md, "# Gallery\n\nWritten by `python benchmarks/galleries/gallery.py`: one picture per algebra x "
               "function pair, in `benchmarks/results/gallery/`.\n", head + "\n".join(rows) + "\n")
    print(f"wrote {md} ({total:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
