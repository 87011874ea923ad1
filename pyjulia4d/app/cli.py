"""Command line: ``pyjulia4d render|animate|explore|mesh|keys|devices|import-pov`` (also ``python -m pyjulia4d``).

Bad input gets one stderr line, ``pyjulia4d: error: <key or path>: <reason>``, and
status 2; Ctrl-C status 130, SIGTERM 143 and SIGHUP 129 (128 + the signal number),
each after removing any temporary file."""
from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import threading
import warnings
from pathlib import Path
from typing import Any, Iterator, NoReturn, Sequence

from pyjulia4d.app.output import check_output_path, closing_line, render_header, write_image
from pyjulia4d.pipeline.progress import clear_stop, request_stop
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError, one_line, show_key
from pyjulia4d.scene.text import override_key

PROG = "pyjulia4d"
DEFAULT_PORT = 8470   # explore's port


class UsageError(Exception):
    """A command line argparse cannot parse; its message is argparse's."""


class Terminated(BaseException):
    """SIGTERM or SIGHUP, raised in the main thread so that clean-up runs as for Ctrl-C
    (a BaseException, like KeyboardInterrupt: ``except Exception`` must not catch it)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (no usage text) and status 2 from main()."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


def _parser() -> argparse.ArgumentParser:
    from pyjulia4d import __version__

    ap = _Parser(prog=PROG, description="Ray trace 3D views of 4D Julia sets: quaternions, the hypercomplex "
                                        "numbers with POV-Ray's 18 functions, CQuats and more.")
    ap.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    r = sub.add_parser("render", help="render a scene to .png or .exr")
    r.add_argument("scene", nargs="?", metavar="SCENE.toml|IMAGE.png|IMAGE.exr|IMAGE.tif",
                   help="scene file, or an image pyjulia4d rendered: its header holds the scene as "
                        "rendered, which is rendered again (default: the built-in scene)")
    r.add_argument("-o", "--output", metavar="OUT",
                   help="OUT.png, OUT.tif or OUT.exr (default: <scene stem>.png, <image stem>-rerender.png for an "
                        "image, or julia.png); image.bits=16 makes a PNG or TIFF 16 bits a channel")
    # kept as text so bad sizes get the same one-line scene error as --set
    r.add_argument("--width", metavar="W", help="image width in pixels (same as --set image.width=W; not both)")
    r.add_argument("--height", metavar="H", help="image height in pixels (same as --set image.height=H; not both)")
    r.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene value, e.g. --set fractal.c=-0.2,0.8,0,0 (repeatable; 'pyjulia4d keys' lists every key, its default and valid range)")
    r.add_argument("--device", metavar="SPEC", help="OpenCL device: P:D index, cpu, gpu, or part of its name")
    r.add_argument("--verbose", action="store_true",
                   help="end with the whole report: why the device, pixels hit, guards fired, the depth bracket "
                        "and error in full, unproven pixels (the image's header holds it either way)")
    r.add_argument("--channels", metavar="LIST",
                   help="EXR channel groups to compute and write, comma-separated from RGBA, Z (depth and "
                        "its bracket), N (normal), P (4D position); default all.  Z alone skips normals "
                        "and shading and keeps 8 bytes per pixel: the way to render huge depth maps")
    r.add_argument("--force", action="store_true",
                   help="render settings refused for their work: predicted over 6 hours by a probe render, or hopeless per ray")
    _cluster_options(r, "tiles of the image")

    a = sub.add_parser("animate", help="render a keyframed scene to numbered frames and a video")
    a.add_argument("scene", metavar="SCENE.toml", help="scene file with [[keyframe]] tables and [animation]")
    a.add_argument("-o", "--output", metavar="PATTERN",
                   help="frame files, one run of # for the frame number: frames/julia_####.png or .exr "
                        "(default: <scene stem>_####.png)")
    a.add_argument("--frames", metavar="A:B", help="render frames A to B (inclusive; default all)")
    a.add_argument("--video", metavar="OUT", help="also encode the frames into OUT.mp4, OUT.webm or an animated OUT.gif")
    a.add_argument("--width", metavar="W", help="frame width (same as --set image.width=W; not both)")
    a.add_argument("--height", metavar="H", help="frame height (same as --set image.height=H; not both)")
    a.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene key (it is then no longer keyframed) or animation.frames, "
                        "animation.fps, animation.interpolation")
    a.add_argument("--device", metavar="SPEC", help="OpenCL device of every worker (as for render)")
    a.add_argument("--channels", metavar="LIST", help="EXR channel groups (as for render)")
    a.add_argument("--force", action="store_true", help="render frames whose work is refused as hopeless")
    _cluster_options(a, "whole frames")

    m = sub.add_parser("mesh", help="the scene's 3D slice of the set as a triangle mesh (.stl, .ply, .obj, .glb)")
    m.add_argument("scene", nargs="?", metavar="SCENE.toml|IMAGE.png|IMAGE.exr",
                   help="scene file, or an image pyjulia4d rendered (default: the built-in scene)")
    m.add_argument("-o", "--output", metavar="OUT",
                   help="OUT.stl, OUT.ply, OUT.obj or OUT.glb (default: <scene stem>.stl, or julia.stl)")
    m.add_argument("--resolution", metavar="N", default="128",
                   help="grid points a side, 8 to 2048 (default 128; 512 took 16 s on a 2-core CPU)")
    m.add_argument("--smooth", metavar="PASSES", default="0",
                   help="Taubin smoothing passes, 0 to 1000 (default 0: every vertex on the surface)")
    m.add_argument("--decimate", metavar="SHARE", default="1",
                   help="keep this share of the triangles, in (0, 1] (default 1: all; quadric decimation may "
                        "open the mesh: the closing line says whether it is watertight)")
    m.add_argument("--size", metavar="MM", default=None,
                   help="scale the mesh so its longest side prints at MM millimetres (STL, PLY and OBJ in "
                        "millimetres, glTF in metres; default: scene units)")
    m.add_argument("--walls", action="store_true",
                   help="also report the thinnest wall, for printing (grids up to 1024 a side)")
    m.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene value, as for render ('clip.planes=[[0, -1, 0, 0.3]]' cuts a flat base)")
    m.add_argument("--device", metavar="SPEC", help="OpenCL device (as for render)")
    m.add_argument("--force", action="store_true", help="mesh grids whose sampling is estimated past 6 hours")

    e = sub.add_parser("explore", help="explore a scene in the browser: a local page that renders as you drag")
    e.add_argument("scene", nargs="?", metavar="SCENE.toml|IMAGE.png|IMAGE.exr",
                   help="scene to start from, or an image pyjulia4d rendered (default: the built-in scene)")
    e.add_argument("--port", metavar="N", default=str(DEFAULT_PORT),
                   help=f"port to listen on (default {DEFAULT_PORT}; 0: any free one)")
    e.add_argument("--host", metavar="ADDRESS", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this machine only)")
    e.add_argument("--folder", metavar="DIR", default=".",
                   help="where the page saves scenes, images and animations (default: the current directory)")
    e.add_argument("--no-browser", action="store_true", help="do not open the page in a browser")
    e.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene value, as for render")
    e.add_argument("--device", metavar="SPEC", help="OpenCL device (as for render)")

    sub.add_parser("devices", help="list the OpenCL devices, which cannot compile, and the default")

    k = sub.add_parser("keys", help="list every scene key with its default, valid range and meaning")
    k.add_argument("section", nargs="?", metavar="SECTION",
                   help="only this section's keys: fractal, camera, slice, march, normals, shading, "
                        "image, clip or render")

    i = sub.add_parser("import-pov", help="convert a POV-Ray julia_fractal scene to a scene file")
    i.add_argument("pov", metavar="FILE.pov", help="POV-Ray 3.7 scene with one julia_fractal")
    i.add_argument("-o", "--output", metavar="SCENE.toml",
                   help="scene file to write (default: <FILE stem>.toml in the current directory)")
    i.add_argument("--width", metavar="W", help="image width, also POV-Ray's image_width (default 640)")
    i.add_argument("--height", metavar="H", help="image height, also POV-Ray's image_height (default 480)")
    return ap


def _cluster_options(p: argparse.ArgumentParser, units: str) -> None:
    """--workers and --scheduler (app/cluster.py): Dask renders ``units``."""
    p.add_argument("--workers", metavar="N",
                   help=f"render {units} on a local Dask cluster of N worker processes (0: in this "
                        f"process; animate's default: one per GPU, or 1 on a CPU; in this process without the cluster "
                        f"extra)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help=f"render {units} on an existing Dask cluster, e.g. tcp://HOST:8786 "
                        f"(dask scheduler; dask worker tcp://HOST:8786 on each node)")


def select_device(spec: str | None) -> Any:
    """default_device.select, imported late: pyopencl is slow to import."""
    from pyjulia4d.opencl import default_device

    return default_device.select(spec)


def _size_overrides(args: argparse.Namespace) -> list[str]:
    """--set overrides with --width and --height added (render and animate)."""
    overrides = list(args.overrides)
    for flag, dotted in (("--width", "image.width"), ("--height", "image.height")):
        value = getattr(args, flag[2:])
        if value is None:
            continue
        if any(override_key(o) == dotted for o in overrides):
            raise SceneError(dotted, f"given twice, by {flag} and by --set {dotted}; use one")
        overrides.append(f"{dotted}={value}")
    return overrides


IMAGE_SUFFIXES = (".png", ".exr", ".tif", ".tiff")


def scene_from_image(path: str, overrides: Sequence[str] = ()) -> Scene:
    """The scene an image was rendered from: the resolved scene write_image put in its header
    (``pyjulia4d.scene``: the camera camera.fit chose included, so the same picture comes
    back), with overrides applied.  One SceneError naming the file if there is none."""
    from pyjulia4d.app.output import read_header
    from pyjulia4d.scene.text import MAX_SCENE_BYTES, scene_table_from_text

    shown = path if path.isprintable() else repr(path)
    if Path(path).is_dir():
        raise SceneError(shown, "is a directory, not an image")
    if not Path(path).exists():
        raise SceneError(shown, "cannot read: no such file")
    if not Path(path).is_file():   # a pipe or a device: an image's header is read by seeking
        raise SceneError(shown, "not a regular file; an image is read from a file")
    header = read_header(Path(path))
    if header is None:
        raise SceneError(shown, f"not a readable {Path(path).suffix.lower()[1:].upper()} file (damaged, truncated "
                                f"or another format)")
    text = header.get("pyjulia4d.scene")
    if text is None:
        raise SceneError(shown, "holds no pyjulia4d scene (not rendered by pyjulia4d, or its metadata "
                                "was stripped)")
    if len(text.encode("utf-8", "replace")) > MAX_SCENE_BYTES:
        raise SceneError(shown, "its scene is larger than 1 MiB")
    return Scene.from_dict(scene_table_from_text(text, f"{shown} (its scene)"), overrides)


def _render(args: argparse.Namespace) -> int:
    # the built-in scene is framed (camera.fit) unless a position is set; an image is rendered again
    scene = _scene_of(args.scene, _size_overrides(args))
    if args.scene is None:
        default_out = "julia.png"
    elif Path(args.scene).suffix.lower() in IMAGE_SUFFIXES:
        default_out = Path(args.scene).stem + "-rerender.png"
    else:
        default_out = Path(args.scene).stem + ".png"
    out = check_output_path(default_out if args.output is None else args.output)
    outputs = _outputs(args.channels, out)
    store = None
    if args.workers is not None or args.scheduler is not None:  # tiles on a Dask cluster
        from pyjulia4d.app.cluster import check_workers, render_on_cluster

        workers = None if args.workers is None else check_workers(args.workers)
        result = render_on_cluster(scene, workers, args.scheduler, args.device, outputs, args.force,
                                   progress=True)
    else:
        device = select_device(args.device)

        from pyjulia4d.opencl.executor import render  # heavy (kernel build); only once the input is known good
        from pyjulia4d.opencl.failures import DeviceFailure

        store = store_for(scene, outputs, out)
        from pyjulia4d.opencl import default_device

        try:
            result = render(scene, device=device, progress=True, force=args.force, outputs=outputs, store=store,
                            fallback=args.device is None)
        except DeviceFailure:
            if args.device is None:   # the remembered default failed where it alone was loaded
                default_device.again_with_every_runtime()
            raise
        if result.fell_back:   # the remembered default failed: the next command chooses again among all
            default_device.forget()
    header, tail = render_header(scene, result)
    if store is not None:
        store.release()   # the report's arrays, read whole
    write_image(out, result, header, None if store is None else store.release)
    why = ""
    if args.verbose and args.device is None and args.workers is None and args.scheduler is None \
            and hasattr(device, "int_ptr"):
        from pyjulia4d.opencl.devices import default_reason
        why = f" ({default_reason(device)})"
    print(closing_line(out, scene, result, tail, args.verbose, why))
    return 0


SPILL_BYTES = 256 * 2**20   # a render's host images past this live in a file (pipeline/store.py)


def store_for(scene: Scene, outputs, out: Path) -> Any:
    """Where a render's host images live: in memory, or past SPILL_BYTES in a file beside the
    output, its rows let go as they are filed and written (pipeline/store.py), so that the
    peak stays a band and the process rather than the image."""
    from pyjulia4d.pipeline.store import IN_MEMORY, ImageStore, spill_folder
    from pyjulia4d.pipeline.workload import output_bytes_per_pixel

    size = float(scene.image.width) * scene.image.height * output_bytes_per_pixel(outputs)
    return ImageStore(spill_folder(out)) if size > SPILL_BYTES else IN_MEMORY


def _scene_of(path: str | None, overrides: Sequence[str]) -> Scene:
    """The scene a command starts from: the built-in one (framed), a scene file, or the scene
    in an image's header."""
    if path is None:
        return Scene.from_dict({}, overrides)
    if Path(path).suffix.lower() in IMAGE_SUFFIXES:
        return scene_from_image(path, overrides)
    return Scene.from_toml(path, overrides)


