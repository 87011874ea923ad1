"""Scene loading, overrides, TOML round trip and validation messages."""
from __future__ import annotations

import dataclasses
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from pyjulia4d.scene.model import SECTIONS, Scene

from pyjulia4d.scene.checks import OrWord, SceneError
from pyjulia4d.scene.ranges import CHECKS, valid_range
from pyjulia4d.fractal.registry import march_method

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def test_defaults() -> None:
    s = Scene.default()
    # a scene read without a camera position frames the set (camera.fit); the built-in
    # scene is the same with its own camera placed
    assert s.camera.fit is False and Scene.from_dict({}).camera.fit is True
    assert s == Scene.from_dict({"camera": {"fit": False}})
    assert s.fractal.c == (-0.2, 0.8, 0.0, 0.0)
    assert s.fractal.max_iter == 12 and s.fractal.bailout == 4.0
    assert s.camera.position == (1.8, 1.6, -2.2, 0.0) and s.camera.fov == 40.0
    assert s.march.method == "auto" and march_method(s) == "de" and s.march.near == "auto" and s.march.max_steps == 4096
    assert s.normals.method == "jacobian" and s.shading.light == (-2.0, 5.0, -4.0, 0.0)
    assert s.shading.shadow == "soft" and s.shading.ao == 0.6
    assert (s.image.width, s.image.height) == (640, 480)
    assert s.render.float == "auto" and s.precision == "single"   # double only where float32 stops proofs short


def test_checks_cover_every_field() -> None:
    for name, cls in SECTIONS.items():
        assert [f.name for f in dataclasses.fields(cls)] == list(CHECKS[name])


def test_frozen() -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        Scene.default().image.width = 3  # type: ignore[misc]


def _custom() -> Scene:
    return Scene.from_dict(
        {
            "fractal": {"c": [0.1, -0.3, 1e-5, 0], "max_iter": 9},
            "camera": {"position": [1, 2, 3], "fov": 33.3},
            "march": {"method": "fixed", "near": 0.5, "far": 7},
            "normals": {"step": 1e-4},
            "shading": {"light": [3, 4, 5, 0.25], "color": [1, 0.5, 0.1]},
            "image": {"width": 17, "height": 9},
            "render": {"float": "double"},
        }
    )


@pytest.mark.parametrize("scene", [Scene.default(), _custom()], ids=["default", "custom"])
def test_toml_round_trip(scene: Scene, tmp_path) -> None:
    text = scene.to_toml()
    assert Scene.from_dict(tomllib.loads(text)) == scene
    path = tmp_path / "s.toml"
    path.write_text(text)
    assert Scene.from_toml(path) == scene
    assert Scene.from_dict(scene.to_dict()) == scene


def test_three_vectors_get_w_zero() -> None:
    s = _custom()
    assert s.camera.position == (1.0, 2.0, 3.0, 0.0)
    assert s.shading.light == (3.0, 4.0, 5.0, 0.25)
    assert all(isinstance(x, float) for x in s.fractal.c)


def test_overrides_parse() -> None:
    s = Scene.default().with_overrides(
        [
            "fractal.c=-0.2,0.8,0,0.1",
            "fractal.max_iter=20",
            "fractal.bailout=3",
            "march.method=fixed",
            "march.near=auto",
            "march.far=9.5",
            "shading.light=eye",
            "shading.light_color=[1, 0.5, 0.5]",
            "camera.up = 1,1,0",
            "image.width=32",
        ]
    )
    assert s.fractal.c == (-0.2, 0.8, 0.0, 0.1)
    assert s.fractal.max_iter == 20 and isinstance(s.fractal.max_iter, int)
    assert s.fractal.bailout == 3.0 and isinstance(s.fractal.bailout, float)
    assert s.march.method == "fixed" and s.march.near == "auto" and s.march.far == 9.5
    assert s.shading.light == "eye" and s.shading.light_color == (1.0, 0.5, 0.5)
    assert s.camera.up == (1.0, 1.0, 0.0, 0.0)
    assert s.image.width == 32


def test_overrides_apply_after_file(tmp_path) -> None:
    path = tmp_path / "s.toml"
    path.write_text("[image]\nwidth = 100\nheight = 50\n")
    s = Scene.from_toml(path, ["image.width=7", "shading.light=1,2,3"])
    assert (s.image.width, s.image.height) == (7, 50)
    assert s.shading.light == (1.0, 2.0, 3.0, 0.0)


