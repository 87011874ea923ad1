"""Path-traced renders as a whole: the same pixels whatever the tiles, the noise target,
the lens's focus, the denoiser, and what a direct render keeps from all of it (nothing)."""
from __future__ import annotations

import numpy as np
import pytest

import pyjulia4d
from pyjulia4d.pipeline import film
from pyjulia4d.pipeline.plan import make_plan
from pyjulia4d.pipeline.path_plan import resolve_focus
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene


def scene(**sections) -> Scene:
    d = {"shading": {"integrator": "path", "bounces": 3}, "image": {"width": 40, "height": 30, "samples": 8},
         "camera": {"fit": False}}
    for k, v in sections.items():
        d.setdefault(k, {}).update(v)
    return Scene.from_dict(d)


def test_same_pixels_in_any_tiles_and_regions() -> None:
    sc = scene()
    whole = pyjulia4d.render(sc)
    tiled = pyjulia4d.render(sc, tile=16, calibrate=False)
    assert np.array_equal(whole.color, tiled.color) and np.array_equal(whole.alpha, tiled.alpha)
    assert np.array_equal(whole.film.variance, tiled.film.variance)
    part = pyjulia4d.render(sc, region=(8, 5, 20, 17))
    assert np.array_equal(part.color, whole.color[5:22, 8:28])
    assert whole.color.std() > 0.01   # a picture, not a blank


def test_noise_target_stops_pixels_that_meet_it() -> None:
    sc = scene(image={"samples": 96, "noise": 0.03})
    r = pyjulia4d.render(sc)
    paths, noise = r.film.paths, r.film.noise
    stopped = paths < 96
    assert stopped.any() and (~stopped).any()
    assert paths.min() >= 16
    assert np.all(noise[stopped] <= 0.03)
    assert np.all(paths[r.alpha == 0] == 16)   # the background has no variance: done at the first check
    # a pixel's paths do not depend on which others stop: its first samples are the full render's
    full = pyjulia4d.render(sc.replace(**{"image.noise": 0.0}))
    assert np.all(full.film.paths == 96)