def _whole(text: str) -> int | str:
    """A flag's whole number, or its text as given (the checker then names it)."""
    t = text.strip()
    return int(t) if t.isascii() and t.lstrip("+-").isdigit() and len(t) < 20 else text


def _real(text: str) -> float | str:
    """A flag's finite number, or its text as given (the checker then names it)."""
    from pyjulia4d.scene.checks import scalar

    value = scalar(text)
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else text


def _mesh(args: argparse.Namespace) -> int:
    """mesh: SCENE -> OUT.stl|ply|obj|glb (app/mesh.py); every argument checked before the device."""
    from pyjulia4d.app.mesh import (build_mesh, check_decimate, check_mesh_path, check_size, check_smooth, check_walls,
                                    write_mesh)
    from pyjulia4d.pipeline.mesh_plan import check_resolution, make_mesh_plan

    resolution = check_resolution(_whole(args.resolution))
    smooth = check_smooth(_whole(args.smooth))
    decimate = check_decimate(_real(args.decimate))
    size = check_size(None if args.size is None else _real(args.size))
    scene = _scene_of(args.scene, args.overrides)
    make_mesh_plan(scene, resolution)   # a slice outside the set's ball: refused before the device
    check_walls(args.walls, resolution)
    stem = "julia" if args.scene is None else Path(args.scene).stem
    out = check_mesh_path(args.output if args.output is not None else stem + ".stl")
    device = select_device(args.device)
    result = build_mesh(scene, resolution, device, smooth, args.force, progress=True,
                        warn=lambda text: _say(f"pyjulia4d: warning: {text}"), decimate=decimate, walls=args.walls)
    scaled = write_mesh(out, result, size)
    print(f"wrote {out} in {result.seconds['total']:.2f} s: {result.summary()}{scaled}")
    return 0


