"""The explorer without a browser: its controls against the scene keys, the render loop's rules
(the latest request wins, previews while moving, refinement at rest), the session's requests and
files, and the server's page, files and socket (Starlette's test client).

Most tests render with a stand-in that takes a known time and paints the scene's c[1] into the
picture, so that the loop's timing rules are tested exactly; the ones marked "device" render
with OpenCL (small images)."""
import dataclasses
import io
import json
import random
import threading
import time

import numpy as np
import pytest
from PIL import Image

from pyjulia4d.app.explore import controls, loop as loop_mod
from pyjulia4d.app.explore.loop import RenderLoop, stages
from pyjulia4d.app.explore.session import ExploreError, Session, animation_toml, file_in
from pyjulia4d.pipeline.result import RenderResult
from pyjulia4d.scene import keyframes
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.ranges import CHECKS

SMALL = Scene.default().replace(**{"image.width": 96, "image.height": 72})


def fake_result(scene, value=None):
    """A RenderResult whose picture is flat grey at c[1] (clipped), every pixel a hit."""
    h, w = scene.image.height, scene.image.width
    v = scene.fractal.c[1] if value is None else value
    color = np.full((h, w, 3), min(1.0, max(0.0, v)), np.float32)
    return RenderResult(color=color, alpha=np.ones((h, w), np.float32), depth=None, normal=None, position=None,
                        status=None, samples=None, bracket=np.zeros((h, w), np.float32),
                        unresolved=np.zeros((h, w), np.float32), counts={"hit": h * w, "miss": 0, "capped": 0},
                        device_name="stand-in", seconds=0.0, scene=scene)