def test_auto_focus_is_the_centre_depth() -> None:
    sc = scene(camera={"aperture": 0.05})
    plan = make_plan(sc, "CPU", 1)
    r = pyjulia4d.render(sc.replace(**{"shading.integrator": "direct", "camera.aperture": 0.0}),
                         outputs=["depth"])
    h, w = r.depth.shape
    fr = plan.frame
    u = (2 * (w // 2 + 0.5) / w - 1) * fr.tan_half_fov * w / h
    v = (1 - 2 * (h // 2 + 0.5) / h) * fr.tan_half_fov
    cos = 1 / np.sqrt(1 + u * u + v * v)
    assert plan.path.focus == pytest.approx(float(r.depth[h // 2, w // 2]) * cos, rel=1e-3)
    assert resolve_focus(sc.replace(**{"camera.focus": 2.5}), plan.frame, plan.march) == 2.5


def test_depth_of_field_blurs_away_from_the_focus() -> None:
    sharp = pyjulia4d.render(scene(image={"samples": 32}))
    near = pyjulia4d.render(scene(image={"samples": 32}, camera={"aperture": 0.25, "focus": 1.0}))
    grad = lambda im: np.abs(np.diff(im.color.mean(axis=2), axis=1)).mean()
    assert grad(near) < 0.8 * grad(sharp)


def test_direct_renders_compile_and_keep_nothing_of_it() -> None:
    sc = Scene.from_dict({"image": {"width": 24, "height": 18}, "camera": {"fit": False}})
    plan = make_plan(sc, "CPU", 1)
    assert plan.path is None and plan.path_config is None
    assert not any(p.startswith("path/") for cfg in (plan.config, plan.march_config) for p in cfg.pieces)
    assert pyjulia4d.render(sc).film is None


def test_denoiser_brings_the_picture_closer_to_the_converged_one() -> None:
    pytest.importorskip("pyoidn")
    sc = scene(image={"samples": 4, "width": 64, "height": 48})
    noisy = pyjulia4d.render(sc)
    clean = pyjulia4d.render(sc.replace(**{"image.denoise": True}))
    ref = pyjulia4d.render(sc.replace(**{"image.samples": 256}))
    err = lambda im: np.sqrt(np.mean((im - ref.color) ** 2))
    assert np.array_equal(clean.film.noisy, noisy.color)
    assert err(clean.color) < 0.7 * err(noisy.color)


def test_direct_renders_ignore_the_path_keys() -> None:
    """Like shading.roughness or bounces, the lens and the denoiser are the path tracer's: a
    direct render of a scene that sets them is the pinhole picture it always was."""
    sc = Scene.from_dict({"image": {"width": 24, "height": 18}, "camera": {"fit": False}})
    plain = pyjulia4d.render(sc)
    lens = pyjulia4d.render(sc.replace(**{"camera.aperture": 0.3, "image.denoise": True}))
    assert np.array_equal(plain.color, lens.color)


def test_denoiser_without_its_extra_is_one_line(monkeypatch) -> None:
    import pyjulia4d.resources as resources
    monkeypatch.setattr(resources, "module_installed", lambda name: name != "pyoidn")
    with pytest.raises(SceneError, match=r"image.denoise: .*pip install 'pyjulia4d\[denoise\]'"):
        film.check_denoiser(scene(image={"denoise": True}))


def test_files_state_the_noise_and_keep_its_channels(tmp_path) -> None:
    import OpenEXR

    from pyjulia4d.app.output import read_header
    r = pyjulia4d.render(scene(image={"samples": 4, "tonemap": "agx"}))
    for suffix in (".png", ".exr"):
        r.save(tmp_path / f"p{suffix}")
        noise = read_header(tmp_path / f"p{suffix}")["pyjulia4d.noise"]
        assert "p50" in noise and "paths per pixel 4-4" in noise
    ch = OpenEXR.File(str(tmp_path / "p.exr"), separate_channels=True).channels()
    assert {"variance.R", "albedo.G", "noise.Y", "paths.Y"} <= set(ch)
    assert np.allclose(ch["noise.Y"].pixels, r.film.noise)
    assert np.allclose(ch["R"].pixels, r.color[..., 0])   # the EXR keeps linear light, not the tone map
    comp = pyjulia4d.render(scene(image={"samples": 4, "exr": "compositing"}))
    comp.save(tmp_path / "c.exr")
    names = set(OpenEXR.File(str(tmp_path / "c.exr"), separate_channels=True).channels())
    assert {"ViewLayer.Variance.R", "ViewLayer.Denoising Albedo.B"} <= names


def _exr(path, img) -> None:
    import OpenImageIO as oiio
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(img.shape[1], img.shape[0], img.shape[2], "float"))
    out.write_image(np.ascontiguousarray(img, np.float32))
    out.close()


@pytest.mark.parametrize("integrator", ["path", "direct"])
@pytest.mark.parametrize("case, reason", [
    ("missing", "cannot read it"), ("truncated", "cannot read its pixels|not an image"), ("text", "not an image"),
    ("square", "not an equirectangular map"), ("negative", "not light"), ("nan", "not light"),
    ("too bright", "light is 0 to 1e"),
])
def test_a_bad_environment_file_is_one_line_before_the_render(tmp_path, case, reason, integrator) -> None:
    """Refused before any kernel runs, with the direct integrator too, which takes no light from
    the map: a scene naming a file it cannot use is wrong whatever renders it."""
    path = tmp_path / "env.exr"
    if case == "truncated":
        _exr(path, np.ones((64, 128, 3)))
        path.write_bytes(path.read_bytes()[:600])
    elif case == "text":
        path.write_text("not an image")
    elif case == "square":
        _exr(path, np.ones((32, 32, 3)))
    elif case in ("negative", "nan", "too bright"):
        img = np.ones((16, 32, 3))
        img[3, 4, 1] = {"negative": -1.0, "nan": np.nan, "too bright": 1.5e9}[case]
        _exr(path, img)
    sc = scene(shading={"environment": str(path), "integrator": integrator})
    with pytest.raises(SceneError, match=reason) as info:
        pyjulia4d.render(sc)
    assert info.value.key == "shading.environment" and "\n" not in str(info.value)


def test_the_brightest_map_states_a_finite_noise(tmp_path) -> None:
    """A map at its brightest (environment.MAX_RADIANCE), under the brightest ambient and sky the
    keys take: every pixel's colour, variance and stated noise finite, and the noise not 0 where
    paths differ (a map of 1e20 overflowed the film's squared deviations, and stated 0)."""
    from pyjulia4d.pipeline.environment import MAX_RADIANCE
    path = tmp_path / "env.exr"
    img = np.full((16, 32, 3), 1e-3)
    img[2:5, 8:12] = MAX_RADIANCE   # a small, very bright sun: paths that find it and paths that do not
    _exr(path, img)
    r = pyjulia4d.render(scene(image={"samples": 8}, shading={"environment": str(path), "ambient": 1e3,
                                                              "sky": [1e3, 1e3, 1e3]}))
    assert np.isfinite(r.color).all() and np.isfinite(r.film.variance).all() and np.isfinite(r.film.noise).all()
    assert r.film.noise_stats()["p99"] > 0


@pytest.mark.parametrize("integrator", ["path", "direct"])
def test_a_bad_environment_on_the_command_line(tmp_path, capsys, integrator) -> None:
    from pyjulia4d.app import cli
    out = tmp_path / "x.png"
    code = cli.main(["render", "--set", f"shading.integrator={integrator}", "--set",
                     f"shading.environment={tmp_path}/no.hdr", "--set", "image.width=8", "--set", "image.height=6",
                     "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "shading.environment" in err
    assert list(tmp_path.iterdir()) == []


def test_the_environment_key_takes_words_and_image_paths() -> None:
    for bad in ("", "sky.png", 3, "a\nb.exr"):
        with pytest.raises(SceneError, match="shading.environment"):
            scene(shading={"environment": bad})
    assert scene(shading={"environment": "x/y.HDR"}).shading.environment == "x/y.HDR"
