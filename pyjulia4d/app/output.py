"""Image outputs: the checks of an output path before any render, the PNG, TIFF and EXR
writers (atomic: pyjulia4d/files.py) and the reader of their headers."""
from __future__ import annotations

import contextlib
import logging
import os
import re
import stat
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping

import numpy as np

from pyjulia4d.files import NAME_MAX, PATH_MAX, RANDOM_CHARS, atomic_write, path_limit, path_text, quoted_path, \
    shown_path, signals_held, temp_affixes
from pyjulia4d.scene.checks import show

FORMATS = (".png", ".exr", ".tif", ".tiff")
TIFF = (".tif", ".tiff")

class OutputError(ValueError):
    """Unusable output path or format; the message starts with the path."""


@contextlib.contextmanager
def output_errors(path: str | Path, doing: str = "cannot write") -> Iterator[None]:
    """OS errors on an output path, in one place: whatever the system refuses while ``path`` is
    made or written (ENAMETOOLONG, ELOOP, ENOTDIR, EACCES, EROFS, ENOSPC, ...) becomes one
    OutputError naming the path, shortened (files.shown_path), what was being done and the
    system's reason.  Every writer (images, scene files, meshes, frames, videos) runs in one;
    the files themselves are written atomically (files.atomic_write), so nothing is left."""
    try:
        yield
    except OSError as e:
        raise OutputError(f"{shown_path(str(path))}: {doing}: {e.strerror or e}") from None


def _suffix(path: str | Path) -> str:
    return Path(path).suffix.lower()


def check_directory(shown: str, parent: Path) -> None:
    """The one-line errors for an output whose directory ``parent`` is missing, unreadable or
    not a directory (images, scene files, videos); ``shown`` names the output."""
    try:
        st = os.stat(parent)
    except FileNotFoundError:
        raise OutputError(f"{shown}: directory {quoted_path(parent)} does not exist") from None
    except (OSError, ValueError) as e:
        raise OutputError(f"{shown}: directory {quoted_path(parent)}: "
                          f"{getattr(e, 'strerror', None) or e}") from None
    if not stat.S_ISDIR(st.st_mode):
        raise OutputError(f"{shown}: {quoted_path(parent)} is not a directory")


def check_output_path(path: str | Path, formats: tuple[str, ...] = FORMATS, what: str = "output") -> Path:
    """Fail before rendering if ``path`` cannot take the image: its format (one of
    ``formats``: an unsupported ``what`` format), its directory, the length of its name and path
    (the temp file's too), and a temp file really created (and removed) beside it."""
    raw = path_text(path, lambda got: OutputError(f"{what} path: expected {got}"))
    shown = shown_path(raw)
    if not raw:
        raise OutputError(f"{shown}: empty output path")
    p = Path(raw)
    ext = _suffix(p)
    if ext not in formats:
        got = quoted_path(ext) if ext else "'(none)'"
        names = " or ".join(([", ".join(formats[:-1])] if len(formats) > 1 else []) + [formats[-1]])
        raise OutputError(f"{shown}: unsupported {what} format {got} (use {names})")
    if raw.endswith(("/", os.sep)):
        raise OutputError(f"{shown}: names a directory (trailing '/')")
    parent = p.parent
    check_directory(shown, parent)
    name_max = path_limit(parent, "PC_NAME_MAX", NAME_MAX)
    path_max = path_limit(parent, "PC_PATH_MAX", PATH_MAX)  # counts the terminating NUL
    name = len(os.fsencode(p.name))
    if name > name_max:
        raise OutputError(f"{shown}: file name too long ({name} bytes; this file system "
                          f"allows {name_max})")
    prefix, suffix = temp_affixes(p, name_max)
    longest = max(len(os.fsencode(raw)),
                  len(os.fsencode(os.path.join(parent, prefix + suffix))) + RANDOM_CHARS)
    if longest >= path_max:
        raise OutputError(f"{shown}: path too long ({longest} bytes with the temporary "
                          f"file's name; the limit is {path_max - 1})")
    try:
        is_dir = stat.S_ISDIR(os.stat(p).st_mode)
    except FileNotFoundError:
        is_dir = False
    except (OSError, ValueError) as e:  # ValueError: a NUL in the name
        raise OutputError(f"{shown}: {getattr(e, 'strerror', None) or e}") from None
    if is_dir:
        raise OutputError(f"{shown}: is a directory")
    try:
        # the only exact test of "can a file be made here" (permissions, read-only
        # mounts, /proc, ACLs, root) is to make one
        with signals_held():
            fd, tmp = tempfile.mkstemp(dir=parent, prefix=prefix, suffix=suffix)
            os.close(fd)
            os.unlink(tmp)
    except OSError as e:
        raise OutputError(f"{shown}: cannot create a file in {quoted_path(parent)}: "
                          f"{e.strerror or e}") from None
    return p