class SlowRender:
    """A stand-in renderer: ``seconds_per_pixel``, in ``tiles`` calls of the hook."""

    def __init__(self, seconds_per_pixel=2e-6, tiles=8):
        self.spp, self.tiles = seconds_per_pixel, tiles
        self.calls = []

    def __call__(self, scene, hook, whole=False):
        self.calls.append(scene)
        n = scene.image.width * scene.image.height
        for k in range(self.tiles):
            time.sleep(self.spp * n / self.tiles)
            hook((k + 1) * n // self.tiles, n)
        return fake_result(scene)


class Collect:
    def __init__(self):
        self.messages, self.pictures = [], []
        self.cond = threading.Condition()

    def emit(self, message, data):
        with self.cond:
            self.messages.append(message)
            if data is not None:
                self.pictures.append((message, data))
            self.cond.notify_all()

    def wait(self, pred, timeout=10.0):
        end = time.time() + timeout
        with self.cond:
            while not pred():
                left = end - time.time()
                assert left > 0, f"timed out; messages: {[m.get('type') for m in self.messages][-20:]}"
                self.cond.wait(left)

    def of(self, kind):
        return [m for m in self.messages if m.get("type") == kind]


# ---------------------------------------------------------------- controls


def test_every_control_is_a_scene_key_and_its_names_are_in_the_form():
    html = controls.form_html(Scene.default())
    for key, c in controls.CONTROLS.items():
        section, name = key.split(".")
        assert name in CHECKS[section]
        for n in c.names():
            assert f'name="{n}"' in html
    # the list: c, max_iter, algebra, function, exponent, kind, slice, quality, shading
    for key in ("fractal.c", "fractal.max_iter", "fractal.algebra", "fractal.function", "fractal.exponent",
                "fractal.kind", "slice.normal", "slice.distance", "march.quality", "shading.color"):
        assert key in controls.CONTROLS


@pytest.mark.parametrize("scene", [Scene.default(), SMALL.replace(**{"fractal.algebra": "hypercomplex",
                                                                      "fractal.function": "pwr",
                                                                      "fractal.exponent": [2.5, 0.5]})])
def test_form_values_read_back_to_the_same_scene(scene):
    assert controls.apply_values(scene, controls.form_values(scene)) == scene


def test_a_component_sets_one_element():
    s = controls.apply_values(SMALL, {"fractal.c[2]": "0.125"})
    assert s.fractal.c == (-0.2, 0.8, 0.125, 0.0)


def test_a_camera_set_by_hand_is_not_framed_again():
    framed = Scene.from_dict({"image": {"width": 32, "height": 24}})
    assert framed.camera.fit
    s = controls.apply_values(framed, {"camera.position[0]": "3"})
    assert not s.camera.fit and s.camera.position[0] == 3.0


@pytest.mark.parametrize("values,names", [
    ({"fractal.c[0]": "5000"}, "fractal.c[0]: must be in [-1e3, 1e3]"),
    ({"fractal.c[0]": "nan"}, "fractal.c[0]: not a finite number"),
    ({"fractal.max_iter": "0"}, "fractal.max_iter: must be in"),
    ({"fractal.max_iter": "twelve"}, "fractal.max_iter: expected an integer"),
    ({"fractal.c[4]": "1"}, "fractal.c[4]: no such control"),
    ({"fractal.c": "1"}, "fractal.c: no such control"),
    ({"fractal.bailout": "3"}, "fractal.bailout: no such control"),
    ({"fractal.algebra": "octonion"}, "fractal.algebra: expected one of"),
    ({"fractal.function": "sin"}, "fractal.function"),
    ({"fractal.c[0]": 1.0}, "fractal.c[0]: expected the field's text"),
    ({"fractal.c[0]": "1" * 101}, "longer than 100 characters"),
    ("fractal.c[0]=1", "values: expected an object"),
])
def test_bad_values_are_one_line_naming_the_control(values, names):
    with pytest.raises(SceneError) as e:
        controls.apply_values(SMALL, values)
    assert names in str(e.value) and "\n" not in str(e.value)


def test_thousands_of_generated_values_are_a_scene_or_one_scene_error():
    rng = random.Random(7)
    names = [n for c in controls.CONTROLS.values() for n in c.names()] + ["fractal.c[7]", "x", "", "a.b[1]"]
    texts = ["", " ", "nan", "inf", "-inf", "1e400", "-0", "0x10", "1_000", "true", "[1,2]", "\u0661", "1e-400",
             "sqr", "quaternion", "auto", "9" * 99, "-1e3", "1e3", "0.5", "2147483648", "\x00", "🌀"]
    for _ in range(3000):
        values = {rng.choice(names): rng.choice(texts + [str(rng.uniform(-5, 5))]) for _ in range(rng.randint(1, 3))}
        try:
            s = controls.apply_values(SMALL, values)
        except SceneError as e:
            assert "\n" not in str(e)
        else:
            assert isinstance(s, Scene)


# ---------------------------------------------------------------- the loop


def test_stages_at_rest_end_with_the_scene_itself():
    scene = Scene.default().replace(**{"image.samples": 4})
    plan = stages(scene, False, 160 * 120)
    assert [s for s, _ in plan] == ["preview", "refine", "refine", "final"]
    assert plan[-1][1] is scene
    sizes = [x.image.width * x.image.height for _, x in plan]
    assert sizes == sorted(sizes) and sizes[0] <= 1.2 * 160 * 120
    assert all(x.image.samples == 1 for _, x in plan[:-1])


def test_stages_while_moving_are_one_preview_of_the_same_aspect():
    plan = stages(Scene.default(), True, 100 * 100)
    assert len(plan) == 1 and plan[0][0] == "preview"
    s = plan[0][1]
    assert abs(s.image.width / s.image.height - 640 / 480) < 0.05


def test_a_small_scene_has_no_preview_at_rest_and_one_while_moving():
    assert [s for s, _ in stages(SMALL, False, 1e5)] == ["final"]
    moving = stages(SMALL, True, 1e5)
    assert [s for s, _ in moving] == ["preview"] and moving[0][1].image.width == SMALL.image.width


def test_the_latest_request_wins():
    got = Collect()
    render = SlowRender(seconds_per_pixel=5e-6)
    lp = RenderLoop(render, lambda p: got.emit({"type": "frame", "stage": p.stage, "g": p.generation}, p.png),
                    lambda m: got.emit({"type": "error", "message": m}, None))
    try:
        for k in range(20):   # 20 requests at rest in quick succession
            lp.request(Scene.default().replace(**{"fractal.c": [-0.2, 0.01 * k, 0, 0]}), moving=False)
        got.wait(lambda: any(m.get("stage") == "final" for m in got.of("frame")))
        time.sleep(0.2)
        frames = got.of("frame")
        # only the last request reached its full size; at most a couple of earlier ones showed a stage
        assert [m["g"] for m in frames if m["stage"] == "final"] == [20]
        assert len({m["g"] for m in frames}) <= 3
        assert len(render.calls) < 20
    finally:
        lp.close()


def test_previews_while_moving_are_finished_not_cancelled():
    got = Collect()
    lp = RenderLoop(SlowRender(seconds_per_pixel=2e-5), lambda p: got.emit({"type": "frame", "stage": p.stage}, p.png),
                    lambda m: got.emit({"type": "error", "message": m}, None), preview_seconds=0.05)
    try:
        t0 = time.time()
        while time.time() - t0 < 1.0:   # a drag: a request every 10 ms, faster than previews render
            lp.request(Scene.default().replace(**{"fractal.c": [-0.2, 0.5 + 0.1 * (time.time() - t0), 0, 0]}),
                       moving=True)
            time.sleep(0.01)
        n = len(got.of("frame"))
        assert n >= 5, f"{n} previews in a second of dragging"
        assert {m["stage"] for m in got.of("frame")} == {"preview"}
    finally:
        lp.close()


def test_a_render_error_is_one_line_and_the_loop_goes_on():
    got = Collect()
    calls = []

    def render(scene, hook):
        calls.append(scene)
        if len(calls) == 1:
            raise RuntimeError("device lost\nsecond line")
        return fake_result(scene)

    lp = RenderLoop(render, lambda p: got.emit({"type": "frame", "stage": p.stage}, p.png),
                    lambda m: got.emit({"type": "error", "message": m}, None))
    try:
        lp.request(SMALL)
        got.wait(lambda: got.of("error"))
        assert got.of("error")[0]["message"] == "render failed: RuntimeError: device lost second line"
        lp.request(SMALL)
        got.wait(lambda: got.of("frame"))
    finally:
        lp.close()


def test_the_picture_is_the_srgb_encoding_of_the_colour():
    color = np.zeros((2, 3, 3), np.float32)
    color[0, 0] = (1.0, 0.5, 0.0)
    color[1, 2] = (0.0031308, 0.2140, 2.0)
    rgb = np.asarray(Image.open(io.BytesIO(loop_mod.picture_png(color))))
    assert rgb.shape == (2, 3, 3)
    assert tuple(rgb[0, 0]) == (255, 188, 0)   # sRGB(0.5) = 0.7354
    def srgb(x):   # IEC 61966-2-1
        return 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055
    assert tuple(rgb[1, 2]) == (round(255 * srgb(0.0031308)), round(255 * srgb(0.2140)), 255)


# ---------------------------------------------------------------- the session


def make_session(tmp_path, render=None, scene=SMALL):
    got = Collect()
    s = Session(scene, render or SlowRender(1e-7), tmp_path, got.emit)
    return s, got


def test_session_start_sends_the_form_and_a_picture(tmp_path):
    s, got = make_session(tmp_path)
    try:
        s.start()
        got.wait(lambda: got.pictures)
        assert got.messages[0]["type"] == "values"
        assert got.messages[0]["values"] == controls.form_values(SMALL)
    finally:
        s.close()


@pytest.mark.parametrize("request_, says", [
    (None, "request: expected an object"),
    ([1, 2], "request: expected an object"),
    ({"op": "fly"}, "op: unknown request 'fly'"),
    ({"op": "set", "values": {"fractal.c[0]": "9e9"}}, "fractal.c[0]: must be in"),
    ({"op": "set", "values": {}, "moving": "yes"}, "moving: expected true or false"),
    ({"op": "orbit", "yaw": "10"}, "yaw: expected a number"),
    ({"op": "orbit", "yaw": float("nan")}, "yaw: expected a number"),
    ({"op": "turn_w"}, "degrees: expected a number"),
    ({"op": "zoom", "factor": 1e9}, "factor: expected a number in"),
    ({"op": "save_scene", "name": "../escape.toml"}, "expected a plain file name"),
    ({"op": "save_scene", "name": "/tmp/escape.toml"}, "expected a plain file name"),
    ({"op": "save_scene", "name": ".hidden.toml"}, "expected a plain file name"),
    ({"op": "save_scene", "name": "scene.png"}, "expected a name ending in .toml"),
    ({"op": "save_scene", "name": 5}, "name: expected a file name"),
    ({"op": "render_file", "name": "x.jpg"}, "expected a name ending in .png or .exr"),
    ({"op": "render_file", "name": "a\\b.png"}, "expected a plain file name"),
    ({"op": "keyframe", "frames": 0}, "frames: expected a number in [1, 100000]"),
    ({"op": "save_animation", "name": "a.toml"}, "add at least two keyframes"),
    ({"op": "save_animation", "name": "a.toml", "interpolation": "cubic"}, "interpolation: expected one of"),
])
def test_bad_requests_are_one_line_and_write_nothing(tmp_path, request_, says):
    s, got = make_session(tmp_path)
    try:
        before = s.scene
        s.handle(request_)
        errors = got.of("error")
        assert len(errors) == 1 and says in errors[0]["message"] and "\n" not in errors[0]["message"]
        assert s.scene == before
        assert list(tmp_path.iterdir()) == []
    finally:
        s.close()


def test_generated_junk_requests_never_raise(tmp_path):
    rng = random.Random(3)
    s, got = make_session(tmp_path)
    junk = [None, True, 0, -1, 1e308, float("inf"), "", "x", [], {}, [1], {"a": 1}, "../../x", "\x00"]
    ops = ["set", "orbit", "turn_w", "zoom", "refine", "save_scene", "render_file", "keyframe", "clear_keyframes",
           "save_animation", "focus", "frame", "nope", None, 3]
    try:
        for _ in range(1500):
            msg = {"op": rng.choice(ops)}
            for k in rng.sample(["values", "moving", "yaw", "pitch", "degrees", "factor", "name", "frames", "fps",
                                 "interpolation", "x", "y"], rng.randint(0, 3)):
                msg[k] = rng.choice(junk)
            s.handle(msg)
        for m in got.of("error"):
            assert "\n" not in m["message"]
        written = [p.name for p in tmp_path.iterdir()]
        assert all(not n.startswith(".") for n in written), written   # no temporary file left
    finally:
        s.close()


def test_save_scene_reads_back_as_the_scene(tmp_path):
    s, got = make_session(tmp_path)
    try:
        s.handle({"op": "set", "values": {"fractal.c[1]": "0.61", "slice.distance": "0.1"}})
        s.handle({"op": "orbit", "yaw": 20, "pitch": 10})
        s.handle({"op": "save_scene", "name": "mine.toml"})
        assert got.of("status")[-1]["message"].startswith("saved ")
        assert Scene.from_toml(tmp_path / "mine.toml") == s.scene
        assert s.scene.fractal.c[1] == 0.61 and not s.scene.camera.fit
    finally:
        s.close()


def test_keyframes_save_an_animation_animate_reads(tmp_path):
    s, got = make_session(tmp_path)
    try:
        s.handle({"op": "keyframe"})
        s.handle({"op": "set", "values": {"fractal.c[1]": "0.6", "fractal.algebra": "cquat"}})
        s.handle({"op": "orbit", "yaw": 30})
        s.handle({"op": "keyframe", "frames": 24})
        s.handle({"op": "turn_w", "degrees": 15})
        s.handle({"op": "keyframe", "frames": 12})
        s.handle({"op": "save_animation", "name": "anim.toml", "fps": 12})
        assert not got.of("error"), got.of("error")
        assert "kept the first keyframe's fractal.algebra" in got.of("status")[-1]["message"]
        anim = keyframes.load(tmp_path / "anim.toml")
        assert anim.frames == 37 and anim.fps == 12.0
        first, mid, last = anim.scene(0), anim.scene(24), anim.scene(36)
        assert first.fractal.c[1] == pytest.approx(0.8) and mid.fractal.c[1] == pytest.approx(0.6)
        assert np.allclose(last.camera.position, s.scene.camera.position, atol=1e-9)
        assert first.fractal.algebra == "quaternion"
    finally:
        s.close()


def test_animation_toml_keys_only_what_changes():
    a = SMALL
    b = SMALL.replace(**{"fractal.c": [-0.2, 0.7, 0, 0]})
    text, kept = animation_toml([(0, a), (10, b)], 24.0, "linear")
    body = text.split("[animation]")[1]
    assert "fractal.c = " in body and "camera.position" not in body and kept == []


@pytest.mark.parametrize("name", ["a.png", "b.TOML", "x y.exr", "ü.png"])
def test_plain_names_are_taken(tmp_path, name):
    assert file_in(tmp_path, name, (".png", ".exr", ".toml")).parent == tmp_path


def test_a_framed_start_keeps_the_framed_camera(tmp_path):
    """camera.fit: the first picture's framing becomes the session's camera (and the form's)."""
    framed = Scene.from_dict({"image": {"width": 32, "height": 24}})
    placed = framed.camera.position

    def render(scene, hook, whole=False):
        out = fake_result(scene)
        if scene.camera.fit:   # as the framing pass does: a placed camera, fit false
            out.scene = dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, position=(0.0, 0.0, -5.0, 0.0),
                                                                                fit=False))
        return out

    s, got = make_session(tmp_path, render, framed)
    try:
        s.start()
        got.wait(lambda: any(m.get("stage") == "final" for m in got.of("frame")))
        assert s.scene.camera.position == (0.0, 0.0, -5.0, 0.0) != placed and not s.scene.camera.fit
        assert got.of("values")[-1]["values"]["camera.position[2]"] == "-5.0"
    finally:
        s.close()


