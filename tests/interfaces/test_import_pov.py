"""``python -m pyjulia4d import-pov``: POV-Ray julia_fractal scenes to pyjulia4d scenes.

No POV-Ray is needed: the camera mapping is held to POV-Ray's projection worked out from
its camera rules (parser.cpp Parse_Camera, 3.5+ order; a pixel's ray is
direction + (x/W - 1/2) right + (1/2 - y/H) up), and the silhouette to an alpha mask
POV-Ray 3.7 rendered once (tests/data/pov/doc_example_alpha.png, see the .pov beside it).
Bad input: exit 2, one stderr line, no file; a fuzz of mutated scenes: 0 or 2, never a
traceback or a partial file.
"""
from __future__ import annotations

import math
import os
import random
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import pyjulia4d
from pyjulia4d.app import cli
from pyjulia4d import reference as ref
from pyjulia4d.geometry.camera import camera_frame, to_world
from pyjulia4d.interop.povray import import_pov, pov_escape_radius, tokenize
from pyjulia4d.scene.model import Scene

DATA = Path(__file__).resolve().parents[1] / "data" / "pov"
PKG_ROOT = str(Path(pyjulia4d.__file__).resolve().parent.parent)

DOC_JULIA = """julia_fractal {
  <-0.083,0.0,-0.83,-0.025>
  quaternion
  sqr
  max_iteration 8
  precision 15
}
"""
CAMERA = "camera { location <1.5, 1, -3.5> look_at <0, 0, 0> angle 45 right x*4/3 }\n"


def _run(argv: list[str], capsys) -> tuple[int, str, str]:
    rc = cli.main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def _import(tmp_path: Path, text: str | bytes, capsys, *extra: str, name: str = "scene.pov"):
    pov = tmp_path / name
    pov.write_bytes(text if isinstance(text, bytes) else text.encode())
    out = tmp_path / "scene.toml"
    rc, stdout, err = _run(["import-pov", str(pov), "-o", str(out), *extra], capsys)
    return rc, out, err


# ------------------------------------------------------------------ conversions

