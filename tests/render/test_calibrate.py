"""calibrate.py: a probe render of the scene predicts the render's time; the prediction
refuses, warns and sizes the tiles, so that Ctrl-C is honoured within a second."""
import signal
import subprocess
import sys
import time
import warnings

import pytest

from harness import device
from pyjulia4d.pipeline import calibrate, workload
from pyjulia4d.opencl.executor import render
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError

# one scene or two of each march method and of the costly options, 200-600 ms each here
SCENES = {
    "de": ["image.width=640", "image.height=480"],
    "de-cube-maxiter30": ["fractal.function=cube", "fractal.c=-0.5,0.3,0.2,0", "fractal.max_iter=30",
                          "image.width=480", "image.height=360"],
    "fixed": ["march.method=fixed", "march.z_resolution=3000", "image.width=320", "image.height=240"],
    "fixed-hypercomplex-sin": ["fractal.algebra=hypercomplex", "fractal.function=sin",
                               "march.z_resolution=800", "image.width=320", "image.height=240"],
    "fixed-zbuffer": ["march.method=fixed", "normals.method=zbuffer", "march.z_resolution=1500",
                      "image.width=320", "image.height=240"],
    "de-samples": ["image.samples=3", "image.width=400", "image.height=300"],
}


@pytest.mark.parametrize("name", SCENES)
def test_prediction_within_a_factor_of_3(name, monkeypatch):
    """The probe (about 2048 pixels in 8x8 blocks) against the kernel time of the render
    itself: the issue's bar is a factor of 3; measured here 0.5-2 (README, Performance).
    These renders are short enough to skip the probe: it is asked for here.  The probe takes
    a few milliseconds, so a moment's preemption on a busy machine (the test suite's other
    worker) moves one prediction by more than that factor (once 0.20 where the same scene
    gives 0.62 quietly and 0.9-1.2 under steady load): the median of three renders' ratios
    is held to it."""
    monkeypatch.setattr(calibrate, "SKIP_BELOW_SECONDS", 0.0)
    s = Scene.from_dict({}, SCENES[name])
    render(s, device=device())    # programs built, the framing pass cached out of the timing
    ratios = []
    for _ in range(3):
        r = render(s, device=device())
        p = r.prediction
        assert p is not None and p.probe_pixels >= 1024
        ratios.append(r.kernel_seconds / p.seconds)
    assert 1 / 3 <= sorted(ratios)[1] <= 3, ratios


def test_probe_blocks_lie_in_the_region_and_spread_over_it():
    s = Scene.from_dict({"camera": {"fit": False}}, ["image.width=1000", "image.height=300"])
    from pyjulia4d.pipeline.plan import make_plan
    for region in (None, (100, 50, 300, 200), (0, 0, 5, 3)):
        plan = make_plan(s, "CPU", 16, region=region)
        tiles = calibrate.probe_tiles(plan)
        x0, y0, w, h = plan.region
        assert all(x0 <= t.x0 and t.x0 + t.w <= x0 + w and y0 <= t.y0 and t.y0 + t.h <= y0 + h for t in tiles)
        n = sum(t.w * t.h for t in tiles)
        assert n <= w * h and (n >= 1024 or n == w * h)
        if region is None:   # both ends of the wide image are sampled
            assert min(t.x0 for t in tiles) < 100 and max(t.x0 for t in tiles) > 900


def test_the_probe_is_skipped_only_where_the_bound_is_short(monkeypatch):
    """No probe where even the upper bound of the work is below SKIP_BELOW_SECONDS and the
    warning's threshold; a render it would warn about is probed, however short."""
    s = Scene.from_dict({}, ["image.width=160", "image.height=120"])
    bound = workload.estimate(s).seconds
    assert bound < calibrate.SKIP_BELOW_SECONDS and not calibrate.wanted(bound)
    assert render(s, device=device()).prediction is None
    monkeypatch.setattr(calibrate, "WARN_SECONDS", 1e-6)
    assert calibrate.wanted(bound)
    with pytest.warns(RuntimeWarning, match="this render will take"):
        assert render(s, device=device()).prediction is not None
    assert calibrate.wanted(calibrate.SKIP_BELOW_SECONDS * 1.01)


def test_tiles_are_sized_by_the_prediction():
    p = calibrate.Prediction(seconds=100.0, seconds_per_pixel=1e-4, probe_pixels=2048, probe_seconds=0.2)
    side = calibrate.tile_side(p, 512)
    assert side % calibrate.MIN_TILE == 0 and side * side * 1e-4 <= calibrate.TILE_SECONDS
    fast = calibrate.Prediction(seconds=1.0, seconds_per_pixel=1e-8, probe_pixels=2048, probe_seconds=0.0)
    assert calibrate.tile_side(fast, 512) == 512
    slow = calibrate.Prediction(seconds=1e5, seconds_per_pixel=1.0, probe_pixels=2048, probe_seconds=2048)
    assert calibrate.tile_side(slow, 512) == calibrate.MIN_TILE


def test_the_1080p_default_renders_without_a_warning():
    """The bound said ~0.4 h for this render of about a second."""
    s = Scene.from_dict({}, ["image.width=1920", "image.height=1080"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = render(s, device=device())
    assert r.prediction is not None and r.prediction.seconds < calibrate.WARN_SECONDS


def test_a_long_render_warns_and_a_longer_one_is_refused_from_the_probe(monkeypatch):
    s = Scene.from_dict({}, ["march.method=fixed", "march.z_resolution=4000", "image.width=200",
                             "image.height=150"])
    monkeypatch.setattr(calibrate, "WARN_SECONDS", 1e-3)
    with pytest.warns(RuntimeWarning, match=r"^march\.z_resolution: 4000: this render will take about "
                                            r".* \(predicted from a probe render of \d+ of its pixels"):
        render(s, device=device())
    monkeypatch.setattr(calibrate, "REFUSE_SECONDS", 1e-3)
    with pytest.raises(SceneError, match=r"^march\.z_resolution: 4000 would take about .* over the limit"):
        render(s, device=device())
    with pytest.warns(RuntimeWarning):
        render(s, device=device(), force=True)   # force renders it, and still says how long


def test_work_the_probe_cannot_afford_is_refused_by_the_bound_instantly():
    s = Scene.from_dict({}, ["march.method=fixed", "march.z_resolution=100000000", "image.width=640",
                             "image.height=480"])
    t0 = time.perf_counter()
    with pytest.raises(SceneError, match=r"^march\.z_resolution: 100000000 could take .*upper bound"):
        render(s, device=device())
    assert time.perf_counter() - t0 < 1.0
    assert workload.probe_iterations(s, workload.estimate(s)) > workload.PROBE_LIMIT_ITERATIONS


def test_ctrl_c_stops_a_long_render_within_a_second(tmp_path):
    """A render of ~10 s here, interrupted after 2 s: tiles of about calibrate.TILE_SECONDS,
    two in flight, so the interrupt waits for at most two of them (measured 0.3-0.9 s)."""
    p = subprocess.Popen([sys.executable, "-m", "pyjulia4d", "render", "--set", "march.method=fixed",
                          "--set", "march.z_resolution=40000", "-o", str(tmp_path / "x.png")],
                         stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    time.sleep(2.5)
    assert p.poll() is None, p.stderr.read()
    t0 = time.perf_counter()
    p.send_signal(signal.SIGINT)
    rc = p.wait(timeout=30)
    latency = time.perf_counter() - t0
    assert rc == 130 and "interrupted" in p.stderr.read()
    assert latency < 1.0, latency
    assert list(tmp_path.iterdir()) == []