def _explore(args: argparse.Namespace) -> int:
    """explore: the local page (app/explore/); every argument checked before the device."""
    from pyjulia4d.app.explore.run import check_folder, check_host, check_port, explore

    host = check_host(args.host)
    port = check_port(args.port)
    folder = check_folder(args.folder)
    scene = _scene_of(args.scene, args.overrides)
    return explore(scene, select_device(args.device), host, port, folder, not args.no_browser)


def _animate(args: argparse.Namespace) -> int:
    """animate: keyframed scene -> frames (and a video): app/animation.py renders them."""
    from pyjulia4d.app.animation import animate, check_pattern, closing_line
    from pyjulia4d.scene import keyframes
    from pyjulia4d.scene.keyframes import parse_frames

    overrides = _size_overrides(args)
    anim = keyframes.load(args.scene, overrides)
    frames = parse_frames(args.frames, anim.frames)
    pattern = args.output if args.output is not None else Path(args.scene).stem + "_####.png"
    check_pattern(pattern)
    outputs = _outputs(args.channels, Path(pattern.replace("#", "0")))
    from pyjulia4d.app.cluster import check_workers

    workers = None if args.workers is None else check_workers(args.workers)
    summary = animate(anim, pattern, frames, video=args.video, workers=workers, scheduler=args.scheduler,
                      device=args.device, force=args.force, outputs=outputs, progress=True)
    print(closing_line(summary, pattern, args.video, anim.fps))
    return 0