def test_documentation_example_converts_and_renders(tmp_path, capsys, monkeypatch):
    """POV-Ray 3.6 documentation's example as it stands (no camera: POV-Ray's default one at the origin,
    looking along +z), then with a camera; both load and render."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "doc.pov").write_text(DOC_JULIA)
    rc, out, err = _run(["import-pov", "doc.pov"], capsys)
    assert rc == 0 and err == "", err
    assert (tmp_path / "doc.toml").exists()  # default name: <stem>.toml in the current directory
    s = Scene.from_toml(tmp_path / "doc.toml")
    assert s.fractal.c == (-0.083, 0.0, -0.83, -0.025)
    assert (s.fractal.algebra, s.fractal.function) == ("quaternion", "sqr")
    assert s.fractal.max_iter == 7  # POV-Ray's max_iteration 8 tests q_0 .. q_7
    c_norm = math.sqrt(0.083**2 + 0.83**2 + 0.025**2)
    assert s.fractal.bailout == pytest.approx(math.sqrt((1 + c_norm + 1e-7) ** 2 + 1e-7), rel=1e-15)
    assert s.camera.position[:3] == (0.0, 0.0, 0.0) and s.camera.target[:3] == (0.0, 0.0, 1.0)
    # POV-Ray's default camera: right 1.33, direction 1 -> 67.38 degrees horizontal; the
    # vertical angle is 2 atan(1/2)
    assert s.camera.fov == pytest.approx(math.degrees(2 * math.atan(0.5)))
    text = (tmp_path / "doc.toml").read_text()
    assert "precision 15" in text and "is kept" in text  # the march is pyjulia4d's, said so

    (tmp_path / "cam.pov").write_text("#version 3.7;\n" + CAMERA + DOC_JULIA)
    rc, out, err = _run(["import-pov", "cam.pov", "-o", "cam.toml", "--width", "32", "--height", "24"], capsys)
    assert rc == 0 and err == "", err
    rc, out, err = _run(["render", "cam.toml", "-o", "cam.png"], capsys)
    assert rc == 0, err
    alpha = np.asarray(Image.open(tmp_path / "cam.png"))[..., 3]
    assert alpha.shape == (24, 32) and 0.2 < np.mean(alpha > 0) < 0.8


def test_silhouette_matches_povray_render():
    """POV-Ray 3.7's own alpha of the documentation example (64x48, stored) against the
    float64 reference render of the converted scene: measured 99.5 % (the rest is POV-Ray's
    precision 15 fraying the edges; at precision 1000 the two agree on every pixel)."""
    pov = np.asarray(Image.open(DATA / "doc_example_alpha.png")) > 0
    s = import_pov(DATA / "doc_example.pov", 64, 48).scene
    a = ref.render(s).alpha > 0
    assert pov.shape == a.shape == (48, 64)
    agree = np.mean(a == pov)
    assert agree >= 0.98
    assert np.mean(a[:, ::-1] == pov) < agree - 0.05  # not mirrored
    assert np.mean(a[::-1] == pov) < agree - 0.05     # not flipped


def test_hypercomplex_pwr(tmp_path, capsys):
    rc, out, err = _import(tmp_path, "#version 3.7;\n" + CAMERA.replace("-3.5", "-9") +
                           "julia_fractal { <-0.4, 0.5, 0.3, -0.2> hypercomplex pwr(2, 0.5) max_iteration 6 }",
                           capsys, "--width", "16", "--height", "12")
    assert rc == 0, err
    s = Scene.from_toml(out)
    f = s.fractal
    assert (f.algebra, f.function, f.exponent) == ("hypercomplex", "pwr", (2.0, 0.5))
    assert f.max_iter == 5 and f.bailout == 4.0  # hypercomplex: POV-Ray's Exit_Value 16
    assert 0.0 < np.mean(ref.render(s).alpha > 0) < 1.0


def test_reflection_and_more_lights_are_taken(tmp_path, capsys):
    """finish { reflection } becomes shading.reflection, and the light_sources after the
    first become shading.lights, each where POV-Ray puts it, in its colour."""
    rc, out, err = _import(tmp_path, "#version 3.7;\n" + CAMERA +
                           "light_source { <-2, 5, -4> color rgb <1, 1, 1> }\n"
                           "light_source { <3, 1, -2> color rgb <0.3, 0.4, 0.8> }\n"
                           "julia_fractal { <-0.2, 0.8, 0, 0> quaternion sqr max_iteration 8 "
                           "finish { reflection 0.25 } }", capsys, "--width", "16", "--height", "12")
    assert rc == 0, err
    sh = Scene.from_toml(out).shading
    assert sh.reflection == 0.25 and sh.light[:3] == (-2.0, 5.0, -4.0)
    assert len(sh.lights) == 1 and sh.lights[0].position[:3] == (3.0, 1.0, -2.0)
    assert sh.lights[0].color == (0.3, 0.4, 0.8)


def test_slice_and_distance(tmp_path, capsys):
    body = "#version 3.7;\n" + CAMERA + "julia_fractal { <-0.2, 0.8, 0, 0> slice N, D }"
    # a w-only normal: exact; POV-Ray normalises it and keeps the distance
    rc, out, err = _import(tmp_path, body.replace("N", "<0, 0, 0, 2>").replace("D", "0.3"), capsys)
    assert rc == 0 and err == "", err
    s = Scene.from_toml(out)
    assert s.slice.normal == (0.0, 0.0, 0.0, 1.0) and s.slice.distance == 0.3
    assert s.camera.position == (1.5, 1.0, -3.5, 0.0) and s.camera.limbo == (0.0, 0.0, 0.0, 1.0)
    # POV-Ray's point (x, y, z) is the 4D point (x, y, z, d / n_t)
    assert np.allclose(to_world(s, (0.1, 0.2, 0.3, 0.0)), (0.1, 0.2, 0.3, 0.3))
    # negative w: the world w is -d, and pyjulia4d's right (cross4 with limbo R e_w = -e_w)
    # would turn over: limbo -w keeps POV-Ray's right
    rc, out, err = _import(tmp_path, body.replace("N", "<0, 0, 0, -1>").replace("D", "0.3"), capsys)
    s = Scene.from_toml(out)
    assert np.allclose(to_world(s, (0.1, 0.2, 0.3, 0.0)), (0.1, 0.2, 0.3, -0.3))
    assert s.camera.limbo == (0.0, 0.0, 0.0, -1.0)
    assert _pixel_pj(s, (1.0, 0, 0)) == pytest.approx(_pixel_pov(_doc_camera(), (1.0, 0, 0), 640, 480), abs=1e-7)
    # a tilted normal: same hyperplane, the eye at POV-Ray's 4D point, and a warning
    rc, out, err = _import(tmp_path, body.replace("N", "<0.2, 0.1, -0.1, 1>").replace("D", "0.1"), capsys)
    assert rc == 0 and err.count("\n") == 1 and "pyjulia4d: warning:" in err and "sheared" in err
    s = Scene.from_toml(out)
    n = np.array([0.2, 0.1, -0.1, 1.0])
    eye = to_world(s, s.camera.position)
    x = np.array([1.5, 1.0, -3.5])
    nn = n / np.linalg.norm(n)  # POV-Ray normalises the normal, not the distance
    assert np.allclose(eye, [*x, (0.1 - nn[:3] @ x) / nn[3]])
    assert eye @ nn == pytest.approx(0.1)  # on the hyperplane n.p = d, |n| = 1


def test_escape_radius():
    assert pov_escape_radius("hypercomplex", (5, 5, 5, 5)) == 4.0
    assert pov_escape_radius("quaternion", (3, 0, 0, 0)) == pytest.approx(math.sqrt(4 + 1e-7))
    assert pov_escape_radius("quaternion", (0, 0, 0, 0)) == pytest.approx(1.0, abs=2e-7)


# ------------------------------------------------------------- camera mapping

def _pov_camera(loc, look_at=None, angle=None, right=(1.33, 0, 0), up=(0, 1, 0), sky=(0, 1, 0),
                direction=(0, 0, 1)):
    """POV-Ray 3.5+ Parse_Camera, written out again here: (location, direction, up, right)."""
    loc, d, up, right, sky = (np.array(v, float) for v in (loc, direction, up, right, sky))
    if angle is not None:
        d = d / np.linalg.norm(d) * np.linalg.norm(right) / math.tan(math.radians(angle) / 2) / 2
    if look_at is not None:
        dl, ul, rl = (np.linalg.norm(v) for v in (d, up, right))
        handed = np.cross(up, d) @ right
        dn = np.array(look_at, float) - loc
        dn /= np.linalg.norm(dn)
        r = np.cross(sky, dn)
        r /= np.linalg.norm(r)
        up = np.cross(dn, r) * ul
        d = dn * dl
        right = r * (rl if handed > 0 else -rl)
    return loc, d, up, right


def _doc_camera():
    return _pov_camera((1.5, 1, -3.5), (0, 0, 0), 45, right=(4 / 3, 0, 0))


def _pixel_pov(cam, p, w, h):
    """Where POV-Ray draws the point p: p - location = s (direction + a right + b up),
    pixel (a + 1/2) W, (1/2 - b) H."""
    loc, d, up, right = cam
    m = np.stack([d, right, up], axis=1)
    s, sa, sb = np.linalg.solve(m, np.asarray(p, float) - loc)
    return np.array([(sa / s + 0.5) * w, (0.5 - sb / s) * h])


def _pixel_pj(scene: Scene, p):
    """Where pyjulia4d draws the camera-space point p (reference.generate_rays inverted)."""
    f = camera_frame(scene)
    v = to_world(scene, (*p, 0.0)) - f.position
    fwd = v @ f.forward
    w, h = scene.image.width, scene.image.height
    u = (v @ f.right) / fwd / (f.tan_half_fov * w / h)
    vv = (v @ f.up) / fwd / f.tan_half_fov
    return np.array([(u + 1) / 2 * w, (1 - vv) / 2 * h])


# (camera statement, POV-Ray's vectors); the image is 640x480 but for "default", whose
# right 1.33 asks for a 1.33 aspect ratio (at 640x480 POV-Ray stretches its pixels 0.25 %)
CAMERAS = {
    "look_at": ("location <1.5, 1, -3.5> look_at <0, 0, 0> angle 45 right x*4/3",
                _pov_camera((1.5, 1, -3.5), (0, 0, 0), 45, right=(4 / 3, 0, 0))),
    "default": ("", _pov_camera((0, 0, 0), right=(1.33, 0, 0))),
    "sky": ("location <0.5, 2.5, -2> look_at <0, 0.1, 0> sky <1, 1, 0> angle 50 right x*4/3",
            _pov_camera((0.5, 2.5, -2), (0, 0.1, 0), 50, right=(4 / 3, 0, 0), sky=(1, 1, 0))),
    "left-handed": ("location <1.5, 1, -3.5> look_at 0 angle 45 right -x*4/3",
                    _pov_camera((1.5, 1, -3.5), (0, 0, 0), 45, right=(-4 / 3, 0, 0))),
    "direction": ("location <0.3, 0.2, -3> direction <0, 0, 1.5> right x*4/3",
                  _pov_camera((0.3, 0.2, -3), direction=(0, 0, 1.5), right=(4 / 3, 0, 0))),
    "angle-order": ("angle 30 look_at <0.2, 0, 0> location <2, 2, 2> right <4/3, 0, 0>",  # any order
                    _pov_camera((2, 2, 2), (0.2, 0, 0), 30, right=(4 / 3, 0, 0))),
}


@pytest.mark.parametrize("name", list(CAMERAS))
def test_camera_projection_matches_povray(tmp_path, capsys, name):
    """Random points land on the same pixel as in POV-Ray's projection; the view axis on
    the image centre; POV-Ray's right and up on the image's right and top."""
    text, cam = CAMERAS[name]
    w, h = (133, 100) if name == "default" else (640, 480)
    rc, out, err = _import(tmp_path, f"camera {{ {text} }}\n" + DOC_JULIA, capsys, "--width", str(w),
                           "--height", str(h))
    assert rc == 0 and err == "", err
    s = Scene.from_toml(out)
    rng = np.random.default_rng(3)
    loc, d, up, right = cam
    for _ in range(20):
        p = loc + d * rng.uniform(0.5, 3) + right * rng.uniform(-0.6, 0.6) + up * rng.uniform(-0.6, 0.6)
        assert _pixel_pj(s, p) == pytest.approx(_pixel_pov(cam, p, w, h), abs=1e-6)
    assert _pixel_pj(s, loc + 2.5 * d) == pytest.approx([w / 2, h / 2], abs=1e-9)
    x_right, _ = _pixel_pj(s, loc + d + 0.2 * right)
    _, y_up = _pixel_pj(s, loc + d + 0.2 * up)
    assert x_right > w / 2 + 1 and y_up < h / 2 - 1


def test_pov_x_appears_on_the_right(tmp_path, capsys):
    """POV-Ray is left-handed (x right, y up, z into the screen): from <0, 0, -5> looking
    at the origin, +x is on the right of the image and +y at the top, unmirrored."""
    rc, out, err = _import(tmp_path, "camera { location <0, 0, -5> look_at <0, 0, 0> }\n" + DOC_JULIA, capsys)
    s = Scene.from_toml(out)
    assert s.camera.position == (0.0, 0.0, -5.0, 0.0) and s.camera.limbo == (0.0, 0.0, 0.0, 1.0)
    assert _pixel_pj(s, (0, 0, 0)) == pytest.approx([320, 240])
    assert _pixel_pj(s, (1, 0, 0))[0] > 320 + 50
    assert _pixel_pj(s, (0, 1, 0))[1] < 240 - 50


@pytest.mark.parametrize("mods", ["rotate <30, -20, 45> translate <0.2, -0.1, 0.3> scale 1.2",
                                  "scale -1", "matrix <0,1,0, -1,0,0, 0,0,1, 0.5,0,0>"])
def test_object_transform_is_the_inverse_camera_transform(tmp_path, capsys, mods):
    """A point p of the fractal's own space is drawn by POV-Ray at T(p) in the world: it
    must land where the untransformed point lands in pyjulia4d's picture."""
    rc, out, err = _import(tmp_path, CAMERA + DOC_JULIA.replace("precision 15", f"precision 15 {mods}"), capsys)
    assert rc == 0, err
    s = Scene.from_toml(out)
    from pyjulia4d.interop.povray import SceneReader
    r = SceneReader(tokenize(f"julia_fractal {{ <0,0,0,0> {mods} }}", "t"), "t", 640, 480)
    r.run()
    tr = r.julias[0].transform
    rng = np.random.default_rng(5)
    cam = _doc_camera()
    for _ in range(10):
        p = rng.uniform(-0.5, 0.5, 3)
        assert _pixel_pj(s, p) == pytest.approx(_pixel_pov(cam, tr.point(p), 640, 480), abs=1e-6)


