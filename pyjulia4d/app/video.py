"""Video from a sequence of frames: MP4 (H.264) or WebM (VP9), through imageio-ffmpeg,
whose wheel ships its own ffmpeg (no system ffmpeg), or an animated GIF through Pillow
(no extra needed; each frame's own palette of 256 colours, Floyd-Steinberg dithered, looping
forever; GIF times frames in hundredths of a second, so 24 fps plays at 25).

PNG frames are taken as written (sRGB, 8 bits); EXR frames hold linear light and are
encoded like a PNG is (colour clipped to [0, 1], sRGB-encoded, rounded: output.write_png).
Alpha is dropped: missed pixels already hold shading.background.  Odd sizes are padded
to even ones by repeating the last row or column (4:2:0 chroma needs even sizes).  The
video is written atomically (output.py: a temp file beside it, renamed).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np

from pyjulia4d.app.output import OutputError, check_directory, library_quiet, output_errors
from pyjulia4d.files import atomic_write, path_text, quoted_path, shown_path
from pyjulia4d.resources import module_installed

CODECS = {".mp4": "libx264", ".webm": "libvpx-vp9"}
# H.264's constant rate factor and VP9's constant quality (lower is better; both about
# visually lossless for renders): smooth gradients of a render band at the defaults.
QUALITY = {".mp4": ["-crf", "18", "-preset", "medium"], ".webm": ["-crf", "24", "-b:v", "0"]}
FORMATS = (*CODECS, ".gif")


def have_ffmpeg() -> bool:
    """Whether imageio-ffmpeg (the ``video`` extra) is installed."""
    return module_installed("imageio_ffmpeg")


def check_video_path(path: str | os.PathLike) -> Path:
    """Fail before rendering if ``path`` cannot take the video: .mp4, .webm or .gif, in an
    existing, writable directory."""
    raw = path_text(path, lambda got: OutputError(f"video path: expected {got}"))
    shown = shown_path(raw)
    p = Path(raw)
    if not raw or raw.endswith(("/", os.sep)):
        raise OutputError(f"{shown}: not a file name")
    ext = p.suffix.lower()
    if ext not in FORMATS:
        got = quoted_path(ext) if ext else "'(none)'"
        raise OutputError(f"{shown}: unsupported video format {got} (use .mp4, .webm or .gif)")
    check_directory(shown, p.parent)
    if p.is_dir():
        raise OutputError(f"{shown}: is a directory")
    if not os.access(p.parent, os.W_OK | os.X_OK):
        raise OutputError(f"{shown}: cannot create a file in {quoted_path(p.parent)}")
    if ext in CODECS and not have_ffmpeg():
        raise OutputError(f"{shown}: video needs imageio-ffmpeg, which is not installed: pip install "
                          f"'pyjulia4d[video]'")
    return p


def read_frame(path: str | os.PathLike) -> np.ndarray:
    """A frame file as (H, W, 3) uint8 sRGB: a PNG's or TIFF's RGB, an EXR's R, G, B encoded as
    output.write_png encodes them.  A file that cannot be read as one is an OutputError naming it."""
    p = Path(path_text(path, lambda got: OutputError(f"frame path: expected {got}")))
    try:
        return _read_rgb(p)
    except OutputError:
        raise
    except Exception as e:   # missing, unreadable, or not an image of that format: the file's fault
        raise OutputError(f"{shown_path(str(p))}: cannot read it as a frame ({type(e).__name__}: "
                          f"{' '.join(str(e).split())[:120]})") from None


def _read_rgb(p: Path) -> np.ndarray:
    if p.suffix.lower() == ".exr":
        import OpenEXR

        from pyjulia4d.pipeline.colormap import levels_u8

        ch = OpenEXR.File(str(p), separate_channels=True).channels()
        if all(f"ViewLayer.Combined.{k}" in ch for k in "RGB"):   # image.exr = "compositing": over black
            ch = {k: ch[f"ViewLayer.Combined.{k}"] for k in "RGB"}
        if not all(k in ch for k in "RGB"):
            raise OutputError(f"{shown_path(str(p))}: no R, G, B channels to make a video of "
                              f"(rendered with --channels without RGBA)")
        rgb = np.stack([np.asarray(ch[k].pixels, np.float32) for k in "RGB"], axis=-1)
        return levels_u8(rgb, srgb=True)
    if p.suffix.lower() in (".tif", ".tiff"):   # 8 or 16 bits a channel (image.bits)
        import tifffile

        with library_quiet("tifffile"):
            rgba = tifffile.imread(p)
        return (rgba[..., :3] >> 8).astype(np.uint8) if rgba.dtype == np.uint16 else rgba[..., :3]
    from PIL import Image

    with Image.open(p) as im:   # a 16-bit PNG is read as 8 bits a channel
        return np.asarray(im.convert("RGB"))


def _even(frame: np.ndarray) -> np.ndarray:
    h, w = frame.shape[:2]
    return np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")


def write_video(path: str | os.PathLike, frames: Iterable[np.ndarray], fps: float) -> int:
    """Encode ``frames`` ((H, W, 3) uint8, one size) at ``fps`` into ``path`` (.mp4, .webm
    or .gif), atomically; returns the number of frames written."""
    p = check_video_path(path)
    ext = p.suffix.lower()
    it: Iterator[np.ndarray] = iter(frames)
    first = next(it, None)
    if first is None:
        raise OutputError(f"{shown_path(str(p))}: no frames to encode")
    if ext == ".gif":
        return _write_gif(p, first, it, fps)
    import imageio_ffmpeg

    first = _even(first)
    h, w = first.shape[:2]
    n = 0
    with output_errors(p), atomic_write(p) as tmp:
        writer = imageio_ffmpeg.write_frames(
            str(tmp), (w, h), fps=fps, codec=CODECS[ext], pix_fmt_in="rgb24", pix_fmt_out="yuv420p",
            quality=None, macro_block_size=1, output_params=QUALITY[ext], ffmpeg_log_level="error")
        writer.send(None)  # start ffmpeg
        try:
            for frame in (first, *(_even(f) for f in it)):
                if frame.shape != first.shape:
                    raise OutputError(f"{shown_path(str(p))}: frame {n} is {frame.shape[1]}x{frame.shape[0]}, "
                                      f"the first {w}x{h}: a video's frames share one size")
                writer.send(np.ascontiguousarray(frame))
                n += 1
        finally:
            writer.close()
    return n


def _write_gif(p: Path, first: np.ndarray, rest: Iterator[np.ndarray], fps: float) -> int:
    """An animated GIF of the frames through Pillow, looping forever: each frame quantised to
    its own 256 colours (median cut, Floyd-Steinberg dithering), shown for 1 / fps rounded to
    GIF's hundredths of a second (at least 2: browsers slow faster frames down to 10 fps)."""
    from PIL import Image

    count = [0]

    def quantised():
        for frame in (first, *rest):
            if frame.shape != first.shape:
                raise OutputError(f"{shown_path(str(p))}: frame {count[0]} is {frame.shape[1]}x{frame.shape[0]}, "
                                  f"the first {first.shape[1]}x{first.shape[0]}: a video's frames share one size")
            count[0] += 1
            yield Image.fromarray(np.ascontiguousarray(frame[..., :3]), "RGB").quantize(
                256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.FLOYDSTEINBERG)

    hundredths = max(2, round(100.0 / fps))
    with output_errors(p), atomic_write(p) as tmp:
        frames = quantised()
        head = next(frames)
        head.save(tmp, format="GIF", save_all=True, append_images=frames, duration=10 * hundredths, loop=0,
                  disposal=1, optimize=False)
    return count[0]


def video_from_files(path: str | os.PathLike, files: Iterable[str | os.PathLike], fps: float) -> int:
    """write_video of the frame files, read one at a time."""
    return write_video(path, (read_frame(f) for f in files), fps)