# ---------------------------------------------------------------- the server


@pytest.fixture
def client(tmp_path):
    from starlette.testclient import TestClient

    from pyjulia4d.app.explore.server import make_app

    app = make_app(SMALL, SlowRender(1e-7), tmp_path)
    with TestClient(app, base_url="http://127.0.0.1:8470") as c:
        yield c


def receive_until(ws, kind, limit=50):
    """Messages up to the first of ``kind`` (a picture's bytes follow its frame message)."""
    seen = []
    for _ in range(limit):
        m = json.loads(ws.receive_text())
        seen.append(m)
        if m["type"] == "frame":
            seen.append(ws.receive_bytes())
        if m["type"] == kind:
            return seen
    raise AssertionError(f"no {kind} in {seen}")


def test_the_page_has_every_control_and_the_view(client):
    r = client.get("/")
    assert r.status_code == 200 and 'id="view"' in r.text
    for c in controls.CONTROLS.values():
        for n in c.names():
            assert f'name="{n}"' in r.text
    assert '"hypercomplex": ["sqr", "cube", "exp"' in r.text
    assert client.get("/static/explore.js").status_code == 200
    assert client.get("/static/explore.css").status_code == 200


@pytest.mark.parametrize("path", ["/static/../session.py", "/static/%2e%2e/session.py", "/../setup.cfg",
                                  "/static/", "/etc/passwd", "/static/page/../../run.py", "/ws/x"])