def test_rotate_follows_povray():
    """rotate <0, 0, 90> turns x into y (POV-Ray's documented left-hand rule), <90, 0, 0> y into z."""
    from pyjulia4d.interop.povray import rotation

    assert rotation((0, 0, 90)) @ [1, 0, 0] == pytest.approx([0, 1, 0])
    assert rotation((90, 0, 0)) @ [0, 1, 0] == pytest.approx([0, 0, 1])
    assert rotation((0, 90, 0)) @ [0, 0, 1] == pytest.approx([1, 0, 0])


def test_shading_light_and_syntax(tmp_path, capsys):
    text = """#version 3.7;  // a comment
#include "colors.inc"
/* a /* nested */ block comment */
#declare C = <-0.2, 0.8, 0, 0>;
#declare Dist = 2*3.5;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.2, 0.3> }
camera { location <0, 1, -Dist> look_at 0 angle 40 right x*image_width/image_height }
light_source { <2, 4, -3> color rgb <1, 0.9, 0.8> }
plane { y, -2 pigment { checker } }
#declare J = julia_fractal { C hypercomplex sin max_iteration 10 };
object { J texture { pigment { rgb <0.5, 0.6, 0.7> } finish { ambient 0.2 specular 0.5 roughness 0.02 } } }
"""
    rc, out, err = _import(tmp_path, text, capsys, "--width", "320", "--height", "200")
    assert rc == 0 and err == "", err
    s = Scene.from_toml(out)
    assert s.fractal.c == (-0.2, 0.8, 0.0, 0.0) and s.fractal.function == "sin"
    assert s.camera.position[:3] == (0.0, 1.0, -7.0) and s.image.width == 320
    sh = s.shading
    assert sh.color == (0.5, 0.6, 0.7) and sh.background == (0.1, 0.2, 0.3)
    assert (sh.ambient, sh.diffuse, sh.specular) == (0.2, 0.6, 0.5)  # diffuse: POV-Ray's default
    assert sh.shininess == pytest.approx(50.0)
    assert sh.light[:3] == (2.0, 4.0, -3.0) and sh.light_color == (1.0, 0.9, 0.8)
    assert sh.shadow == "hard" and sh.ao == 0.0  # POV-Ray's point light; no ambient occlusion
    toml = out.read_text()
    assert "plane (line 10)" in toml and "colors.inc" in toml


