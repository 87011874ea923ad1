"""Starting the explorer: the renderer behind a session, the first pass that frames the scene
and builds its kernels before the page opens, and ``pyjulia4d explore`` itself."""
from __future__ import annotations

import dataclasses
import errno
import os
import sys
import tempfile
import threading
from pathlib import Path
from typing import Any, Callable

from pyjulia4d.app.explore.loop import stages
from pyjulia4d.app.explore.session import Render
from pyjulia4d.files import path_text, shown_path
from pyjulia4d.scene.checks import SceneError, show, show_key
from pyjulia4d.scene.model import Scene

# The explorer's tiles: a stale stage is abandoned at the end of a tile (loop.py), so they
# are smaller than a file render's (pipeline/plan.py TILE = 512).
EXPLORE_TILE = 128
# What a stage keeps: the picture and the facts it shows (loop.facts).
STAGE_OUTPUTS = ("color", "alpha", "bracket", "unresolved")
WARM_PIXELS = 160 * 120


def device_renderer(device: Any) -> Render:
    """session.Render on an OpenCL device (a pyopencl Device, a --device text, or None: the
    default): a stage in small tiles without the time probe; the file render as ``pyjulia4d
    render`` makes it (probed, every output)."""
    from pyjulia4d.opencl.devices import device_of
    from pyjulia4d.opencl.executor import render

    device = device_of(device)

    def run(scene: Scene, hook: Callable[[int, int], None], whole: bool, first_sample: int = 0) -> Any:
        if whole:
            return render(scene, device=device, on_progress=hook)
        # a path-traced stage keeps its normals: the denoiser's guide (loop.shown_color)
        outputs = STAGE_OUTPUTS + (("normal",) if scene.shading.integrator == "path" else ())
        return render(scene, device=device, on_progress=hook, calibrate=False, tile=EXPLORE_TILE,
                      outputs=outputs, first_sample=first_sample)

    return run


def warm(scene: Scene, render: Render) -> Scene:
    """The scene after a small first render: framed (camera.fit resolved, so that each page
    starts from the same camera), its kernels built."""
    _, first = stages(scene, True, WARM_PIXELS)[0]
    result = render(first, lambda done, total: None, False)
    rendered = getattr(result, "scene", None)
    if scene.camera.fit and rendered is not None:
        return dataclasses.replace(scene, camera=rendered.camera)
    return scene


def check_folder(folder: str | os.PathLike) -> Path:
    """--folder (and the notebook Explorer's folder): an existing, writable directory."""
    folder = path_text(folder, lambda got: SceneError("--folder", f"expected {got}"))
    p = Path(folder)
    shown = shown_path(folder)
    if not p.is_dir():
        raise SceneError("--folder", f"{shown}: no such directory")
    try:   # the only exact test of "can a file be made here" is to make one
        with tempfile.TemporaryFile(dir=p):
            pass
    except OSError as e:
        raise SceneError("--folder", f"{shown}: cannot write there: {e.strerror or e}") from None
    return p.resolve()


def check_port(text: str) -> int:
    s = text.strip()
    if not (s.isascii() and s.isdigit() and len(s) <= 5 and int(s) <= 65535):
        raise SceneError("--port", f"expected a port number in [0, 65535] (0: any free one), got {text!r}"[:120])
    return int(s)


def check_host(text: str) -> str:
    """--host: a host name or an IP address (an IPv6 one bare or in brackets).  An empty one is
    refused: the socket would listen on every interface, where the default is this machine."""
    inner = text[1:-1] if text.startswith("[") and text.endswith("]") else text
    if (not inner or len(text) > 255 or not text.isprintable() or any(c.isspace() or c in "[]/" for c in inner)):
        raise SceneError("--host", f"expected a host name or an IP address such as 127.0.0.1 (0.0.0.0: every "
                                   f"interface), got {show(text)}")
    return text


def explore(scene: Scene, device: Any, host: str, port: int, folder: Path, open_browser: bool) -> int:
    """Frame and build, bind, say where it listens, open the browser, serve until Ctrl-C."""
    from pyjulia4d.app.explore.server import LOCAL_HOSTS, bind, make_app, serve, url_of

    render = device_renderer(device)
    scene = warm(scene, render)
    try:
        sock = bind(host, port)
    except OSError as e:
        if e.errno in (errno.EADDRINUSE, errno.EACCES):
            raise SceneError("--port", f"cannot listen on {show_key(host)} port {port}: {e.strerror or e}"
                             + ("; --port 0 picks a free one" if port else "")) from None
        raise SceneError("--host", f"cannot listen on {show_key(host)}: {e.strerror or e}") from None
    url = url_of(sock)
    hosts = tuple(dict.fromkeys(LOCAL_HOSTS + (host.strip("[]"), host)))
    app = make_app(scene, render, folder, hosts if host not in ("0.0.0.0", "::") else ("*",))

    # no display (a server, a container, CI): no browser is started; a console one would take
    # over the terminal the server prints to
    headless = sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    opening = open_browser and not headless

    def started() -> None:
        note = "" if opening or not open_browser else "; no display here: open the address in a browser"
        print(f"pyjulia4d explore: listening on {url} (files are saved in {folder}; Ctrl-C stops){note}", flush=True)
        if opening:
            import webbrowser

            threading.Thread(target=webbrowser.open, args=(url,), daemon=True).start()

    try:
        serve(app, sock, started)
    finally:
        sock.close()
    sys.stdout.flush()
    return 0