def test_replace() -> None:
    s = Scene.default().replace(**{"march.post_steps": 10, "fractal.c": (0, 0, 0, 0)})
    assert s.march.post_steps == 10 and s.fractal.c == (0.0, 0.0, 0.0, 0.0)
    with pytest.raises(SceneError, match=r"^march\.zres: unknown key$"):
        Scene.default().replace(**{"march.zres": 1})


BAD = [
    # (override, key the message must start with)
    ("march.zres=3", "march.zres"),
    ("zork.x=1", "zork.x"),
    ("fractal.max_iter=abc", "fractal.max_iter"),
    ("fractal.max_iter=12.0", "fractal.max_iter"),
    ("fractal.max_iter=true", "fractal.max_iter"),
    ("fractal.max_iter=0", "fractal.max_iter"),
    ("fractal.algebra=octonion", "fractal.algebra"),
    ("fractal.function=quartic", "fractal.function"),
    ("fractal.function=sin", "fractal.function"),   # quaternions: sqr and cube only
    ("fractal.exponent=1,2,3", "fractal.exponent"),
    ("fractal.bailout=0", "fractal.bailout"),
    ("fractal.bailout=nan", "fractal.bailout"),
    ("fractal.c=1,2,3", "fractal.c"),
    ("fractal.c=1,2,x,4", "fractal.c"),
    ("fractal.c=1,2,inf,4", "fractal.c"),
    ("camera.up=0,0,0", "camera.up"),
    ("camera.up=0,0,0,0", "camera.up"),
    ("camera.limbo=0,0,0,0", "camera.limbo"),
    ("camera.position=1,2", "camera.position"),
    ("camera.target=1.8,1.6,-2.2", "camera.target"),
    ("camera.limbo=-1.8,-1.6,2.2", "camera.limbo"),
    ("camera.up=0,0,0,1", "camera.up"),
    ("camera.fov=0", "camera.fov"),
    ("camera.fov=180", "camera.fov"),
    ("camera.fov=inf", "camera.fov"),
    ("slice.normal=0,0,0,0", "slice.normal"),
    ("slice.distance=-inf", "slice.distance"),
    ("march.method=sphere", "march.method"),
    ("march.z_resolution=0", "march.z_resolution"),
    ("march.post_steps=-1", "march.post_steps"),
    ("march.epsilon=0", "march.epsilon"),
    ("march.epsilon=-1e-3", "march.epsilon"),
    ("march.max_steps=0", "march.max_steps"),
    ("march.near=-1", "march.near"),
    ("march.near=fast", "march.near"),
    ("march.far=0", "march.far"),
    ("normals.method=magic", "normals.method"),
    ("normals.step=0", "normals.step"),
    ("shading.color=1,-0.1,0", "shading.color"),
    ("shading.color=1,1,1,1", "shading.color"),
    ("shading.ambient=-0.1", "shading.ambient"),
    ("shading.shininess=0", "shading.shininess"),
    ("shading.light=sun", "shading.light"),
    ("shading.light=1,2", "shading.light"),
    ("image.width=0", "image.width"),
    ("image.height=-5", "image.height"),
    ("image.width=1.5", "image.width"),
    ("image.width=99999999999", "image.width"),
    ("render.float=half", "render.float"),
]


@pytest.mark.parametrize("override,key", BAD, ids=[b[0] for b in BAD])
def test_bad_override(override: str, key: str) -> None:
    with pytest.raises(SceneError) as info:
        Scene.from_dict({}, [override])
    msg = str(info.value)
    assert msg.startswith(key + ": "), msg
    assert info.value.key == key and "\n" not in msg


@pytest.mark.parametrize(
    "value,reason",
    [
        (float("nan"), "not a finite number"),
        (float("inf"), "not a finite number"),
        (-math.inf, "not a finite number"),
        (True, "expected a number, got True"),
        ("1.0", "expected a number, got '1.0'"),
    ],
)
def test_bad_float_values(value: object, reason: str) -> None:
    with pytest.raises(SceneError) as info:
        Scene.from_dict({"march": {"epsilon": value}})
    assert str(info.value) == f"march.epsilon: {reason}"


def test_exact_messages() -> None:
    cases = {
        "camera.up=0,0,0": "camera.up: zero-length vector",
        "march.zres=1": "march.zres: unknown key",
        "fractal.max_iter=abc": "fractal.max_iter: expected an integer, got 'abc'",
        "camera.target=1.8,1.6,-2.2,0": "camera.target: equals camera.position",
        "fractal.c=1,2": "fractal.c: expected a list of 4 numbers, got 2",
    }
    for override, message in cases.items():
        with pytest.raises(SceneError) as info:
            Scene.default().with_overrides([override])
        assert str(info.value) == message