def test_paths_outside_the_page_are_not_found(client, path):
    assert client.get(path).status_code == 404


def test_another_host_name_is_refused(client):
    assert client.get("/", headers={"host": "evil.example"}).status_code == 400


def test_a_socket_from_another_site_is_refused(client):
    from starlette.websockets import WebSocketDisconnect

    with pytest.raises(WebSocketDisconnect):
        with client.websocket_connect("ws://127.0.0.1:8470/ws", headers={"origin": "http://evil.example"}) as ws:
            ws.receive_text()


def test_the_socket_answers_bad_messages_in_one_line_and_stays_open(client, tmp_path):
    with client.websocket_connect("ws://127.0.0.1:8470/ws", headers={"origin": "http://127.0.0.1:8470"}) as ws:
        receive_until(ws, "frame")
        for bad, says in [("{", "request: not JSON"), ("[" * 100000, "request: 100000 characters"),
                          ('{"op": "set", "values": {"fractal.c[0]": "1e9"}}', "fractal.c[0]: must be in")]:
            ws.send_text(bad)
            m = receive_until(ws, "error")[-1]
            assert says in m["message"] and "\n" not in m["message"]
        ws.send_bytes(b"\x00\x01")
        assert "binary message" in receive_until(ws, "error")[-1]["message"]
        ws.send_text(json.dumps({"op": "set", "values": {"fractal.c[1]": "0.25"}}))
        png = receive_until(ws, "frame")[-1]
        assert Image.open(io.BytesIO(png)).getpixel((0, 0))[0] == round(255 * (1.055 * 0.25 ** (1 / 2.4) - 0.055))
        ws.send_text(json.dumps({"op": "save_scene", "name": "from-page.toml"}))
        receive_until(ws, "status")
    assert Scene.from_toml(tmp_path / "from-page.toml").fractal.c[1] == 0.25


