"""``pyjulia4d explore``: the explorer's local web server (Starlette on uvicorn).

- ``GET /``: the page (page/index.html with the form of controls.py filled in);
  ``/static/``: its script and style, from the package; any other path is 404.
- ``/ws``: a WebSocket per page.  The page sends JSON requests (session.py); the server
  answers with JSON messages, each picture's message followed by its PNG as a binary
  message.  Each connection is a Session of its own, started from the server's scene.
- Requests larger than MAX_MESSAGE bytes, or that are not JSON, get a one-line error and the
  socket stays open; past MAX_FRAME uvicorn closes the socket (the page reconnects).
- It binds to 127.0.0.1 unless told otherwise.  Only pages it served may open the socket (the
  Origin header must name this server), so that no other site the browser visits can
  drive the renderer or write files, and requests naming another host are refused (DNS
  rebinding).
"""
from __future__ import annotations

import asyncio
import json
import socket
from pathlib import Path
from typing import Any, Callable
from urllib.parse import urlsplit

from pyjulia4d.app.explore import controls
from pyjulia4d.app.explore.session import ExploreError, Render, Session
from pyjulia4d.fractal.registry import FUNCTIONS_OF
from pyjulia4d.scene.checks import one_line
from pyjulia4d.scene.model import Scene

MAX_MESSAGE = 64 * 1024      # bytes of one request the session reads
MAX_FRAME = 1024 * 1024      # bytes of one WebSocket frame uvicorn accepts at all
PAGE = Path(__file__).with_name("page")
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1", "[::1]")


def page_html(scene: Scene) -> str:
    """index.html with the controls of ``scene`` and the functions each algebra has."""
    text = (PAGE / "index.html").read_text(encoding="utf-8")
    data = json.dumps({"functions": {k: list(v) for k, v in FUNCTIONS_OF.items()}}).replace("<", "\\u003c")
    return text.replace("<!--FORM-->", controls.form_html(scene)).replace("/*DATA*/null", data)


def allowed_origin(origin: str | None, host: str | None) -> bool:
    """A WebSocket's Origin is this server's own page (or absent: not a browser)."""
    if origin is None:
        return True
    parts = urlsplit(origin)
    return parts.scheme in ("http", "https") and host is not None and parts.netloc == host


def make_app(scene: Scene, render: Render, folder: str | Path, hosts: tuple[str, ...] = LOCAL_HOSTS) -> Any:
    """The Starlette application: the page, its files and the socket, for ``scene``, rendered
    by ``render`` (session.Render), saving into ``folder``; ``hosts``: the Host names served."""
    from starlette.applications import Starlette
    from starlette.middleware import Middleware
    from starlette.middleware.trustedhost import TrustedHostMiddleware
    from starlette.responses import HTMLResponse
    from starlette.routing import Mount, Route, WebSocketRoute
    from starlette.staticfiles import StaticFiles
    from starlette.websockets import WebSocket, WebSocketDisconnect

    html = page_html(scene)

    async def index(request: Any) -> HTMLResponse:
        return HTMLResponse(html, headers={"Cache-Control": "no-store"})

    async def socket_endpoint(ws: WebSocket) -> None:
        if not allowed_origin(ws.headers.get("origin"), ws.headers.get("host")):
            await ws.close(code=1008)
            return
        await ws.accept()
        loop = asyncio.get_running_loop()
        outbox: asyncio.Queue = asyncio.Queue()

        def emit(message: dict, data: bytes | None) -> None:
            try:
                loop.call_soon_threadsafe(outbox.put_nowait, (message, data))
            except RuntimeError:   # the server's event loop is closed: the page is gone
                pass

        async def send_all() -> None:
            while True:
                batch = [await outbox.get()]
                while not outbox.empty():
                    batch.append(outbox.get_nowait())
                # a picture overtaken by a newer one in the same batch is not sent: the page
                # never works through a queue of stale frames
                frames = [i for i, (m, _) in enumerate(batch) if m.get("type") == "frame"]
                for i, (message, data) in enumerate(batch):
                    if message.get("type") == "frame" and i != frames[-1]:
                        continue
                    await ws.send_text(json.dumps(message))
                    if data is not None:
                        await ws.send_bytes(data)

        session = Session(scene, render, folder, emit)
        sender = asyncio.create_task(send_all())
        session.start()
        try:
            while True:
                event = await ws.receive()
                if event["type"] == "websocket.disconnect":
                    break
                try:
                    request = parse_request(event.get("text"), event.get("bytes"))
                except ExploreError as e:
                    emit({"type": "error", "message": one_line(e)}, None)
                    continue
                session.handle(request)
        except WebSocketDisconnect:
            pass
        finally:
            sender.cancel()
            await asyncio.to_thread(session.close)

    return Starlette(
        routes=[Route("/", index), Mount("/static", StaticFiles(directory=PAGE), name="static"),
                WebSocketRoute("/ws", socket_endpoint)],
        middleware=[Middleware(TrustedHostMiddleware, allowed_hosts=list(hosts))])


def parse_request(text: str | None, data: bytes | None) -> Any:
    """The request in a WebSocket message: a JSON value of at most MAX_MESSAGE characters
    (the session checks what it holds).  ExploreError, one line, when it cannot be read."""
    if text is None:
        raise ExploreError(f"request: a binary message of {len(data or b'')} bytes; requests are JSON text")
    if len(text) > MAX_MESSAGE:
        raise ExploreError(f"request: {len(text)} characters; at most {MAX_MESSAGE}")
    try:
        return json.loads(text)
    except RecursionError:
        raise ExploreError("request: not JSON (nested too deeply)") from None
    except ValueError as e:
        raise ExploreError(f"request: not JSON ({' '.join(str(e).split())[:100]})") from None


def bind(host: str, port: int) -> socket.socket:
    """A listening socket on (host, port); port 0 picks a free one.  OSError when it cannot."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((host.strip("[]"), port))
        sock.listen(64)
    except OSError:
        sock.close()
        raise
    return sock


def url_of(sock: socket.socket) -> str:
    host, port = sock.getsockname()[:2]
    return f"http://{'[' + host + ']' if ':' in host else host}:{port}/"


def serve(app: Any, sock: socket.socket, started: Callable[[], None] | None = None) -> None:
    """Run uvicorn on ``sock`` until Ctrl-C or SIGTERM; ``started()`` once it accepts."""
    import uvicorn

    config = uvicorn.Config(app, log_level="warning", ws_max_size=MAX_FRAME, lifespan="off",
                            ws_ping_interval=None)
    server = uvicorn.Server(config)
    if started is not None:
        original = server.startup

        async def startup(sockets: Any = None) -> None:
            await original(sockets=sockets)
            started()

        server.startup = startup   # type: ignore[method-assign]
    server.run(sockets=[sock])