def test_dict_errors() -> None:
    with pytest.raises(SceneError, match=r"^zork: unknown key$"):
        Scene.from_dict({"zork": {}})
    with pytest.raises(SceneError, match=r"^image: expected a table"):
        Scene.from_dict({"image": 3})
    with pytest.raises(SceneError, match=r"^fractal\.max_iter: expected an integer, got 12\.0$"):
        Scene.from_dict({"fractal": {"max_iter": 12.0}})
    with pytest.raises(SceneError, match=r"^fractal\.c: expected a list of 4 numbers"):
        Scene.from_dict({"fractal": {"c": "0,0,0,0"}})


def test_far_must_exceed_near() -> None:
    with pytest.raises(SceneError, match=r"^march\.far: must be greater than march\.near"):
        Scene.from_dict({"march": {"near": 2.0, "far": 2.0}})
    assert Scene.from_dict({"march": {"near": 2, "far": "auto"}}).march.near == 2.0


def test_malformed_override() -> None:
    with pytest.raises(SceneError, match=r"^fractal\.c: malformed override"):
        Scene.from_dict({}, ["fractal.c"])
    with pytest.raises(SceneError, match=r"^width: unknown key$"):
        Scene.from_dict({}, ["width=3"])


def test_unreadable_file(tmp_path) -> None:
    missing = tmp_path / "missing.toml"
    with pytest.raises(SceneError) as info:
        Scene.from_toml(missing)
    assert str(info.value).startswith(f"{missing}: cannot read: ")
    with pytest.raises(SceneError, match=r": cannot read: "):
        Scene.from_toml(tmp_path)  # a directory