# ---------------------------------------------------------------- on the OpenCL device


def test_the_picture_at_rest_is_the_command_lines_render_of_the_saved_scene(tmp_path):
    """The session's last stage renders the scene as saved: `pyjulia4d render` of the saved file
    gives the same pixels on the same device, and so does the page's own render to a file."""
    import os
    import subprocess
    import sys

    import harness
    from pyjulia4d.app.explore.run import device_renderer, warm

    render = device_renderer(harness.device())
    scene = warm(Scene.from_dict({"image": {"width": 120, "height": 90}}), render)
    assert not scene.camera.fit
    s, got = make_session(tmp_path, render, scene)
    try:
        s.start()
        s.handle({"op": "set", "values": {"fractal.c[1]": "0.7", "shading.ao": "0.3"}})
        s.handle({"op": "orbit", "yaw": 25, "pitch": -10})
        g = s.loop.generation
        got.wait(lambda: any(m["stage"] == "final" and m["generation"] == g for m, _ in got.pictures), 60)
        final = next(png for m, png in got.pictures if m["stage"] == "final" and m["generation"] == g)
        s.handle({"op": "save_scene", "name": "rest.toml"})
        s.handle({"op": "render_file", "name": "page.png"})
        got.wait(lambda: any(m["message"].startswith("rendered") for m in got.of("status")), 60)
        assert not got.of("error"), got.of("error")
    finally:
        s.close()
    device = ["--device", os.environ["PYJULIA4D_DEVICE"]] if os.environ.get("PYJULIA4D_DEVICE") else []
    subprocess.run([sys.executable, "-m", "pyjulia4d", "render", str(tmp_path / "rest.toml"), "-o",
                    str(tmp_path / "cli.png"), *device], check=True, capture_output=True, timeout=120)
    page = np.asarray(Image.open(io.BytesIO(final)))
    for name in ("cli.png", "page.png"):
        rgba = np.asarray(Image.open(tmp_path / name))
        assert rgba.shape == (90, 120, 4)
        assert np.array_equal(rgba[..., :3], page), name
    assert 0.05 < np.mean(np.any(page > 0, axis=2)) < 0.95   # a picture of the set, not of nothing