PNG_BAND_ROWS = 64   # rows encoded at a time (write_png)


def to_u8(x: np.ndarray) -> np.ndarray:
    """Values in [0, 1] (clipped; NaN as 0) as 8-bit integers, rounded (colormap.levels_u8)."""
    from pyjulia4d.pipeline.colormap import levels_u8

    return levels_u8(x, srgb=False)


def to_levels(x: np.ndarray, bits: int) -> np.ndarray:
    """Values in [0, 1] (clipped; NaN as 0) as 8- or 16-bit integers, rounded."""
    if bits == 8:
        return to_u8(x)
    x = np.nan_to_num(np.asarray(x, dtype=np.float32), nan=0.0)
    return np.rint(np.clip(x, 0.0, 1.0) * 65535.0).astype(np.uint16)


def wants_alpha(scene: Any) -> bool:
    """image.alpha resolved: "auto" is alpha, but opaque where a gradient or image is behind the set."""
    a = scene.image.alpha
    if a == "auto":
        from pyjulia4d.pipeline.backdrop import has_backdrop

        return not has_backdrop(scene.shading)
    return bool(a)


def background_of(result: Any, scene: Any) -> np.ndarray:
    """What a render's missed samples saw: its backdrop (H, W, 3), else shading.background (3,)."""
    back = getattr(result, "backdrop", None)
    return back if back is not None else np.asarray(scene.shading.background, np.float32)


def straight_colour(color: np.ndarray, alpha: np.ndarray, background) -> np.ndarray:
    """The colour a PNG's or TIFF's straight alpha wants: a pixel the set covers in part was
    rendered as a c + (1 - a) background (its samples that missed saw the background), so its
    own colour is (colour - (1 - a) background) / a; pixels wholly covered or wholly missed
    keep theirs.  ``background``: a colour (3,), or per pixel (H, W, 3) (background_of).
    ``color`` is copied only where some pixel is covered in part."""
    a = np.asarray(alpha)
    part = (a > 0) & (a < 1)
    if not part.any():
        return color
    out = np.array(color, np.float32)
    ap = a[part].astype(np.float32)[:, None]
    bg = np.asarray(background, np.float32)
    bg = bg[part] if bg.ndim == 3 else bg[None, :3]   # a backdrop's own colour at each pixel
    out[part] = np.maximum((out[part] - (1 - ap) * bg) / ap, 0.0)
    return out


def rgba_levels(color: np.ndarray, alpha: np.ndarray | None, bits: int = 8) -> np.ndarray:
    """(H, W, 4) integers of ``bits`` (8 or 16) from ``color`` (H, W, 3), linear light, and
    ``alpha`` (H, W) in [0, 1]: the colour clipped to [0, 1] and sRGB-encoded (the renderer
    shades in linear light; an EXR keeps it linear), alpha linear; both rounded.  Without
    ``alpha`` (None): (H, W, 3), the colour alone."""
    from pyjulia4d.pipeline.colormap import levels_u8, linear_to_srgb
    from pyjulia4d.pipeline.store import new_empty

    color = np.asarray(color)
    alpha = None if alpha is None else np.asarray(alpha)
    if color.ndim != 3 or color.shape[2] != 3 or (alpha is not None and alpha.shape != color.shape[:2]):
        raise ValueError(f"expected color (H, W, 3) and alpha (H, W), got {color.shape} and "
                         f"{None if alpha is None else alpha.shape}")
    # in bands of rows: the float64 temporaries of the transfer function on a whole 3840x2160
    # image took 800 MB (a PNG render's peak was 1.16 GB); a band's are a few MB
    # pages of its own past 4 MiB (store.new_empty: numpy's huge pages took 70-80 ms to first
    # touch for a 3840x2160 image here, plain pages 12 ms)
    rgba = new_empty(color.shape[:2] + (3 if alpha is None else 4,), np.uint8 if bits == 8 else np.uint16)
    for r0 in range(0, color.shape[0], PNG_BAND_ROWS):
        band = slice(r0, r0 + PNG_BAND_ROWS)
        if bits == 8:   # from tables, the same levels as the transfer function's (levels_u8),
            for k in range(3):   # a channel at a time: the render's colour lies in planes
                rgba[band, :, k] = levels_u8(color[band, :, k], srgb=True, total=color.size)
        else:
            rgba[band, :, :3] = to_levels(linear_to_srgb(np.nan_to_num(np.asarray(color[band], np.float32), nan=0.0)),
                                          bits)
        if alpha is not None:
            rgba[band, :, 3] = to_levels(alpha[band], bits)
    return rgba