# ------------------------------------------------------------------ bad input

BAD = {
    "no-block": ("camera { location <0,0,-3> }\nsphere { 0, 1 }\n", "no julia_fractal"),
    "unknown-keyword": ("julia_fractal { <0,0,0,0> sqrt }", "unknown or unmappable keyword 'sqrt'"),
    "interior": ("julia_fractal { <0,0,0,0> interior { ior 1.5 } }", "'interior'"),
    "zero-slice": ("julia_fractal { <0,0,0,0> slice <0,0,0,0>, 1 }", "slice: the normal is zero"),
    "zero-t-slice": ("julia_fractal { <0,0,0,0> slice <1,0,0,0>, 1 }", "4th component is zero"),
    "pwr-missing": ("julia_fractal { <0,0,0,0> hypercomplex pwr(2) }", "pwr needs two numbers"),
    "pwr-bare": ("julia_fractal { <0,0,0,0> hypercomplex pwr }", "expected '(' after pwr"),
    "comment": ("julia_fractal { <0,0,0,0> } /* never closed", "unterminated /* comment"),
    "non-utf8": (b"// caf\xe9\njulia_fractal { <0,0,0,0> }", "not UTF-8"),
    "unknown-identifier": ("#include \"colors.inc\"\njulia_fractal { Jp }",
                           "unknown identifier 'Jp' where a value is expected (files named by #include"),
    "declared-texture": ("#declare T = texture { pigment { rgb 1 } }\njulia_fractal { <0,0,0,0> texture { T } }",
                         "texture: 'T' cannot be mapped"),
    "non-uniform-scale": ("julia_fractal { <0,0,0,0> scale <1,2,1> }", "is not uniform"),
    "two": ("julia_fractal { <0,0,0,0> }\njulia_fractal { <0,0,0,0> }", "a second julia_fractal"),
    "max-iteration-1": ("julia_fractal { <0,0,0,0> max_iteration 1 }", "max_iteration 1"),
    "quaternion-sin": ("julia_fractal { <0,0,0,0> sin }", "quaternion takes sqr and cube only"),
    "unterminated": ("julia_fractal { <0,0,0,0> sqr", "unterminated 'julia_fractal {'"),
    "directive": ("#if (1) #end julia_fractal { <0,0,0,0> }", "unsupported directive #if"),
    "orthographic": ("camera { orthographic location <0,0,-3> }\njulia_fractal { <0,0,0,0> }",
                     "camera type 'orthographic' cannot be mapped"),
    "pattern": ("julia_fractal { <0,0,0,0> pigment { checker } }", "only a plain colour"),
    "nested": ("union { julia_fractal { <0,0,0,0> } sphere { 0, 1 } }", "julia_fractal inside 'union"),
    "range": ("julia_fractal { <0,0,0,0> hypercomplex pwr(40, 0) }", "maps to fractal.exponent"),
    "division": ("julia_fractal { <0,0,0,1/0> }", "division by zero"),
}