def test_the_notebook_view_renders_as_its_sliders_move(tmp_path):
    pytest.importorskip("ipywidgets", reason="the notebook view needs ipywidgets (pip install '.[notebook]')")
    import harness
    from pyjulia4d.app.explore.notebook import Explorer

    ex = Explorer(Scene.from_dict({"image": {"width": 80, "height": 60}}), device=harness.device(), folder=tmp_path)
    try:
        end = time.time() + 60
        while not ex.image.value and time.time() < end:
            time.sleep(0.02)
        first = bytes(ex.image.value)
        assert first and "80x60" in ex.facts.value
        ex.widgets["fractal.c[1]"].value = 0.3
        while bytes(ex.image.value) == first and time.time() < end:
            time.sleep(0.02)
        assert bytes(ex.image.value) != first
        ex.widgets["fractal.algebra"].value = "hypercomplex"   # the function list follows the algebra
        assert "atanh" in ex.widgets["fractal.function"].options
        ex.widgets["image.width"].value = 0   # below the key's range: one line, nothing breaks
        assert "image.width: must be in" in ex.message.value
    finally:
        ex.close()


# ---------------------------------------------------------------- the command line


@pytest.mark.parametrize("args,says", [
    (["--port", "abc"], "--port: expected a port number in [0, 65535]"),
    (["--port", "65536"], "--port: expected a port number"),
    (["--port", "-1"], "--port: expected a port number"),
    (["--folder", "/nonexistent/x"], "--folder: /nonexistent/x: no such directory"),
    (["--set", "fractal.max_iter=0"], "fractal.max_iter: must be in"),
    (["missing.toml"], "missing.toml: cannot read"),
    (["--host", "no-such-host.invalid", "--port", "0"], "--host: cannot listen on no-such-host.invalid"),
    (["--bogus"], "unrecognized arguments: --bogus"),
    # an empty host would listen on every interface, where the default is this machine only
    # (each host is checked before the port: with a bad port, a regression stops, never serves)
    (["--host", "", "--port", "x"], "--host: expected a host name or an IP address such as 127.0.0.1"),
    (["--host", "[::1", "--port", "x"], "every interface), got '[::1'"),
    (["--host", "a\x01b", "--port", "x"], "got 'a\\x01b'"),
    (["--host", "a" * 300, "--port", "x"], "got 'aaaa"),
])
def test_bad_explore_arguments_are_one_line_and_status_2(tmp_path, capsys, monkeypatch, args, says):
    from pyjulia4d.app.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["explore", "--no-browser", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pyjulia4d: error: ") and says in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_a_port_in_use_is_one_line(tmp_path, capsys, monkeypatch):
    import socket

    from pyjulia4d.app.cli import main

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        monkeypatch.chdir(tmp_path)
        assert main(["explore", "--no-browser", "--port", str(port), "--set", "image.width=32",
                     "--set", "image.height=24"]) == 2
    err = capsys.readouterr().err
    assert f"--port: cannot listen on 127.0.0.1 port {port}: Address already in use; --port 0 picks a free one" in err
    assert list(tmp_path.iterdir()) == []


def test_generated_socket_messages_get_at_most_one_line_each_and_the_socket_stays(client):
    """Random JSON values, truncated JSON and junk text on the socket: each is answered by at
    most one error line (or carried out), and a valid request after them still renders."""
    rng = random.Random(11)
    leaves = [None, True, 1, -1.5, 1e308, "", "x" * 50, "fractal.c[0]", "../../etc/passwd", "set", "orbit"]

    def value(depth=0):
        r = rng.random()
        if depth < 3 and r < 0.2:
            return [value(depth + 1) for _ in range(rng.randint(0, 3))]
        if depth < 3 and r < 0.45:
            keys = ["op", "values", "moving", "yaw", "degrees", "factor", "name", "frames", "fps", "x"]
            return {rng.choice(keys): value(depth + 1) for _ in range(rng.randint(0, 4))}
        return rng.choice(leaves)

    with client.websocket_connect("ws://127.0.0.1:8470/ws", headers={"origin": "http://127.0.0.1:8470"}) as ws:
        receive_until(ws, "frame")
        for k in range(300):
            msg = value()
            if isinstance(msg, dict) and rng.random() < 0.5:
                msg["op"] = rng.choice(["set", "orbit", "turn_w", "zoom", "keyframe", "save_scene", "render_file"])
            text = json.dumps(msg)
            if rng.random() < 0.15:
                text = text[: rng.randint(0, len(text))] + rng.choice(["", "}", "\x00", "\ufffd"])
            ws.send_text(text)
        ws.send_text(json.dumps({"op": "set", "values": {"fractal.c[1]": "0.5"}}))
        ws.send_text(json.dumps({"op": "save_scene", "name": "after-fuzz.toml"}))
        seen = receive_until(ws, "status", limit=5000)
        errors = [m for m in seen if isinstance(m, dict) and m.get("type") == "error"]
        assert errors and all("\n" not in m["message"] for m in errors)
        assert len(errors) <= 300


def test_frame_places_the_camera_from_the_framing_pass(tmp_path):
    def render(scene, hook, whole=False):
        out = fake_result(scene)
        if scene.camera.fit:
            out.scene = dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, position=(0.0, 0.0, -7.0, 0.0),
                                                                                fit=False))
        return out

    s, got = make_session(tmp_path, render)
    try:
        s.handle({"op": "frame"})
        got.wait(lambda: any(m.get("stage") == "final" for m in got.of("frame")))
        assert s.scene.camera.position == (0.0, 0.0, -7.0, 0.0) and not s.scene.camera.fit
        assert got.of("values")[-1]["values"]["camera.position[2]"] == "-7.0"
    finally:
        s.close()