def _itxt(key: str, text: str) -> bytes:
    """A PNG iTXt chunk's data: keyword, no compression, no language (PNG 1.2, 4.2.3.3)."""
    return key.encode("latin-1", "replace")[:79] + b"\0\0\0\0\0" + str(text).encode("utf-8")


def write_png(
    path: str | Path,
    color: np.ndarray,
    alpha: np.ndarray,
    text: Mapping[str, str] | None = None,
    bits: int = 8,
) -> None:
    """RGBA PNG of ``bits`` per channel (8 or 16: image.bits) from ``color`` and ``alpha``
    (rgba_levels; RGB where ``alpha`` is None: image.alpha false).  ``text`` entries become iTXt chunks (UTF-8, unlike tEXt's Latin-1).
    Pillow writes 8 bits; pypng 16, its chunks with the text added before IEND."""
    rgba = np.ascontiguousarray(rgba_levels(color, alpha, bits))
    if bits == 8:
        from PIL import Image, PngImagePlugin

        info = PngImagePlugin.PngInfo()
        for k, v in (text or {}).items():
            info.add_itxt(k, str(v))
        with atomic_write(path) as tmp:
            Image.fromarray(rgba).save(tmp, format="PNG", pnginfo=info)
        return
    import io

    import png

    h, w = rgba.shape[:2]
    buf = io.BytesIO()
    png.Writer(w, h, greyscale=False, alpha=rgba.shape[2] == 4, bitdepth=16).write_packed(
        buf, (row.astype(">u2").tobytes() for row in rgba))
    chunks = list(png.Reader(bytes=buf.getvalue()).chunks())
    chunks[-1:-1] = [(b"iTXt", _itxt(k, v)) for k, v in (text or {}).items()]
    with atomic_write(path) as tmp, open(tmp, "wb") as f:
        png.write_chunks(f, chunks)


def write_tiff(
    path: str | Path,
    color: np.ndarray,
    alpha: np.ndarray,
    text: Mapping[str, str] | None = None,
    bits: int = 8,
) -> None:
    """RGBA TIFF (tifffile) of ``bits`` per channel, as write_png's pixels, deflate-compressed,
    alpha unassociated; ``text`` as a JSON object in the ImageDescription tag."""
    import json

    import tifffile

    rgba = np.ascontiguousarray(rgba_levels(color, alpha, bits))
    with atomic_write(path) as tmp:
        tifffile.imwrite(tmp, rgba, photometric="rgb", extrasamples=["unassalpha"] if rgba.shape[2] == 4 else None,
                         compression="zlib", description=json.dumps(dict(text or {})), metadata=None)


EXR_BAND_ROWS = 64   # rows written at a time (write_exr)
# OpenEXR's standard attributes under OpenImageIO's names for them
_OIIO_NAMES = {"worldToCamera": "worldtocamera", "worldToNDC": "worldToNDC"}


