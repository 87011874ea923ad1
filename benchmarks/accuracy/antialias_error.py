"""Antialiasing's edge error and cost: uniform supersampling (image.samples) against the
adaptive mode (image.adaptive, pyjulia4d/pipeline/antialias.py), each against a 16-sample uniform
render of the same scene.

Per scene and mode: the error of the colour, sRGB-encoded (what a PNG stores), as the
largest channel difference |RGB - RGB_ref| per pixel, its mean and 99th percentile over
the *edge pixels* and over all pixels.  Edge pixels are defined from the reference alone
(not from the adaptive flags, which would favour the adaptive mode): partial coverage,
0 < alpha_ref < 1, or a step of more than EDGE_STEP in a channel of the sRGB colour or in
alpha to one of the 8 neighbours.  The cost is the median over --repeats renders of the
kernels' own time (RenderResult.kernel_seconds) and of the wall time, as ratios to
samples = 1 measured in the same run (the machine is shared and noisy).  For the adaptive
modes, the share of pixels flagged and of pixels the sample passes ran over (whole 8x8
blocks) are listed too; --thresholds 16 4 adds 4-sample adaptive rows with the flag
threshold (antialias.THRESHOLD, 1/64) set to 1/16 and 1/4.  Writes
benchmarks/results/antialias.md (a section per run: device, date, commit); --pictures DIR
also writes each mode's PNG, to look at.

    python benchmarks/accuracy/antialias_error.py [--size 320x240] [--repeats 3] [--thresholds 256 16 4]
                                         [--pictures DIR]
"""
from __future__ import annotations

import statistics
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

from pyjulia4d import Scene, render  # noqa: E402
from pyjulia4d.pipeline import antialias
from pyjulia4d.pipeline.colormap import linear_to_srgb  # noqa: E402
from pyjulia4d.fractal.registry import march_method  # noqa: E402

SCENES = {
    "default": [],
    "hypercomplex": ["fractal.algebra=hypercomplex", "fractal.c=-0.123,0,-0.745,0", "camera.fit=true"],
    "hypercomplex sin (fixed scan, thin parts)": ["fractal.algebra=hypercomplex", "fractal.function=sin",
                                                  "camera.fit=true"],
}
# (label, samples, adaptive); the reference is REFERENCE uniform samples
MODES = [("1", 1, False), ("4", 4, False), ("4 adaptive", 4, True), ("9", 9, False),
         ("9 adaptive", 9, True)]
REFERENCE = 16
DEFAULT_THRESHOLD = antialias.THRESHOLD
EDGE_STEP = 0.1   # sRGB step to a neighbour that makes a reference pixel an edge pixel


def _srgb_alpha(r) -> np.ndarray:
    """(H, W, 4): the sRGB-encoded colour and the alpha of a render."""
    return np.concatenate([linear_to_srgb(r.color), np.asarray(r.alpha, np.float64)[..., None]], axis=-1)


def edge_pixels(ref) -> np.ndarray:
    """(H, W) bool: the reference's partly covered pixels and those with a step over
    EDGE_STEP to one of their 8 neighbours (sRGB colour or alpha)."""
    v = _srgb_alpha(ref)
    h, w = v.shape[:2]
    p = np.pad(v, ((1, 1), (1, 1), (0, 0)), mode="edge")
    step = np.zeros((h, w))
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            step = np.maximum(step, np.abs(p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] - v).max(axis=-1))
    return ((ref.alpha > 0) & (ref.alpha < 1)) | (step > EDGE_STEP)


def error(r, ref) -> np.ndarray:
    """(H, W): the largest sRGB channel difference to the reference."""
    return np.abs(linear_to_srgb(r.color) - linear_to_srgb(ref.color)).max(axis=-1)


def timed(s: Scene, repeats: int):
    """The last of ``repeats`` renders, with the median wall and kernel seconds (after one
    unmeasured render that builds or loads the programs)."""
    render(s)
    runs = [render(s) for _ in range(repeats)]
    return (runs[-1], statistics.median(r.seconds for r in runs),
            statistics.median(r.kernel_seconds for r in runs))


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--scenes", nargs="*", default=list(SCENES), choices=list(SCENES))
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--pictures", type=Path, default=None)
    ap.add_argument("--thresholds", type=int, nargs="*", default=[],
                    help="denominators d: also 4-sample adaptive with threshold 1/d")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    w, h = size_of(a.size, "--size")
    device = "?"
    sections = []
    for name in a.scenes:
        base = Scene.default().with_overrides(SCENES[name] + [f"image.width={w}", f"image.height={h}"])
        ref = render(base.with_overrides([f"image.samples={REFERENCE}"]))
        device = ref.device_name
        edges = edge_pixels(ref)
        rows = []
        wall1 = kern1 = None
        centre = None
        modes = MODES + [(f"4 adaptive, threshold 1/{d}", 4, True, 1.0 / d) for d in a.thresholds]
        for label, n, adaptive, *threshold in modes:
            antialias.THRESHOLD = threshold[0] if threshold else DEFAULT_THRESHOLD
            s = base.with_overrides([f"image.samples={n}", f"image.adaptive={'true' if adaptive else 'false'}"])
            r, wall, kern = timed(s, a.repeats)
            if n == 1:
                wall1, kern1, centre = wall, kern, r
            e = error(r, ref)
            share = ""
            if adaptive:
                flags = antialias.flag_edges(centre.color, centre.alpha)
                tiles = antialias.block_tiles(flags, (0, 0, w, h), w, h, 0, w * h)
                ran = sum(t.w * t.h for t in tiles) / (w * h)
                share = f"{100 * flags.mean():.1f} / {100 * ran:.1f}"
            rows.append(f"| {label} | {e[edges].mean():.4f} | {np.percentile(e[edges], 99):.4f} | "
                        f"{e.mean():.4f} | {np.percentile(e, 99):.4f} | {kern:.3f} | {kern / kern1:.2f} | "
                        f"{wall:.3f} | {wall / wall1:.2f} | {share} |")
            print(f"{name}: {rows[-1]}", flush=True)
            if a.pictures is not None:
                from pyjulia4d.app.output import write_png
                a.pictures.mkdir(parents=True, exist_ok=True)
                slug = name.split(" ")[0] + ("_sin" if "sin" in name else "")
                tag = "".join(ch if ch.isalnum() else "_" for ch in label)
                write_png(a.pictures / f"{slug}_{tag}.png", r.color, r.alpha)
        antialias.THRESHOLD = DEFAULT_THRESHOLD
        sections.append(
            f"\n### {name} ({march_method(base)} march; {100 * edges.mean():.1f} % edge pixels)\n\n"
            "| samples | edge mean | edge p99 | all mean | all p99 | kernels s | kernels / 1 | "
            "wall s | wall / 1 | % flagged / % sampled |\n"
            "|---|---|---|---|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")
    head = (f"\n## {utc_now()}, {device}, commit {git_commit()}, {w}x{h}, median of {a.repeats}\n\n"
            f"Error: largest sRGB channel difference to a {REFERENCE}-sample uniform render, per pixel; "
            f"edge pixels: the reference's 0 < alpha < 1 or a step over {EDGE_STEP} to a neighbour.\n")
    append_run(a.out / "antialias.md", "# Antialiasing: edge error and cost\n\nWritten by "
               "`python benchmarks/accuracy/antialias_error.py`.\n", head + "".join(sections))
    print(f"wrote {a.out / 'antialias.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