@pytest.mark.parametrize("device", [5, object(), ["cpu"]])
def test_the_renderer_refuses_what_is_no_device(device):
    from pyjulia4d.app.explore.run import device_renderer

    with pytest.raises(SceneError, match="device: expected None, a pyopencl Device"):
        device_renderer(device)


# ---------------------------------------------------------------- the path tracer in the explorer


def test_path_batches_double_the_total_up_to_the_samples():
    from pyjulia4d.app.explore.loop import path_batches
    assert path_batches(1) == [(0, 1)]
    assert path_batches(2) == [(0, 2)]
    assert path_batches(16) == [(0, 2), (2, 2), (4, 4), (8, 8)]
    assert path_batches(100) == [(0, 2), (2, 2), (4, 4), (8, 8), (16, 16), (32, 32), (64, 36)]
    for s in (1, 5, 37, 256, 1000):
        b = path_batches(s)
        assert sum(c for _, c in b) == s and all(f == sum(c for _, c in b[:k]) for k, (f, _) in enumerate(b))


def test_a_path_scenes_previews_are_direct_and_its_last_stage_the_scene():
    path = Scene.default().replace(**{"shading.integrator": "path", "image.samples": 64})
    moving = stages(path, True, 100 * 100)
    assert [x.shading.integrator for _, x in moving] == ["direct"]
    rest = stages(path, False, 160 * 120)
    assert rest[-1] == ("final", path) and all(x.shading.integrator == "direct" for _, x in rest[:-1])