def test_toml_syntax_error(tmp_path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text("[fractal\nmax_iter = 3\n")
    with pytest.raises(SceneError) as info:
        Scene.from_toml(path)
    assert str(info.value).startswith(f"{path}: invalid TOML: ")
    path.write_bytes(b"[image]\nwidth = \xff\n")
    with pytest.raises(SceneError, match=r": invalid TOML"):
        Scene.from_toml(path)


def test_toml_values_validated(tmp_path) -> None:
    path = tmp_path / "s.toml"
    path.write_text("[march]\nepsilon = nan\n")
    with pytest.raises(SceneError, match=r"^march\.epsilon: not a finite number$"):
        Scene.from_toml(path)
    path.write_text("[camera]\nlimbo = [0, 0, 0, 0]\n")
    with pytest.raises(SceneError, match=r"^camera\.limbo: zero-length vector$"):
        Scene.from_toml(path)


def test_error_single_argument_form() -> None:
    e = SceneError("camera.up: parallel to the view direction")
    assert (e.key, e.reason) == ("camera.up", "parallel to the view direction")
    assert str(SceneError("a.b", "c")) == "a.b: c"


def _readme_key_rows() -> dict[str, list[str]]:
    """docs/scene-keys.md's table of scene keys: key -> its cells, backticks and escapes
    removed."""
    readme = Path(__file__).resolve().parents[2] / "docs" / "scene-keys.md"
    if not readme.exists():
        pytest.skip("docs/scene-keys.md is not beside the tests (installed package)")
    text = readme.read_text(encoding="utf-8")
    table = text[text.index("| key | default | valid range | meaning |"):]
    rows = {}
    for line in table.splitlines()[2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip().replace("`", "").replace("\\|", "|")
                 for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        rows[cells[0]] = cells[1:]
    return rows


def test_readme_valid_ranges_match_the_checkers() -> None:
    """docs/scene-keys.md's valid-range column is the checkers' own description and its
    default column the scene's default as ``pyjulia4d keys`` prints it, for every key."""
    from pyjulia4d.scene.keys import default_text

    rows = _readme_key_rows()
    keys = [f"{s}.{k}" for s, table in CHECKS.items() for k in table]
    assert sorted(rows) == sorted(keys)
    for key in keys:
        assert rows[key][1] == valid_range(key), key
        assert rows[key][0] == default_text(key), key


# ------------------------------------------------------------------ valid ranges

def _edges():
    """(dotted key, its lowest and highest valid value, a value just outside each) for
    every numeric key; vectors get every component at the edge."""
    for section, table in CHECKS.items():
        for key, check in table.items():
            inner = OrWord.split(check)[1]   # "auto" (or "auto" or "pixel") or a number
            element = getattr(inner, "element", None)  # a vector's components
            rng = getattr(element or inner, "range", None)
            if rng is None:
                continue
            n = max(inner.lengths) if element else 0
            integer = isinstance(rng.lo, int)
            lo = rng.lo + 1e-9 if rng.lo_open else rng.lo
            below = rng.lo - 1 if integer else rng.lo - max(1.0, abs(rng.lo)) * 1e-9
            above = rng.hi + 1 if integer else rng.hi * (1 + 1e-9)
            for inside, outside in ((lo, below), (rng.hi, above)):
                yield f"{section}.{key}", [inside] * n if n else inside, [outside] * n if n else outside


@pytest.mark.parametrize("key,inside,outside", list(_edges()))
def test_range_edges(key: str, inside, outside) -> None:
    section, _, name = key.partition(".")
    camera = {"position": [1.8, 1.6, -2.2, 0], "target": [0, 0, 0, 0], "up": [0, 1, 0, 0], "limbo": [0, 0, 0, 1]}
    # a camera vector with every component at an edge needs the others out of its way
    if name in ("position", "target"):
        camera.update(position=[0, 0, 0, 0], target=[0, 0, 0, 0], up=[1, -1, 0, 0], limbo=[0, 0, 1, -1])
        camera["target" if name == "position" else "position"] = [1, 0, 0, 0] if inside[0] == 0 else [0, 0, 0, 0]
    elif name in ("up", "limbo"):
        camera.update(position=[0, 0, 0, 0], target=[1, -1, 0, 0], up=[0, 0, 1, -1], limbo=[0, 0, 1, -1])
    data = {"camera": camera} if section == "camera" else {}
    data.setdefault(section, {})[name] = inside
    Scene.from_dict(data)  # the edge itself is valid
    data[section][name] = outside
    with pytest.raises(SceneError) as info:
        Scene.from_dict(data)
    assert info.value.key == key and "must be in " in info.value.reason


def test_every_catalogue_case_is_valid() -> None:
    from pyjulia4d.measure import catalogue
    for case in catalogue.catalogue():
        for method in case.methods:
            catalogue.scene(case, method, "double")


@pytest.mark.parametrize("text,message", [
    ("slice.normal=1e300,1e300,1e300,1e300", "slice.normal: element 0: must be in [-1e6, 1e6], got 1e+300"),
    ("camera.position=1e300,0,0", "camera.position: element 0: must be in [-1e6, 1e6], got 1e+300"),
    ("shading.specular=1e308", "shading.specular: must be in [0, 1e3], got 1e+308"),
    ("shading.shininess=1e308", "shading.shininess: must be in [1e-3, 1e4], got 1e+308"),
    ("march.near=1e308", "march.near: must be in [0, 1e7], got 1e+308"),
    ("fractal.c=0,0,0,1001", "fractal.c: element 3: must be in [-1e3, 1e3], got 1001"),
    ("fractal.bailout=1e80", "fractal.bailout: must be in [1e-3, 1e76], got 1e+80"),
    ("camera.fov=179.95", "camera.fov: must be in [1e-6, 179.9], got 179.95"),
    ("march.post_steps=1001", "march.post_steps: must be in [0, 1000], got 1001"),
    ("fractal.max_iter=1000001", "fractal.max_iter: must be in [1, 1000000], got 1000001"),
    ("march.far=0", "march.far: must be in (0, 1e7], got 0"),
    ("fractal.max_iter=١٢", "fractal.max_iter: expected an integer, got '١٢'"),
    ("march.epsilon=1e400", "march.epsilon: not a finite number"),
    ("fractal.max_iter=" + "9" * 5000, "fractal.max_iter: expected an integer, got '" + "9" * 56 + "..."),
    ("=", "--set: missing key in '=', expected SECTION.KEY=VALUE"),
    ("", "--set: malformed override '', expected SECTION.KEY=VALUE"),
    ("fractal.c\n=1", "fractal.c: expected a list of 4 numbers, got 1"),
    ("a\nb=1", "'a\\nb': unknown key"),
    ("camera.target=1.8,1.6,-2.2,1e-9", "camera.target: closer than 3.3e-08 to camera.position (1e-8 x max(1, |position|, |target|): "
     "the view direction must hold to the smallest fov)"),
])
def test_out_of_range_messages(text: str, message: str) -> None:
    with pytest.raises(SceneError) as info:
        Scene.default().with_overrides([text])
    assert str(info.value) == message


def test_huge_integers_in_a_scene() -> None:
    with pytest.raises(SceneError, match=r"^march\.epsilon: must be in \[1e-12, 1\], got 10000+\.\.\.$"):
        Scene.from_dict({"march": {"epsilon": 10**400}})
    with pytest.raises(SceneError, match=r"^march\.epsilon: must be in \[1e-12, 1\], got <an integer of ~5001 digits>$"):
        Scene.from_dict({"march": {"epsilon": 10**5000}})
    with pytest.raises(SceneError, match=r"^image\.width: must be in \[1, 2147483647\], got 1000"):
        Scene.from_dict({"image": {"width": 10**40}})


def test_negative_zero_is_zero() -> None:
    s = Scene.from_dict({"march": {"near": -0.0}, "fractal": {"c": [-0.0, 0.8, 0, 0]}})
    assert math.copysign(1.0, s.march.near) == 1.0 and math.copysign(1.0, s.fractal.c[0]) == 1.0


@pytest.mark.parametrize("scale", [1e-300, 5e-324, 1e-12, 1.0, 1e6])
def test_directions_of_any_length(scale: float) -> None:
    """up, limbo and slice.normal are directions: normalised by their largest component,
    so tiny and large lengths give the frame of the unit vector."""
    from pyjulia4d.geometry.camera import camera_frame, slice_rotation
    base = Scene.default().with_overrides(["slice.normal=0.2,0,0.3,1"])
    s = base.replace(**{"camera.up": [0, scale, 0, 0], "camera.limbo": [0, 0, 0, scale],
                        "slice.normal": [0.2 * scale, 0, 0.3 * scale, scale] if scale > 1e-300 else [0, 0, 0, scale]})
    f, g = camera_frame(s), camera_frame(base if scale > 1e-300 else Scene.default())
    for a, b in ((f.forward, g.forward), (f.up, g.up), (f.right, g.right), (f.position, g.position)):
        assert np.all(np.isfinite(a)) and np.allclose(a, b, atol=1e-12)
    assert np.all(np.isfinite(slice_rotation([scale, scale, scale, scale])))


def test_deep_toml_and_big_files(tmp_path) -> None:
    path = tmp_path / "s.toml"
    path.write_text("[fractal]\nc = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(SceneError, match=r": invalid TOML: nested too deeply$"):
        Scene.from_toml(path)
    path.write_text("[fractal]\nc = [" + "[" * 300 + "]" * 300 + ", 0, 0, 0]\n")  # parses; shown short
    with pytest.raises(SceneError, match=r"^fractal\.c: element 0: expected a number, got \[\[\["):
        Scene.from_toml(path)
    path.write_text("[fractal]\nmax_iter = " + "1" * 5000 + "\n")
    with pytest.raises(SceneError, match=r": invalid TOML: a number too long to read$"):
        Scene.from_toml(path)
    path.write_bytes(b"#" * (1 << 20) + b"\n")
    with pytest.raises(SceneError, match=r": larger than 1 MiB, not a scene file$"):
        Scene.from_toml(path)
    path.write_bytes(b"#" * ((1 << 20) - 1) + b"\n")  # exactly 1 MiB is fine
    assert Scene.from_toml(path) == Scene.from_dict({})


@pytest.mark.parametrize("camera, fit", [({}, True), ({"position": [0, 0, -4, 0]}, False),
                                          ({"fit": False}, False), ({"position": [0, 0, -4, 0], "fit": True}, True),
                                          ({"target": [0, 0.1, 0, 0]}, True)])
def test_fit_is_the_default_without_a_camera_position(camera, fit) -> None:
    assert Scene.from_dict({"camera": camera}).camera.fit is fit
    # an override giving the position counts as given
    assert Scene.from_dict({}, ["camera.position=0,0,-4,0"]).camera.fit is False
    # a resolved scene says it, so it reads back the same
    s = Scene.from_dict({"camera": camera})
    assert Scene.from_dict(tomllib.loads(s.to_toml())) == s


def test_a_keyframed_scene_points_to_animate() -> None:
    for table in ({"animation": {"frames": 3}}, {"keyframe": [{"frame": 0}]}):
        with pytest.raises(SceneError, match=r"^(animation|keyframe): a keyframed scene: render its frames with "):
            Scene.from_dict(table)
