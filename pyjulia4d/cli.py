"""Command line: ``python -m pyjulia4d render|devices``."""
from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any, Sequence

from .output import check_output_path, write_image
from .scene import Scene

PROG = "python -m pyjulia4d"


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog=PROG, description="Ray trace 3D views of 4D quaternion Julia sets.")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    r = sub.add_parser("render", help="render a scene to .png or .exr")
    r.add_argument("scene", nargs="?", metavar="SCENE.toml", help="scene file (default: the built-in scene)")
    r.add_argument("-o", "--output", metavar="OUT", help="OUT.png or OUT.exr (default: <scene stem>.png, or julia.png)")
    # kept as text so bad sizes get the same one-line scene error as --set
    r.add_argument("--width", metavar="W", help="image width in pixels (same as --set image.width=W)")
    r.add_argument("--height", metavar="H", help="image height in pixels (same as --set image.height=H)")
    r.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene value, e.g. --set fractal.c=-0.2,0.8,0,0 (repeatable)")
    r.add_argument("--device", metavar="SPEC", help="OpenCL device: P:D index, cpu, gpu, or part of its name")
    r.add_argument("--force", action="store_true",
                   help="render settings whose estimated work is refused as hopeless (hours)")

    sub.add_parser("devices", help="list the OpenCL devices")
    return ap


def select_device(spec: str | None) -> Any:
    """devices.select_device, imported late: pyopencl is slow to import."""
    from .devices import select_device as select

    return select(spec)


def _render(args: argparse.Namespace) -> int:
    overrides = list(args.overrides)
    if args.width is not None:
        overrides.append(f"image.width={args.width}")
    if args.height is not None:
        overrides.append(f"image.height={args.height}")
    if args.scene is None:
        scene = Scene.default().with_overrides(overrides)
        default_out = "julia.png"
    else:
        scene = Scene.from_toml(args.scene, overrides)
        default_out = Path(args.scene).stem + ".png"
    out = check_output_path(args.output or default_out)
    device = select_device(args.device)

    from .render import render  # heavy (kernel build); only once the input is known good

    result = render(scene, device=device, progress=True, force=args.force)
    header = {
        "pyjulia4d.scene": scene.to_toml(),
        "pyjulia4d.device": result.device_name,
        "pyjulia4d.render_seconds": "%.6f" % result.seconds,
        "pyjulia4d.capped_pixels": str(result.capped),
        "pyjulia4d.guards": " ".join(f"{k}={v}" for k, v in result.guards.items()),
    }
    write_image(out, result, header)
    w, h = scene.image.width, scene.image.height
    # guards that fired and capped rays are part of the result: say so (never hidden)
    fired = [f"{k} {v}" for k, v in result.guards.items() if v]
    extra = f", {result.capped} capped" if result.capped else ""
    extra += f"; guards fired: {', '.join(fired)}" if fired else ""
    print(
        f"rendered {out} ({w}x{h}) in {result.seconds:.2f} s on {result.device_name}, "
        f"{100 * result.hit_fraction:.1f}% of pixels hit{extra}"
    )
    return 0


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).splitlines()) or type(e).__name__


def _warn_one_line(message, category, filename, lineno, file=None, line=None) -> None:
    print(f"pyjulia4d: warning: {_one_line(Warning(message))}", file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit status (2 on bad input, 130 on Ctrl-C)."""
    args = _parser().parse_args(argv)
    warnings.showwarning = _warn_one_line  # workload and precision warnings: one line each
    try:
        if args.command == "devices":
            from .devices import describe_devices

            print(describe_devices())
            return 0
        return _render(args)
    except ValueError as e:  # SceneError, OutputError, DeviceError and render's own
        print(f"pyjulia4d: error: {_one_line(e)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("pyjulia4d: interrupted", file=sys.stderr)
        return 130