def _import_pov(args: argparse.Namespace) -> int:
    """import-pov: FILE.pov -> SCENE.toml (pyjulia4d/interop/povray/); warnings only on success."""
    from pyjulia4d.interop.povray import check_toml_path, import_pov, write_toml

    size = []
    for key, value in (("image.width", args.width), ("image.height", args.height)):
        if value is not None:
            value = _whole(value)
            Scene.from_dict({"image": {key.partition(".")[2]: value}})  # render's range errors
        size.append(value)
    imported = import_pov(args.pov, *size)
    out = check_toml_path(args.output if args.output is not None else Path(args.pov).stem + ".toml", args.pov)
    write_toml(out, imported.toml)
    for w in imported.warnings:
        _say(f"pyjulia4d: warning: {one_line(Warning(w))}")
    s = imported.scene
    print(f"wrote {out}: {s.fractal.algebra} {s.fractal.function}, c = {list(s.fractal.c)}, "
          f"max_iter {s.fractal.max_iter}, {s.image.width}x{s.image.height} "
          f"(render: {PROG} render {out})")
    return 0


# --channels: EXR channel groups and the render outputs behind them (render.RenderResult)
CHANNEL_GROUPS = {"RGBA": ("color", "alpha"), "Z": ("depth", "bracket"), "N": ("normal",),
                  "P": ("position",)}


