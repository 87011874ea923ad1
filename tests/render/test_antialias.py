"""Supersampling (image.samples): stratified jittered rays (rays.cl sample_offset) against
the float64 reference, determinism, and outputs other than RGBA from the pixel centres."""
import numpy as np
import pytest

from pyjulia4d import reference as ref
from pyjulia4d.opencl.executor import render
from pyjulia4d.scene.model import Scene

SMALL = ["image.width=40", "image.height=30"]


def test_sample_offsets_are_stratified():
    # sample k of n lies in cell (k mod g, k div g) of the g x g grid over the pixel
    x, y = np.meshgrid(np.arange(50), np.arange(40))
    for n in (2, 4, 9, 10):
        g = int(np.ceil(np.sqrt(n)))
        for k in range(n):
            ox, oy = ref.sample_offset(x.ravel(), y.ravel(), k, n)
            assert np.all((ox >= (k % g) / g) & (ox < (k % g + 1) / g))
            assert np.all((oy >= (k // g) / g) & (oy < (k // g + 1) / g))
    # and spread inside their cell: no pattern shared by all pixels
    ox, _ = ref.sample_offset(x.ravel(), y.ravel(), 0, 4)
    assert np.std(ox) > 0.1


@pytest.mark.parametrize("over", [[], ["fractal.algebra=hypercomplex", "fractal.c=-0.123,0,-0.745,0",
                                       "camera.position=1.7,5.7,-5.7", "camera.fov=15"]])
def test_supersampled_colour_matches_reference(over):
    s = Scene.default().with_overrides(SMALL + over + ["image.samples=4"])
    k, r = render(s), ref.render(s)
    # an edge pixel's mean depends on which samples hit: a sample flipping between float32
    # and float64 moves it by up to 1/4; most pixels agree to float32 shading
    dc = np.abs(k.color - r.color).max(axis=-1)
    assert np.median(dc) < 1e-3 and np.mean(dc < 0.3) > 0.99
    np.testing.assert_allclose(k.alpha.mean(), r.alpha.mean(), atol=0.01)
    # partial coverage shows on the silhouette
    assert np.any((k.alpha > 0) & (k.alpha < 1))


def test_supersampling_is_deterministic_and_keeps_the_centres():
    s1 = Scene.default().with_overrides(SMALL)
    s4 = s1.with_overrides(["image.samples=4"])
    a, b, c = render(s4), render(s4), render(s1)
    np.testing.assert_array_equal(a.color, b.color)
    for name in ("depth", "normal", "position", "status", "bracket"):
        np.testing.assert_array_equal(getattr(a, name), getattr(c, name), err_msg=name)
    assert a.counts == c.counts


# ---------------------------------------------------------------- adaptive (image.adaptive)

from pyjulia4d.pipeline import antialias  # noqa: E402
from pyjulia4d.pipeline.colormap import srgb_to_linear  # noqa: E402
from pyjulia4d.scene.checks import SceneError  # noqa: E402

HYPER = ["fractal.algebra=hypercomplex", "fractal.c=-0.123,0,-0.745,0", "camera.position=1.7,5.7,-5.7",
         "camera.fov=15"]


def _linear(srgb):
    return srgb_to_linear(np.asarray(srgb, np.float64))


def test_flag_rule_steps_in_srgb_and_alpha_over_8_neighbours():
    t = antialias.THRESHOLD
    # a vertical step of 1.5 thresholds in sRGB flags the columns either side of it, one of
    # 0.5 threshold none - in the darks, where the same linear step is 10x larger in sRGB
    for step, flagged in ((1.5 * t, True), (0.5 * t, False)):
        srgb = np.full((6, 8, 3), 0.05)
        srgb[:, 4:, 1] += step
        f = antialias.flag_edges(_linear(srgb), np.ones((6, 8)))
        assert f[:, 3:5].all() == flagged and not f[:, [0, 1, 2, 5, 6, 7]].any()
    # one hit pixel in a miss: its 3x3 neighbourhood (8-neighbours) and nothing else
    a = np.zeros((7, 7))
    a[3, 3] = 1.0
    f = antialias.flag_edges(None, a)
    assert f[2:5, 2:5].all() and f.sum() == 9
    # the float64 twin, written apart, flags the same pixels of a random picture
    rng = np.random.default_rng(1)
    c, a = rng.random((20, 30, 3)) ** 3, (rng.random((20, 30)) > 0.3).astype(float)
    c[rng.random((20, 30)) > 0.2] = 0.3   # flat patches: unflagged pixels too
    a[:] = np.where(rng.random((20, 30)) > 0.1, 1.0, a)
    f = antialias.flag_edges(c, a)
    assert 0.1 < f.mean() < 0.95
    np.testing.assert_array_equal(f, ref.flag_edges(c, a, t))


def test_block_tiles_cover_the_flagged_blocks_alone(monkeypatch):
    monkeypatch.setattr(antialias, "BLOCK", 8)   # several blocks in a small region
    rng = np.random.default_rng(2)
    region, W, H = (5, 3, 37, 29), 50, 40
    flags = rng.random((29, 37)) > 0.97
    tiles = antialias.block_tiles(flags, region, W, H, halo=1, most=400)
    cover = np.zeros((H, W), int)
    for t in tiles:
        cover[t.dst()] += 1
        assert t.n <= 400 or t.w <= antialias.BLOCK
    b = antialias.BLOCK
    want = np.zeros((H, W), int)
    for y in range(0, 29, b):
        for x in range(0, 37, b):
            if flags[y:y + b, x:x + b].any():
                want[3 + y:3 + min(y + b, 29), 5 + x:5 + min(x + b, 37)] = 1
    np.testing.assert_array_equal(cover, want)   # each flagged block once, nothing else
    assert len(tiles) < int(want.sum()) // (b * b)   # neighbouring blocks merged


def test_adaptive_key_is_checked():
    assert Scene.default().image.adaptive is False
    assert Scene.default().with_overrides(["image.adaptive=true"]).image.adaptive is True
    with pytest.raises(SceneError, match="image.adaptive"):
        Scene.default().with_overrides(["image.adaptive=1"])


@pytest.mark.parametrize("over", [[], HYPER])
def test_adaptive_is_the_mean_where_flagged_and_the_centre_elsewhere(over):
    s1 = Scene.default().with_overrides(SMALL + over)
    s4 = s1.with_overrides(["image.samples=4"])
    sa = s4.with_overrides(["image.adaptive=true"])
    c, u, a, a2 = render(s1), render(s4), render(sa), render(sa)
    f = antialias.flag_edges(c.color, c.alpha)
    assert 0.05 < f.mean() < 0.9   # some pixels of each kind
    # bit for bit: the samples of a pixel do not depend on the tiles they ran in
    np.testing.assert_array_equal(a.color, np.where(f[..., None], u.color, c.color))
    np.testing.assert_array_equal(a.alpha, np.where(f, u.alpha, c.alpha))
    np.testing.assert_array_equal(a.color, a2.color)   # deterministic
    for name in ("depth", "normal", "position", "status", "bracket"):
        np.testing.assert_array_equal(getattr(a, name), getattr(c, name), err_msg=name)
    assert a.counts == c.counts


def test_adaptive_with_every_pixel_flagged_is_the_uniform_image(monkeypatch):
    s4 = Scene.default().with_overrides(SMALL + ["image.samples=3"])
    u = render(s4)
    monkeypatch.setattr(antialias, "THRESHOLD", -1.0)   # every neighbour differs
    a = render(s4.with_overrides(["image.adaptive=true"]))
    np.testing.assert_array_equal(a.color, u.color)
    np.testing.assert_array_equal(a.alpha, u.alpha)


def test_an_adaptive_region_renders_as_the_same_pixels_of_the_whole():
    # the region's border pixels are flagged from neighbours outside it (antialias.ring);
    # Z-buffer normals need the tiles' halo
    s = Scene.default().with_overrides(["image.width=70", "image.height=50", "image.samples=4",
                                        "image.adaptive=true", "normals.method=zbuffer"])
    whole = render(s, tile=16)
    part = render(s, tile=16, region=(13, 7, 40, 30))
    np.testing.assert_array_equal(whole.color[7:37, 13:53], part.color)
    np.testing.assert_array_equal(whole.alpha[7:37, 13:53], part.alpha)


@pytest.mark.parametrize("over", [[], HYPER])
def test_adaptive_colour_matches_reference(over):
    s1 = Scene.default().with_overrides(SMALL + over)
    sa = s1.with_overrides(["image.samples=4", "image.adaptive=true"])
    k1, r1 = render(s1), ref.render(s1)
    k, r = render(sa), ref.render(sa)
    # the flags come from float32 and float64 centres: a pixel whose neighbour step sits at
    # the threshold, or whose centre ray flips hit/miss, may be flagged by one alone
    fk = antialias.flag_edges(k1.color, k1.alpha)
    fr = ref.flag_edges(r1.color, r1.alpha, antialias.THRESHOLD)
    assert np.mean(fk == fr) > 0.98
    # as for uniform supersampling: a sample flipping moves an edge pixel by up to 1/4;
    # most pixels agree to float32 shading
    dc = np.abs(k.color - r.color).max(axis=-1)
    assert np.median(dc) < 1e-3 and np.mean(dc < 0.3) > 0.99
    np.testing.assert_allclose(k.alpha.mean(), r.alpha.mean(), atol=0.01)


def test_progress_total_is_the_adaptive_work(monkeypatch):
    import sys

    from pyjulia4d.opencl import passes as rmod   # where the passes drive their progress

    bars = []

    class Bar:   # the progress render() drives (pipeline/progress.Progress): its total and what was done
        def __init__(self, total, *args, **kwargs):
            self.total, self.n = total, 0
            bars.append(self)

        def update(self, k, note=""):
            self.n += k

        def set_total(self, total):
            self.total = total

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return None

    monkeypatch.setattr(rmod, "Progress", Bar)
    monkeypatch.setattr(antialias, "BLOCK", 8)   # blocks of background in a small image
    s = Scene.default().with_overrides(SMALL + ["image.samples=4", "image.adaptive=true"])
    render(s, calibrate=False)
    render(s, calibrate=False, region=(5, 4, 20, 20))
    (whole, part) = bars
    assert whole.n == whole.total < 40 * 30 * 5   # the blocks alone, not every pixel 4 times
    assert part.n == part.total   # the ring around the region counted too


def test_antialias_benchmark_runs(tmp_path):
    """benchmarks/accuracy/antialias_error.py, tiny, so that it cannot rot."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "benchmarks" / "accuracy" / "antialias_error.py"
    spec = importlib.util.spec_from_file_location("antialias_error", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--size", "40x30", "--repeats", "1", "--scenes", "default", "--thresholds", "16",
                     "--out", str(tmp_path)]) == 0
    assert antialias.THRESHOLD == 1.0 / 64.0   # restored
    md = (tmp_path / "antialias.md").read_text()
    assert "commit " in md and "| 9 adaptive |" in md and "| 4 adaptive, threshold 1/16 |" in md
    rows = [line.split("|") for line in md.splitlines() if line.startswith("| 1 |")]
    assert len(rows) == 1 and float(rows[0][7]) == 1.0   # the ratios are to one sample