def test_a_path_traced_picture_refines_at_rest_to_the_render_of_the_scene(tmp_path):
    """On the device: batches of paths shown one after another, their noise falling and their
    paths adding up, the last one's pixels the render of the whole scene (pooled: to float32
    rounding); a click on the picture focuses the lens there."""
    import harness
    from pyjulia4d import render as render_scene
    from pyjulia4d.app.explore.run import device_renderer

    scene = Scene.from_dict({"camera": {"position": [1.8, 1.6, -2.2, 0], "aperture": 0.05},
                             "shading": {"integrator": "path", "bounces": 3},
                             "image": {"width": 48, "height": 36, "samples": 16}})
    shown = []
    orig = loop_mod.picture_png
    loop_mod.picture_png = lambda color, sc=None: (shown.append(np.array(color)), orig(color, sc))[1]
    render = device_renderer(harness.device())
    s, got = make_session(tmp_path, render, scene)
    try:
        s.start()
        got.wait(lambda: any(m["stage"] == "final" for m, _ in got.pictures), 120)
        frames = [m for m, _ in got.pictures if m["generation"] == s.loop.generation]
        paths = [int(m["facts"]["paths"]) for m in frames if "paths" in m["facts"]]
        assert paths == [2, 4, 8, 16]
        noise = [float(m["facts"]["noise"].split()[1].rstrip(",")) for m in frames if "noise" in m["facts"]]
        # from the third batch on: the standard error a batch of 2 or 4 paths states is itself
        # rough (one to three degrees of freedom a channel, over stratified samples: a pixel's
        # first few paths of a Sobol' pair often agree), its p50 often below the truth
        assert noise[-1] < noise[2]
        s.handle({"op": "focus", "x": 0.5, "y": 0.5})
        assert s.scene.camera.focus != "auto" and 0 < s.scene.camera.focus < 10
        assert not got.of("error"), got.of("error")
    finally:
        s.close()
        loop_mod.picture_png = orig
    from pyjulia4d.resources import module_installed
    if not module_installed("pyoidn"):   # the page shows the pooled picture itself
        whole = render_scene(scene)
        assert np.abs(shown[-1] - whole.color).max() < 1e-5


def test_text_controls_take_what_set_takes_and_give_it_back():
    # the lighting and colour keys without a number of their own (a light at "eye" or a 4D point,
    # more lights, colour ramps, a backdrop, the environment): typed as --set takes them, and
    # each shown back as text that gives the same scene
    from pyjulia4d.app.explore.controls import CONTROLS, apply_values, form_values

    typed = {"shading.light": "eye", "shading.lights": "[{position = [3, 1, -2], color = [0.3, 0.5, 1]}]",
             "shading.gradient": "[[0, 0, 0, 0], [1, 1, 0.5, 0]]",
             "shading.background_gradient": "[[0, 0.1, 0.2, 0.4], [1, 0.9, 0.8, 0.7]]", "shading.environment": "uniform"}
    s = apply_values(Scene.default(), typed)
    assert s.shading.light == "eye" and s.shading.lights[0].color == (0.3, 0.5, 1.0)
    assert s.shading.environment == "uniform" and len(s.shading.background_gradient) == 2
    shown = form_values(s)
    texts = {k: shown[k] for k in shown if CONTROLS[k.split("[")[0]].widget == "text"}
    assert set(typed) <= set(texts) and apply_values(Scene.default(), texts) == s
    with pytest.raises(SceneError, match="shading.lights"):
        apply_values(Scene.default(), {"shading.lights": "[{position = [3, 1"})


def test_the_facts_say_what_is_proven_and_how_to_have_it():
    """The panel's depth error: the statement where the march proves the space in front of its
    hits, else that it states none and which quality would (as the command line's closing line)."""
    from pyjulia4d import render

    s = Scene.default().with_overrides(["image.width=24", "image.height=18"])
    estimate = loop_mod.facts(render(s), "final")
    assert estimate["error"].startswith("not stated") and "quality 'normal' proves it" in estimate["error"]
    assert estimate["unresolved"] == "every ray"
    proven = loop_mod.facts(render(s.with_overrides(["march.quality=normal"])), "final")
    assert proven["error"].startswith("p50=") and "not stated" not in proven["error"], proven["error"]