@pytest.mark.parametrize("name", list(BAD))
def test_bad_input(tmp_path, capsys, name):
    text, message = BAD[name]
    before = sorted(os.listdir(tmp_path))
    rc, out, err = _import(tmp_path, text, capsys)
    assert rc == 2
    assert err.count("\n") == 1 and err.startswith("pyjulia4d: error: "), err
    assert message in err, err
    assert sorted(os.listdir(tmp_path)) == sorted(before + ["scene.pov"])  # no output, no temp file


@pytest.mark.parametrize("argv,message", [
    (["import-pov", "DIR"], "cannot read: Is a directory"),
    (["import-pov", "missing.pov"], "cannot read: No such file or directory"),
    (["import-pov", "ok.pov", "-o", "ok.png"], "unsupported output format '.png' (use .toml)"),
    (["import-pov", "ok.pov", "-o", "nowhere/ok.toml"], "directory 'nowhere' does not exist"),
    (["import-pov", "ok.pov", "-o", "DIR"], "unsupported output format"),
    (["import-pov", "ok.pov", "--width", "0"], "image.width: must be in [1, 2147483647], got 0"),
    (["import-pov", "ok.pov", "--height", "abc"], "image.height: expected an integer, got 'abc'"),
    (["import-pov"], "the following arguments are required: FILE.pov"),
])
def test_bad_paths_and_options(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "DIR").mkdir()
    (tmp_path / "ok.pov").write_text(DOC_JULIA)
    rc, out, err = _run(argv, capsys)
    assert rc == 2 and err.count("\n") == 1 and message in err, err
    assert sorted(os.listdir(tmp_path)) == ["DIR", "ok.pov"]