def _outputs(channels: str | None, out: Path) -> tuple[str, ...] | None:
    """The render outputs behind --channels (None: all the format holds)."""
    if out.suffix.lower() != ".exr":
        kind = "PNG" if out.suffix.lower() == ".png" else "TIFF"
        if channels is not None and channels.strip().upper() != "RGBA":
            raise SceneError("--channels", f"{channels!r}: a {kind} holds RGBA only; write .exr for Z, N or P")
        return CHANNEL_GROUPS["RGBA"]
    if channels is None:
        return None
    groups = [g.strip().upper() for g in channels.split(",")]
    if not all(groups):
        raise SceneError("--channels", f"{channels!r}: empty name in the list; use names from "
                                       f"{', '.join(CHANNEL_GROUPS)}")
    for g in groups:
        if g not in CHANNEL_GROUPS:
            raise SceneError("--channels", f"unknown channel group {g!r}; use names from "
                                           f"{', '.join(CHANNEL_GROUPS)}")
    return tuple(o for g in groups for o in CHANNEL_GROUPS[g])


def _say(line: str) -> None:
    """One line on stderr, whatever its encoding, even with the terminal gone."""
    try:
        try:
            print(line, file=sys.stderr)
        except UnicodeEncodeError:  # e.g. an argument's undecodable bytes on an ASCII stderr
            print(line.encode("ascii", "backslashreplace").decode("ascii"), file=sys.stderr)
    except OSError:  # the terminal is gone (SIGHUP): nothing left to tell
        pass


