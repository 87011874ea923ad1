"""Image writers (PNG, EXR).  Every writer is atomic: a temp file in the target
directory is renamed over the output, so a failed or interrupted write leaves
nothing at the output path."""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Any, Iterator, Mapping

import numpy as np

FORMATS = (".png", ".exr")


class OutputError(ValueError):
    """Unusable output path or format; the message starts with the path."""


def _suffix(path: str | Path) -> str:
    return Path(path).suffix.lower()


def check_output_path(path: str | Path) -> Path:
    """Fail before rendering if ``path`` cannot take the image."""
    p = Path(path)
    ext = _suffix(p)
    if ext not in FORMATS:
        shown = ext or "(none)"
        raise OutputError(f"{p}: unsupported output format '{shown}' (use .png or .exr)")
    parent = p.parent
    if not parent.is_dir():
        raise OutputError(f"{p}: directory '{parent}' does not exist")
    if p.is_dir():
        raise OutputError(f"{p}: is a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{p}: directory '{parent}' is not writable")
    return p


def _file_mode() -> int:
    """0o666 less the umask: what a plain open() would have created."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def _atomic(path: str | Path) -> Iterator[Path]:
    """Yield a temp path beside ``path``; move it onto ``path`` only on success."""
    p = Path(path)
    with tempfile.NamedTemporaryFile(
        dir=p.parent, prefix=f".{p.stem}.", suffix=p.suffix, delete=False
    ) as f:
        tmp = Path(f.name)
    try:
        yield tmp
        os.chmod(tmp, _file_mode())  # NamedTemporaryFile creates 0600
        os.replace(tmp, p)
    except BaseException:  # KeyboardInterrupt too: never leave the temp file behind
        tmp.unlink(missing_ok=True)
        raise


def _to_u8(x: np.ndarray) -> np.ndarray:
    x = np.nan_to_num(np.asarray(x, dtype=np.float32), nan=0.0)
    return np.rint(np.clip(x, 0.0, 1.0) * 255.0).astype(np.uint8)


def write_png(
    path: str | Path,
    color: np.ndarray,
    alpha: np.ndarray,
    text: Mapping[str, str] | None = None,
) -> None:
    """8-bit RGBA PNG from ``color`` (H, W, 3) and ``alpha`` (H, W) in [0, 1].

    Values are clipped and rounded; no sRGB transfer is applied.  ``text``
    entries become PNG tEXt chunks.
    """
    from PIL import Image, PngImagePlugin

    color = np.asarray(color)
    alpha = np.asarray(alpha)
    if color.ndim != 3 or color.shape[2] != 3 or alpha.shape != color.shape[:2]:
        raise ValueError(f"expected color (H, W, 3) and alpha (H, W), got {color.shape} and {alpha.shape}")
    rgba = np.concatenate([_to_u8(color), _to_u8(alpha)[..., None]], axis=2)
    info = PngImagePlugin.PngInfo()
    for k, v in (text or {}).items():
        info.add_itxt(k, str(v))  # iTXt: UTF-8, unlike tEXt's Latin-1
    with _atomic(path) as tmp:
        Image.fromarray(np.ascontiguousarray(rgba)).save(tmp, format="PNG", pnginfo=info)


def write_exr(
    path: str | Path,
    channels: Mapping[str, np.ndarray],
    header: Mapping[str, str] | None = None,
) -> None:
    """Single-part scanline EXR, ZIP-compressed, one float32 channel per entry.

    ``header`` entries are written as string attributes.
    """
    import OpenEXR

    if not channels:
        raise ValueError("no channels to write")
    # OpenEXR.File replaces the dict's arrays by Channel objects: hand it a fresh dict.
    data = {name: np.ascontiguousarray(a, dtype=np.float32) for name, a in channels.items()}
    shapes = {a.shape for a in data.values()}
    if len(shapes) != 1 or len(next(iter(shapes))) != 2:
        raise ValueError(f"EXR channels must be 2D and of one shape, got {sorted(shapes)}")
    hdr: dict[str, Any] = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
    }
    hdr.update({k: str(v) for k, v in (header or {}).items()})
    with _atomic(path) as tmp:
        OpenEXR.File(hdr, data).write(str(tmp))


def write_image(path: str | Path, result: Any, header: Mapping[str, str] | None = None) -> None:
    """Write a RenderResult as .png (colour + alpha) or .exr (``result.exr_channels()``)."""
    p = check_output_path(path)
    try:
        if _suffix(p) == ".png":
            write_png(p, result.color, result.alpha, header)
        else:
            write_exr(p, result.exr_channels(), header)
    except OSError as e:
        raise OutputError(f"{p}: cannot write: {e.strerror or e}") from e