def test_no_traceback_through_python_m(tmp_path):
    (tmp_path / "bad.pov").write_text("julia_fractal { <0,0,0,0> interior { } }")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [PKG_ROOT, os.environ.get("PYTHONPATH")]))}
    p = subprocess.run([sys.executable, "-m", "pyjulia4d", "import-pov", "bad.pov"], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "Traceback" not in p.stderr and p.stderr.count("\n") == 1
    assert sorted(os.listdir(tmp_path)) == ["bad.pov"]


# ------------------------------------------------------------------------ fuzz

BASE = (DATA / "doc_example.pov").read_text() + """
#declare K = <0.2, 0.1, -0.1, 1>;
background { color rgb <0, 0, 0.1> }
sphere { <0, -3, 0>, 1 pigment { rgb 1 } }
"""
VOCAB = ["{", "}", "<", ">", "(", ")", ",", ";", "-", "*", "/", "0", "1", "2.5", "1e400", "-0", "x",
         "julia_fractal", "hypercomplex", "quaternion", "cube", "sin", "pwr", "slice", "K", "max_iteration",
         "precision", "camera", "look_at", "location", "angle", "180", "sky", "right", "up", "rotate", "scale",
         "translate", "pigment", "finish", "texture", "rgb", "color", "interior", "#declare", "#include",
         "#version", "#if", '"', "/*", "*/", "//", "object", "light_source", "image_width", "undefined_id",
         "\u00e9", "\x00"]


def test_fuzz_mutated_scenes(tmp_path, capsys, monkeypatch):
    """300 scenes with tokens deleted, inserted, duplicated and numbers changed: every one is imported with
    status 0 (and a scene that loads) or 2 (one error line and no file); no exception
    escapes, no temp file is left behind."""
    monkeypatch.chdir(tmp_path)
    rng = random.Random(20251125)
    base = [t.text if t.kind != "str" else f'"{t.text}"' for t in tokenize(BASE, "base")[:-1]]
    counts = {0: 0, 2: 0}
    for i in range(300):
        toks = list(base)
        for _ in range(rng.randint(1, 4)):
            op = rng.random()
            k = rng.randrange(len(toks) + 1)
            if op < 0.3 and toks:
                del toks[min(k, len(toks) - 1)]
            elif op < 0.6:
                toks.insert(k, rng.choice(VOCAB))
            elif op < 0.75:
                toks.insert(k, toks[min(k, len(toks) - 1)])
            else:  # a number changed: mostly still a scene, sometimes out of range
                numbers = [j for j, t in enumerate(toks) if t[:1].isdigit()]
                toks[rng.choice(numbers)] = rng.choice(["0", "1", "-3", "0.5", "1e-9", "7", "2e5", "180"])
        (tmp_path / "f.pov").write_text(" ".join(toks), encoding="utf-8")
        rc, out, err = _run(["import-pov", "f.pov", "-o", "f.toml", "--width", "32", "--height", "24"], capsys)
        counts[rc] = counts.get(rc, 0) + 1
        files = sorted(os.listdir(tmp_path))
        if rc == 0:
            assert files == ["f.pov", "f.toml"], (i, files)
            Scene.from_toml("f.toml")
            os.unlink("f.toml")
        else:
            assert rc == 2, (i, rc, err)
            lines = err.splitlines()
            assert len(lines) == 1 and lines[0].startswith("pyjulia4d: error: "), (i, err)
            assert files == ["f.pov"], (i, files)
    assert counts[0] >= 30 and counts[2] >= 100, counts  # both outcomes are exercised


@pytest.mark.parametrize("light,mods,shadow", [("shadowless", "", "none"), ("", "no_shadow", "none"),
                                              ("", "", "hard")])
def test_light_shadows(tmp_path, capsys, light, mods, shadow):
    rc, out, err = _import(tmp_path, CAMERA + f"light_source {{ <1, 2, -3> color rgb 1 {light} }}\n"
                           + DOC_JULIA.replace("precision 15", f"precision 15 {mods}"), capsys)
    assert rc == 0, err
    sh = Scene.from_toml(out).shading
    assert (sh.shadow, sh.ao) == (shadow, 0.0)