def _warn_one_line(message, category, filename, lineno, file=None, line=None) -> None:
    _say(f"pyjulia4d: warning: {one_line(Warning(message))}")


_SIGNALS = tuple(getattr(signal, s) for s in ("SIGTERM", "SIGHUP") if hasattr(signal, s))


def _raise_terminated(signum: int, frame: Any) -> None:
    # a second SIGTERM/SIGHUP during the clean-up the first one starts would cut it short
    for s in _SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    # raised again at the next progress update, should this one land in a finaliser
    request_stop(Terminated(signum))
    raise Terminated(signum)


@contextlib.contextmanager
def _signals_raise() -> Iterator[None]:
    """SIGTERM and SIGHUP raise Terminated inside the block.  Only where their action
    is the default one (``nohup`` sets SIGHUP to ignore: that stays), and only in the
    main thread (the only one that can set handlers)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = {s: signal.getsignal(s) for s in _SIGNALS}
    for s, h in old.items():
        if h == signal.SIG_DFL:
            signal.signal(s, _raise_terminated)
    try:
        yield
    finally:
        clear_stop()
        for s, h in old.items():
            signal.signal(s, h if h is not None else signal.SIG_DFL)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit status (2 on bad input, 130 on Ctrl-C, 128 + the
    signal number on SIGTERM or SIGHUP)."""
    try:
        args = _parser().parse_args(argv)
    except UsageError as e:
        _say(f"pyjulia4d: error: {one_line(e)} (see --help)")
        return 2
    shown = warnings.showwarning
    warnings.showwarning = _warn_one_line  # workload and precision warnings: one line each
    try:
        with _signals_raise():
            if args.command == "devices":
                from pyjulia4d.opencl.listing import describe_devices

                print(describe_devices())
                return 0
            if args.command == "keys":
                from pyjulia4d.scene.keys import describe_keys
                from pyjulia4d.scene.model import SECTION_NAMES

                if args.section is not None and args.section not in SECTION_NAMES:
                    raise SceneError(show_key(args.section), f"unknown section; use one of "
                                                              f"{', '.join(SECTION_NAMES)}")
                print(describe_keys(args.section))
                return 0
            if args.command == "import-pov":
                return _import_pov(args)
            if args.command == "animate":
                return _animate(args)
            if args.command == "explore":
                return _explore(args)
            if args.command == "mesh":
                return _mesh(args)
            return _render(args)
    except ValueError as e:  # SceneError, OutputError, DeviceError and render's own
        _say(f"pyjulia4d: error: {one_line(e)}")
        return 2
    except Exception as e:   # an OpenCL error no step named (opencl/failures.py names the render's)
        if type(e).__module__.partition(".")[0] != "pyopencl":
            raise
        _say(f"pyjulia4d: error: OpenCL: {one_line(e)}")
        return 2
    except KeyboardInterrupt:
        _say("pyjulia4d: interrupted")
        return 130
    except Terminated as e:
        _say(f"pyjulia4d: terminated by {signal.Signals(e.signum).name}")
        return 128 + e.signum
    finally:
        warnings.showwarning = shown