def write_exr(
    path: str | Path,
    channels: Mapping[str, Any],
    header: Mapping[str, Any] | None = None,
    release: Callable[[slice], None] | None = None,
    shape: tuple[int, int] | None = None,
) -> None:
    """Single-part scanline EXR, ZIP-compressed, one float32 channel per entry, written in
    bands of EXR_BAND_ROWS rows by OpenImageIO: a channel is an (H, W) array or a function
    of a band of rows giving that band (exr_layout.exr_output), so no copy of the whole
    image is made; ``release(rows)`` is called after each band is written (store.py: the
    rows' pages let go).  ``header`` entries are written as string attributes, and numpy
    4x4 matrices as OpenEXR's M44f (worldToCamera, worldToNDC).  ``shape`` (H, W): the
    image's, where no channel is an array."""
    import OpenImageIO as oiio

    if not channels:
        raise ValueError("no channels to write")
    names = list(channels)
    shapes = {np.shape(v) for v in channels.values() if not callable(v)}
    if len(shapes) > 1 or any(len(s) != 2 for s in shapes):
        raise ValueError(f"EXR channels must be 2D and of one shape, got {sorted(shapes)}")
    if shape is not None:
        shapes.add(tuple(shape))
    if len(shapes) != 1:
        raise ValueError(f"EXR channels must be of the image's shape {shape}, got {sorted(shapes)}"
                         if shapes else "EXR channels need an array or a shape to give the image's size")
    h, w = next(iter(shapes))
    spec = oiio.ImageSpec(w, h, len(names), "float")
    spec.channelnames = tuple(names)
    spec.attribute("compression", "zip")
    for k, v in (header or {}).items():
        if isinstance(v, np.ndarray):
            spec.attribute(_OIIO_NAMES.get(k, k), oiio.TypeDesc("matrix"), tuple(float(x) for x in v.ravel()))
        else:
            spec.attribute(k, str(v))
    band = np.empty((min(EXR_BAND_ROWS, h), w, len(names)), np.float32)
    with atomic_write(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None or not out.open(str(tmp), spec):
            raise OSError(f"OpenImageIO cannot open the EXR: {oiio.geterror() if out is None else out.geterror()}")
        try:
            for r0 in range(0, h, EXR_BAND_ROWS):
                rows = slice(r0, min(h, r0 + EXR_BAND_ROWS))
                n = rows.stop - r0
                for c, name in enumerate(names):
                    v = channels[name]
                    band[:n, :, c] = v(rows) if callable(v) else v[rows]
                if not out.write_scanlines(r0, rows.stop, 0, band[:n]):
                    raise OSError(f"OpenImageIO cannot write the EXR: {out.geterror()}")
                if release is not None:
                    release(rows)
        finally:
            if not out.close():
                raise OSError(f"OpenImageIO cannot finish the EXR: {out.geterror()}")


# a header key as every format can hold it: PNG's keyword rules (1-79 Latin-1 characters,
# printable, no leading, trailing or double spaces), the strictest of the three
_HEADER_KEY = re.compile(r"[\x20-\x7e\xa1-\xff]{1,79}")
MAX_HEADER_VALUE = 1 << 20   # characters


def check_header(header: Any, reserved: str = "") -> dict[str, str]:
    """A header given from Python: None or a mapping of text keys (PNG's keyword rules, which
    EXR and TIFF also take) to text values (no NUL, at most 1 Mi characters); keys starting
    with ``reserved`` are the render's own entries and refused.  OutputError, one line, else."""
    if header is None:
        return {}
    if not isinstance(header, Mapping):
        raise OutputError(f"header: expected None or a dict of text entries, got {type(header).__name__}")
    try:
        items = list(header.items())
    except Exception:   # a mapping whose own items() fails
        raise OutputError(f"header: its entries cannot be read ({type(header).__name__})") from None
    out = {}
    for k, v in items:
        if not isinstance(k, str) or not _HEADER_KEY.fullmatch(k) or k != k.strip() or "  " in k:
            raise OutputError(f"header: key {show(k)}: expected 1 to 79 printable Latin-1 characters, no space "
                              f"at either end or twice")
        if reserved and k.startswith(reserved):
            raise OutputError(f"header: key {show(k)}: the {reserved}* entries are the render's own")
        if not isinstance(v, str) or "\0" in v or len(v) > MAX_HEADER_VALUE:
            raise OutputError(f"header: {k}: expected text without NUL, at most {MAX_HEADER_VALUE} characters, "
                              f"got {show(v)}")
        out[k] = v
    return out


def write_image(path: str | Path, result: Any, header: Mapping[str, str] | None = None,
                release: Callable[[slice], None] | None = None) -> None:
    """Write a RenderResult as .png or .tif/.tiff (colour + alpha, 8 or 16 bits a channel by
    the scene's image.bits) or .exr (the channels of the scene's image.exr layout:
    exr_layout.py); ``release(rows)`` after each band of an EXR is written (write_exr)."""
    p = check_output_path(path)
    if not hasattr(result, "color") or not hasattr(result, "alpha"):
        raise OutputError(f"{shown_path(str(p))}: expected a RenderResult to write, got {type(result).__name__}")
    header = check_header(header)
    scene = getattr(result, "scene", None)
    bits = scene.image.bits if scene is not None else 8
    try:
        if _suffix(p) in (".png",) + TIFF:
            from pyjulia4d.pipeline.tonemap import display
            color, alpha = result.color, result.alpha
            if scene is not None and color is not None:
                if not wants_alpha(scene):   # opaque: the picture on its background, as rendered
                    alpha = None
                elif alpha is not None:     # straight alpha: the background out of the edges' colour
                    color = straight_colour(color, alpha, background_of(result, scene))
                # exposure and tone map: the picture's, not an EXR's
                color = display(color, scene.image.exposure, scene.image.tonemap)
            (write_png if _suffix(p) == ".png" else write_tiff)(p, color, alpha, header, bits)
        else:
            from pyjulia4d.app.exr_layout import exr_output

            channels, extra = exr_output(result, scene) if scene is not None else (result.exr_channels(), {})
            shape = next((np.shape(a)[:2] for a in (result.color, result.alpha, getattr(result, "depth", None))
                          if a is not None), None)
            write_exr(p, channels, {**(header or {}), **extra}, release, shape)
    except OSError as e:
        raise OutputError(f"{shown_path(str(p))}: cannot write: {e.strerror or e}") from None


def write_file(path: str | Path, data: bytes | str) -> None:
    """``data`` (text as UTF-8) into ``path``, atomically; OutputError naming it when it cannot
    be written (scene files, meshes)."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    with output_errors(path), atomic_write(path) as tmp:
        tmp.write_bytes(data)


def render_header(scene: Any, result: Any) -> tuple[dict[str, str], str]:
    """An image's header entries - the scene as rendered (with camera.fit, the camera the
    framing pass chose: the same picture comes back from it) and the render's report - and the
    tail of the closing line that says the same (RenderResult.report)."""
    from pyjulia4d.scene.quality import resolved_quality, stated_p99

    # capped rays, the guards that fired, the certified depth bracket and the unresolved
    # space are part of the result: said in the header and the closing line, never hidden
    report, tail = result.report(stated_p99(resolved_quality(scene)))
    rendered = getattr(result, "scene", None) or scene
    return {"pyjulia4d.scene": rendered.to_toml(), **report}, tail


LOST_SET = 0.01   # a share of pixels hit below which the closing line suggests camera.fit


def closing_line(out: Path, scene: Any, result: Any, tail: str, verbose: bool, why: str = "") -> str:
    """The render command's last line.  At a glance: the output, size, time and device, the
    error the render states in one figure (RenderResult.brief) and the camera camera.fit
    chose.  ``verbose``: the whole report (``tail``, render_header's) after ``why`` the device."""
    from pyjulia4d.scene.quality import stated_p99

    rendered = getattr(result, "scene", None) or scene
    w, h = scene.image.width, scene.image.height
    framed = ""
    if scene.camera.fit and rendered is not scene:
        pos = ", ".join(f"{v:.4g}" for v in rendered.camera.position)
        tail += f"; camera framed by a first pass (camera.fit): position [{pos}]"
        framed = f"; framed from [{pos}]"
    head = f"rendered {out} ({w}x{h}) in {result.seconds:.2f} s on {result.device_name}"
    if getattr(result, "fell_back", ""):   # the default device failed: said, with what took over
        head += f" (the default failed: {result.fell_back})"
    if verbose:
        return f"{head}{why}, {100 * result.hit_fraction:.1f}% of pixels hit{tail}"
    # a preset's bound is named only where the user chose the preset
    chosen = stated_p99(scene.march.quality) if scene.march.quality != "auto" else None
    hint = ""
    if not scene.camera.fit and getattr(result, "hit_fraction", 1.0) < LOST_SET:
        # a camera placed by hand turns camera.fit off: say so where the set is all but out of view
        hint = (f"; the set covers {100 * result.hit_fraction:.2g}% of the picture: --set camera.fit=true "
                f"frames it from this camera")
    return head + (result.brief(chosen) if hasattr(result, "brief") else "") + framed + hint


@contextlib.contextmanager
def library_quiet(name: str) -> Iterator[None]:
    """The log records of the library logging as ``name`` dropped while in the block: tifffile
    logs what it finds wrong with a damaged file to the standard error, where the caller's one
    line, naming the file, says it already."""
    log = logging.getLogger(name)
    was, log.disabled = log.disabled, True
    try:
        yield
    finally:
        log.disabled = was


def read_header(path: str | Path) -> dict[str, str] | None:
    """An image's header entries (PNG text chunks, EXR string attributes), as write_image
    wrote them; None if it cannot be read (OutputError if ``path`` is no path at all)."""
    path = Path(path_text(path, lambda got: OutputError(f"image path: expected {got}")))
    try:
        if path.suffix.lower() == ".exr":
            import OpenEXR
            hdr = OpenEXR.File(str(path), header_only=True).header()
            return {k: v for k, v in hdr.items() if isinstance(v, str)}
        if path.suffix.lower() in TIFF:
            import json

            import tifffile
            with library_quiet("tifffile"), tifffile.TiffFile(path) as t:
                description = t.pages[0].description or "{}"
            try:   # another program's description (not our JSON object) is no damage: no entries
                text = json.loads(description)
            except (ValueError, RecursionError):
                return {}
            if not isinstance(text, dict):
                return {}
            return {k: v for k, v in text.items() if isinstance(k, str) and isinstance(v, str)}
        from PIL import Image
        with Image.open(path) as im:
            im.load()  # text chunks after the image data too; a truncated file fails here
            return dict(im.text)
    except Exception:  # a damaged or foreign file
        return None
