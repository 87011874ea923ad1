"""CI smoke run of benchmarks/accuracy/error_vs_time.py --quick, so the benchmark cannot rot."""
import csv
import importlib.util
import subprocess
import sys
from pathlib import Path
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def script(name: str) -> Path:
    """A benchmark script by name, in whichever family's folder it sits (benchmarks/<family>/)."""
    (path,) = (ROOT / "benchmarks").glob(f"*/{name}.py")
    return path


def load_benchmark():
    spec = importlib.util.spec_from_file_location("error_vs_time", script("error_vs_time"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_quick_run_writes_sane_results(tmp_path):
    bench = load_benchmark()
    assert bench.main(["--quick", "--out", str(tmp_path)]) == 0
    with open(tmp_path / "error_vs_time.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert rows and set(bench.COLUMNS) <= set(rows[0])
    assert {r["scene"] for r in rows} == set(bench.QUICK_SCENES)
    assert {r["method"] for r in rows} == {"fixed", "de"}
    for r in rows:
        assert float(r["kernel_s"]) > 0 and float(r["render_s"]) >= float(r["kernel_s"])
        assert 0 <= float(r["silhouette_err"]) <= 1
        assert 0 <= float(r["depth_err_median"]) <= float(r["depth_err_p99"]) <= float(r["depth_err_max"]) < 1
        for m in bench.NORMAL_METHODS:
            assert 0 <= float(r[f"normal_err_{m}_median"]) <= 180
        assert r["device"] and r["commit"] and r["date"]
        assert r["refine"] == "itp"
        # the render's own certified bracket is recorded beside the error, and checked against the truth
        assert 0 <= float(r["bracket_p50"]) <= float(r["bracket_p99"]) <= float(r["bracket_max"])
        assert 0 <= int(r["stepped_over"]) <= int(r["n_both"]) and int(r["after_bracket"]) >= 0
    # post-stepping makes the fixed scan's depth more accurate (Ödegaard & Wennergren eq. 12); on the
    # real-c scene (on the c = 0 ball the bounding sphere is the surface: no bracket to narrow)
    real = {(r["method"], r["post_steps"]): float(r["depth_err_median"]) for r in rows if r["scene"] == "real"}
    assert real[("fixed", "10")] < real[("fixed", "0")] / 100
    md = (tmp_path / "error_vs_time.md").read_text()
    assert "device:" in md and "commit:" in md and "| method | refine | z_res |" in md
    assert (tmp_path / "error_vs_time.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_extreme_cases_report_runs(tmp_path):
    """benchmarks/accuracy/extreme_cases.py on two catalogue cases, tiny, so the report cannot rot."""
    spec = importlib.util.spec_from_file_location("extreme_cases", script("extreme_cases"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--only", "c_zero", "epsilon_below_ulp", "--scale", "1", "--repeats", "1",
                     "--out", str(tmp_path)]) == 0
    with open(tmp_path / "extreme_cases.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert {(r["case"], r["method"]) for r in rows} == {(c, m) for c in ("c_zero", "epsilon_below_ulp")
                                                       for m in ("fixed", "de")}
    assert all(r["verdict"] == "ok" and r["nan_inf32"] == "0" and r["nan_inf64"] == "0" for r in rows)
    md = (tmp_path / "extreme_cases.md").read_text()
    assert "commit `" in md and "| epsilon_below_ulp | de |" in md and "ulp_step=" in md


def test_preset_check_runs(tmp_path):
    """benchmarks/accuracy/preset_check.py on two unseen scenes, tiny, so the check cannot rot."""
    spec = importlib.util.spec_from_file_location("preset_check", script("preset_check"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--n", "2", "--seeds", "2027", "--width", "16", "--height", "12", "--z-start", "1000", "--time-default", "0",
                     "--out", str(tmp_path)]) == 0
    with open(tmp_path / "preset_check.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2 * 3 and {r["quality"] for r in rows} == {"draft", "normal", "final"}
    assert [r["kind"] for r in rows[::3]] == ["boundary", "dust"]
    for r in rows:
        assert r["commit"] and r["device"] and r["date"]
        assert int(r["max_iter"]) == 12 and float(r["truth_hit"]) >= mod.MIN_HIT
        assert r["p99_held"] in ("True", "False") and 0 <= float(r["silhouette_err"]) <= 1
        assert float(r["bracket_p99"]) >= 0 and int(r["stepped_over"]) >= 0
    md = (tmp_path / "preset_check.md").read_text()
    assert "commit: `" in md and "| quality | stated p99 |" in md and "| 2027_s01_dust |" in md


def load(name):
    spec = importlib.util.spec_from_file_location(name, script(name))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_iteration_counter_counts_exactly():
    """benchmarks/speed/throughput.py's -D COUNT_ITERATIONS build: with the eye inside the c = 0
    set every ray's first set test is inside, after exactly max_iter iterations of f."""
    from harness import device
    from pyjulia4d.scene.model import Scene

    tp = load("throughput")
    s = Scene.default().with_overrides(["fractal.c=0,0,0,0", "fractal.max_iter=37", "march.method=fixed",
                                        "march.post_steps=0", "camera.position=0.1,0.1,0.1,0",
                                        "image.width=9", "image.height=7"])
    r = tp.march_throughput(s, device(), repeats=1)
    assert r["iterations"] == 9 * 7 * 37 and r["hit"] == 1.0


@pytest.mark.slow   # builds a program per packet width and precision (~9 s from cold)
def test_throughput_report_runs(tmp_path):
    tp = load("throughput")
    assert tp.main(["--size", "16x12", "--repeats", "1", "--widths", "1,4", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "throughput.md").read_text()
    assert "| single | float4 |" in md and "iterations/s" in md and "commit" in md


def test_peers_report_runs(tmp_path, monkeypatch):
    """benchmarks/peers/peers.py, tiny: POV-Ray where installed (skipped with a message otherwise),
    pyjulia4d always; the POV-Ray scene is the default scene.  Mandelbulber2 is left out
    here (its OpenCL warm-ups took most of this test's 13 s from cold caches); `-m slow`
    runs it in test_peers_report_runs_with_mandelbulber."""
    peers = load("peers")
    which = peers.shutil.which
    monkeypatch.setattr(peers.shutil, "which", lambda name: None if name == "mandelbulber2" else which(name))
    src = peers.pov_scene(16, 12)
    assert "<-0.2, 0.8, 0.0, 0.0>" in src and "max_iteration 12" in src and "location <1.8, 1.6, -2.2>" in src
    assert peers.main(["--size", "16x12", "--repeats", "1", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "peers.md").read_text()
    assert "| pyjulia4d default |" in md and "pixels per CPU-second" in md


def test_peer_error_counts_wrong_pixels():
    """benchmarks/peers/peer_error.py's error of a row, on hand-made depths: a silhouette
    disagreement is wrong at any tolerance, a depth error is wrong past its share of a pixel."""
    import numpy as np

    pe = load("peer_error")
    inf = np.inf
    truth = np.array([1.0, 2.0, 3.0, inf, 4.0])
    pixel = np.full(5, 1e-2)                     # one pixel's worth of depth everywhere
    depth = np.array([[1.0, 2.0005, 3.05, 1.0, inf]])   # exact, 0.05 px, 5 px, false hit, missed
    e = pe.errors(depth, np.arange(5), truth, pixel)
    assert e["sil"] == 0.4
    assert e["wrong01"] == 0.6 and e["wrong1"] == 0.6   # the 5 px error and both silhouette errors
    depth[0, 1] = 2.002                                  # 0.2 px: wrong at 0.1 px, not at 1 px
    e = pe.errors(depth, np.arange(5), truth, pixel)
    assert e["wrong01"] == 0.8 and e["wrong1"] == 0.6
    assert abs(e["p50"] - 0.002) < 1e-12 and e["p99"] > e["p90"] > e["p50"]
    assert pe.as_good(e, e) and not pe.as_good(e, dict(e, wrong1=0.5))


def test_peer_error_settings_follow_the_pair():
    """Every setting peer_error.py runs on a scene is one the scene's pair renders: no
    distance-estimate march where the pair has no estimate (the command refuses it), the
    coarser scans there instead; the scene's default first (the plot stars it)."""
    from pyjulia4d.scene.model import Scene
    from pyjulia4d.scene.checks import SceneError

    pe = load("peer_error")
    quat = pe.settings_for(Scene.default())
    assert quat == pe.SETTINGS
    for fn in ("exp", "sin", "ln", "pwr"):
        scene = Scene.default().with_overrides(["fractal.algebra=hypercomplex", f"fractal.function={fn}"])
        got = pe.settings_for(scene)
        assert next(iter(got)) == next(iter(pe.SETTINGS))
        assert set(pe.FIXED_SETTINGS) <= set(got) and "draft (proven)" in got
        for over in got.values():
            scene.with_overrides(over)   # a SceneError where the pair cannot
        with pytest.raises(SceneError):
            scene.with_overrides(pe.SETTINGS["de, epsilon 1e-2"])


def test_peer_error_reads_povray_depth_to_the_mathematics(tmp_path):
    """POV-Ray's depth as benchmarks/peers/peer_error.py reads it (a distance pigment in two 16-bit
    channels) against the float64 brute force of the same set: at precision 1000 POV-Ray
    steps over nothing at this size, so every pixel both hit agrees to 1e-6 (its bisection
    polishes to within the readout's 2e-7) - which checks the encoding, the decoding and the view mapping."""
    import shutil

    import numpy as np

    if shutil.which("povray") is None:
        pytest.skip("povray not installed (Debian: apt-get install povray)")
    pe = load("peer_error")
    from pyjulia4d import reference as ref
    from pyjulia4d.geometry.camera import camera_frame
    from pyjulia4d.interop.povray import import_pov
    from pyjulia4d.measure.brute_force import brute_force_depth

    w, h = 32, 24
    text = pe.pov_matched(w, h, 1000)
    (tmp_path / "s.pov").write_text(text)
    scene = import_pov(tmp_path / "s.pov", w, h).scene
    o, d = ref.generate_rays(camera_frame(scene), w, h)
    idx = np.arange(0, w * h, 5)
    truth = brute_force_depth(scene, o[idx], d[idx])
    hit = np.isfinite(truth)
    assert 0.2 < hit.mean() < 0.8
    depth = pe.pov_depth(text, w, h, tmp_path, float(truth[hit].min()) - 0.5, float(truth[hit].max()) + 0.5)
    got = depth.ravel()[idx]
    assert np.array_equal(np.isfinite(got), hit)
    assert np.max(np.abs(got[hit] - truth[hit])) < 1e-6


@pytest.mark.slow   # a child process per setting
def test_peer_error_report_runs(tmp_path, monkeypatch):
    from PIL import Image

    pe = load("peer_error")
    monkeypatch.setattr(pe, "PRECISIONS", (20,))
    monkeypatch.setattr(pe, "SETTINGS", {k: pe.SETTINGS[k] for k in list(pe.SETTINGS)[:2]})
    assert pe.main(["--size", "32x24", "--repeats", "1", "--renders", "1", "--samples", "100",
                    "--out", str(tmp_path)]) == 0
    md = (tmp_path / "peer_error.md").read_text()
    assert "| default (march.quality auto) |" in md and "default march here: the distance estimate" in md and "wrong by > 0.1 px" in md
    assert pe.main(["--size", "32x24", "--repeats", "1", "--renders", "1", "--samples", "100", "--look", "default",
                    "--scenes", "matched", "--out", str(tmp_path)]) == 0
    assert "pyjulia4d's default look" in (tmp_path / "peer_error.md").read_text()
    for png in ("peer_error.png", "peer_error_default_look.png"):
        with Image.open(tmp_path / png) as im:
            assert im.size[0] > 300 and im.size[1] > 300
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]   # no temporary file left
    assert pe.peers.LOOK == pe.peers.MATCHED and pe.LOOK == []


@pytest.mark.slow   # Mandelbulber2's OpenCL warm-ups
def test_peers_report_runs_with_mandelbulber(tmp_path):
    import shutil

    if shutil.which("mandelbulber2") is None:
        pytest.skip("mandelbulber2 not installed (Debian: apt-get install mandelbulber2)")
    peers = load("peers")
    assert peers.main(["--size", "16x12", "--repeats", "1", "--out", str(tmp_path)]) == 0
    assert "| Mandelbulber2 2.20 CPU" in (tmp_path / "peers.md").read_text()


@pytest.mark.slow   # a child per CPU runtime, each building from cold: the longest test of the default run
def test_cpu_runtimes_benchmark_runs(tmp_path, capsys):
    """benchmarks/speed/cpu_runtimes.py on one pair, tiny: a table row per pair with every CPU
    device that compiles, and the results file with its commit and devices."""
    spec = importlib.util.spec_from_file_location("cpu_runtimes", script("cpu_runtimes"))
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.main(["--only", "quaternion_sqr", "--size", "24x18", "--repeats", "1", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith("| quaternion_sqr |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    n = (len(cells) - 2) // 2   # kernel and first-build columns per device, then the ratio
    # kernel times (may print 0.000 at this size), then first renders, which build: > 0
    assert n >= 1 and all(float(c) >= 0 for c in cells[1:1 + n]) and all(float(c) > 0 for c in cells[1 + n:1 + 2 * n])
    text = (tmp_path / "cpu_runtimes.md").read_text()
    assert "commit" in text and "Devices:" in text and "| quaternion_sqr |" in text
    assert set(bench.pairs()) >= {f"{a}_{f}" for a, fs in __import__("pyjulia4d").scene.FUNCTIONS_OF.items() for f in fs}


def test_pair_accuracy_benchmark_runs(tmp_path, capsys):
    """benchmarks/accuracy/pair_accuracy.py on one pair, tiny: its row, and the verdict for the c = 0
    ball, whose every number is known (a ball is as accurate as any render reports)."""
    spec = importlib.util.spec_from_file_location("pair_accuracy", script("pair_accuracy"))
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert len(bench.pairs()) == 24
    assert bench.main(["--only", "quaternion_sqr", "--size", "24x18", "--set", "fractal.c=0,0,0,0",
                       "--set", "fractal.max_iter=3", "--out", str(tmp_path)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("| quaternion sqr |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == "de" and cells[4] == "0.00 %" and cells[5] == "0.00 %" and cells[6] == "0.00 %" and cells[7] == "yes"
    assert "commit" in (tmp_path / "pair_accuracy.md").read_text()


def test_proven_speed_benchmark_runs(tmp_path, capsys):
    """benchmarks/speed/proven_speed.py on the quaternion default, tiny: a row per march, the fixed
    scan the kernels' unit, the estimate the CPU-seconds', the proven march's share of proofs given."""
    spec = importlib.util.spec_from_file_location("proven_speed", script("proven_speed"))
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.main(["--only", "quaternion sqr (default)", "--size", "24x18", "--repeats", "1",
                       "--out", str(tmp_path)]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| quaternion sqr")]
    assert len(rows) == 5   # the device's width, 8 and 16 lanes, the scan, the estimate
    cells = {r.split("|")[2].strip(): [c.strip() for c in r.strip("|").split("|")] for r in rows}
    assert cells["fixed, z_resolution 1000"][3] == "1.00"
    assert cells["custom (the estimate, else the scan at 250)"][5] == "1.00"   # the CPU-seconds' unit
    assert float(cells["proven, quality normal"][4]) > 0
    assert cells["proven, quality normal"][9].endswith("%") and cells["fixed, z_resolution 1000"][9] == ""
    assert "commit" in (tmp_path / "proven_speed.md").read_text()


def test_pair_error_vs_time_benchmark_runs(tmp_path, capsys):
    """benchmarks/accuracy/pair_error_vs_time.py on the c = 0 ball, tiny: a row per setting (the
    estimate too, which quaternions have), the fixed scan at 1000 its own unit, the proven
    presets stating less than the whole ray, and the csv and plot written."""
    spec = importlib.util.spec_from_file_location("pair_error_vs_time", script("pair_error_vs_time"))
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.settings_for({"algebra": "hypercomplex", "function": "sin"}, bench.SETTINGS) == [
        n for n in bench.SETTINGS if n != "de"]
    assert bench.main(["--only", "quaternion_sqr", "--size", "16x12", "--repeats", "1",
                       "--settings", "fixed 1000", "de", "normal", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    rows = {r.split("|")[1].strip(): [c.strip() for c in r.strip("|").split("|")]
            for r in out.splitlines() if r.startswith("| ") and r.split("|")[2].strip() in ("fixed", "de", "proven")}
    assert set(rows) == {"fixed 1000", "de", "normal"}
    assert rows["fixed 1000"][3] == "1.00"
    assert float(rows["normal"][4]) < 0.01 < float(rows["fixed 1000"][4])   # proven: less than the whole ray
    assert "commit" in (tmp_path / "pair_error_vs_time.md").read_text()
    assert (tmp_path / "pair_error_vs_time.png").stat().st_size > 0
    assert len((tmp_path / "pair_error_vs_time.csv").read_text().splitlines()) == 4


@pytest.mark.slow   # a server, a headless browser and renders: the explorer's own tests cover the page
def test_explore_latency_report_runs(tmp_path):
    """benchmarks/speed/explore_latency.py, tiny, with the caches as they are: the table with every
    measure of a start, and the results file with its commit (skipped where no browser is)."""
    from pyjulia4d.app.explore.drive import HOW_TO_GET, browser_paths

    if None in browser_paths() or not importlib.util.find_spec("selenium"):
        pytest.skip(HOW_TO_GET)
    lat = load("explore_latency")
    out = tmp_path / "explore_latency.md"
    assert lat.main(["--changes", "1", "--drag-seconds", "0.5", "--keep-caches", "--set", "image.width=64",
                     "--set", "image.height=48", "--out", str(out)]) == 0
    md = out.read_text()
    assert "commit" in md and "| page open -> first picture (warm server) |" in md
    assert "previews per second while dragging" in md and "Scene size 64x48" in md


def test_refill_trial_report_runs(tmp_path):
    """benchmarks/studies/refill_trial.py, tiny: every queue's row, the same results as one block's."""
    assert load("refill_trial").main(["--size", "64x48", "--queues", "1,4", "--repeats", "1",
                                      "--out", str(tmp_path)]) == 0
    if not (tmp_path / "refill_trial.md").exists():
        pytest.skip("the march here runs no packets of 16 (the trial's only width)")
    md = (tmp_path / "refill_trial.md").read_text()
    assert "commit" in md and md.count("| yes |") == 2


def test_march_levers_schedules_count_rounds_exactly():
    """benchmarks/studies/march_levers.py's schedules on one packet worked by hand: lane 0 takes 3 then
    1 iterations, lane 1 1 then 3, the other lanes 1 and 1.  The blocks wait for each step's
    slowest lane (3 + 3 rounds); at its own pace every lane is done after 4 rounds, and an
    orbit ends at rounds 1, 2, 3 and 4; every lane busy would take (4 + 4 + 14 x 2) / 16."""
    lev = load("march_levers")
    its = np.ones((lev.LANES, 2), np.int64)
    its[0], its[1] = (3, 1), (1, 3)
    order = np.arange(lev.LANES)
    assert lev.cost_blocks(its, order) == 6
    assert lev.cost_own_pace(its, order) == (4, 4)
    assert lev.cost_refill(its, order, 1) == 6     # no queue to refill from: the blocks' cost
    lines = lev.schedules(its, order, "hand")
    assert ("| each lane at its own pace (steps' ends - estimates, proofs' outcomes - in 2.0x the blocks' "
            "rounds) | 56.2% | 0.67 |") in lines


def test_march_levers_wavefront_packs_the_rays_left():
    """march_levers.py's wavefront on two packets worked by hand: in each, ray 0 takes steps of 1,
    4 and 4 iterations and the other 15 one step of 1.  The blocks cost 9 each; launches of one
    step cost 1 + 1, then the two rays left share one packet: 4, and 4 (3 launches, 10 in all);
    launches of two steps cost 5 + 5, then 4."""
    lev = load("march_levers")
    its = np.zeros((2 * lev.LANES, 3), np.int64)
    its[:, 0] = 1
    its[0, 1:] = its[lev.LANES, 1:] = 4
    order = np.arange(2 * lev.LANES)
    assert lev.cost_blocks(its, order) == 18
    assert lev.cost_wavefront(its, order, 1) == (10, 3)
    assert lev.cost_wavefront(its, order, 2) == (14, 2)
    assert lev.cost_wavefront(its, order, 3) == (18, 1)   # one launch: the blocks


def test_march_levers_report_runs(tmp_path):
    """benchmarks/studies/march_levers.py, tiny (the float64 twin, no OpenCL): every schedule's row."""
    assert load("march_levers").main(["--size", "32x24", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "march_levers.md").read_text()
    assert "commit" in md and md.count("| each lane at its own pace") == 2
    assert md.count("| refill from a queue of 16 blocks |") == 2 and md.count("| wavefront: launches of 4 steps") == 2


def test_march_levers_proven_report_runs(tmp_path):
    """march_levers.py --march proven, tiny: the twin's enclosures per ray and every schedule's row."""
    assert load("march_levers").main(["--size", "32x24", "--march", "proven", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "march_levers.md").read_text()
    assert "the proven march (normal preset)" in md and "enclosures and" in md
    assert md.count("| wavefront: launches of") == 3 and "| every lane always busy" in md


@pytest.mark.slow   # eight runs of the whole command, each a process of its own
def test_command_cost_report_runs(tmp_path):
    assert load("command_cost").main(["--repeats", "1", "--no-big", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "command_cost.md").read_text()
    assert "| start-up, 8x6 PNG |" in md and "| 640x480 PNG |" in md


@pytest.mark.slow   # a git worktree and child processes per commit
def test_command_cost_beside_an_earlier_commit_runs(tmp_path):
    import shutil
    import subprocess

    if shutil.which("git") is None or subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT,
                                                     capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout")
    assert load("command_cost").main(["--repeats", "1", "--no-big", "--rev", "HEAD", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "command_cost.md").read_text()
    assert " beside " in md and "| 640x480 PNG |" in md and "wall s, at " in md


@pytest.mark.slow   # a git worktree and a child process per commit
def test_commit_ratio_report_runs(tmp_path):
    import shutil
    import subprocess

    if shutil.which("git") is None or subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT,
                                                     capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout")
    assert load("commit_ratio").main(["--rev", "HEAD", "--repeats", "1", "--renders", "1",
                                            "--size", "64x48", "--png", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "commit_ratio.md").read_text()
    assert "| kernel march |" in md and "| CPU-s of a render |" in md and "keeping a PNG's outputs" in md


@pytest.mark.parametrize("name,args", [
    ("peers.py", ["--size", "640x"]),
    ("commit_ratio.py", ["--rev", "no-such-commit"]),
    ("command_cost.py", ["--big", "0x480"]),
    ("command_cost.py", ["--rev", "no-such-commit", "--no-big"]),
    ("scaling.py", ["--repeats", "3"]),
    ("throughput.py", ["--size", "axb"]),
    ("pov_compare.py", ["--repeats", "many"]),
    ("peer_error.py", ["--samples", "0"]),
    ("peer_error.py", ["--scenes", "nothing"]),
    ("peer_error.py", ["--look", "default", "--scenes", "hypercomplex"]),
])
def test_bad_flags_are_one_line_and_exit_2(name, args, tmp_path):
    # benchmarks/lib/args.py: a bad flag is one line naming it, exit status 2, no traceback
    # and nothing written
    p = subprocess.run([sys.executable, str(script(name[:-3])), *args, "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=120, cwd=tmp_path)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1 and name in lines[0], p.stderr
    assert "Traceback" not in p.stderr and not list(tmp_path.iterdir())


def test_mandelbulber_depth_reads_to_the_mathematics(tmp_path):
    """Mandelbulber2's depth as benchmarks/peers/mb_depth.py reads it (its log-scaled 16-bit
    z-buffer, fixed by a near sphere and an empty sphere about the camera) on a third sphere
    in the set's depth range, against the exact depth where each ray meets that sphere grown
    by the threshold: within 0.05 of a pixel's footprint at the default threshold and at a
    constant one - which checks the decoding, the rays through the pixels' corners and the
    stop rule together.  Its CPU path: the same march as its OpenCL one, without the build."""
    import shutil

    if shutil.which("mandelbulber2") is None:
        pytest.skip("mandelbulber2 not installed (Debian: apt-get install mandelbulber2)")
    mb = load("mb_depth")
    from pyjulia4d.scene.model import Scene

    w, h = 160, 120
    scene = Scene.default().with_overrides(mb.peers.MATCHED + [f"image.width={w}", f"image.height={h}"])
    text = mb.peers.mb_settings(w, h)
    for kw in ({}, {"threshold": 1e-3}):
        ro = mb.Readout(scene, w, h, **kw)
        assert ro.z_min < ro.z_max
        assert mb.check(ro, text, mb.peers.MB_CPU, tmp_path) < 0.05
    import numpy as np

    hit = np.isfinite(mb.render_depth(ro, text, mb.peers.MB_CPU, tmp_path))
    assert 0.2 < hit.mean() < 0.6 and not hit[0, 0]   # the set, and not the reference spheres


def test_gpu_check_stops_without_a_gpu(tmp_path):
    # benchmarks/speed/gpu_check.sh on a machine with no OpenCL GPU: the devices listed, one line
    # saying why nothing ran, status 3 (a GPU machine runs the checks instead)
    import os
    import pyopencl as cl

    if any(d.type & cl.device_type.GPU for p in cl.get_platforms() for d in p.get_devices()):
        pytest.skip("an OpenCL GPU is here: the script would run its checks")
    env = dict(os.environ, PY=sys.executable, OUT=str(tmp_path))
    p = subprocess.run(["bash", str(ROOT / "benchmarks" / "speed" / "gpu_check.sh")], env=env, capture_output=True,
                       text=True, timeout=120)
    assert p.returncode == 3, p.stdout + p.stderr
    assert "gpu_check: no OpenCL GPU found" in p.stdout
    assert "(default)" in (tmp_path / "devices.txt").read_text()


def test_proof_budget_ball_is_proven_and_the_largest():
    """benchmarks/studies/proof_budget.py's certified ball: every point drawn in the ball about
    p escapes (|q_k| > bailout for some k <= max_iter, checked in float64 by iterating), for
    the square and the cube; the recursion it inverts, run forward, proves the ball of 0.999 r
    and not that of 1.001 r (r is the largest it proves); and a point inside the set gets 0."""
    from pyjulia4d.reference.algebra.quaternion import alg_cube, alg_sqr
    pb = load("proof_budget")
    rng = np.random.default_rng(5)
    c = np.array([-0.2, 0.8, 0.0, 0.0])
    for degree, power in ((2, alg_sqr), (3, alg_cube)):
        p = rng.normal(size=(40, 4)) * 0.7
        r = pb.best_ball(p, c, 12, 4.0, degree)
        assert (r >= 0).all() and (r > 0).sum() > 20
        for i in np.nonzero(r > 0)[0][:12]:
            u = rng.normal(size=(400, 4))
            u *= (rng.random(400) ** 0.25 * r[i] / np.linalg.norm(u, axis=1))[:, None]
            q = p[i] + u
            escaped = np.linalg.norm(q, axis=1) > 4.0
            for _ in range(12):
                q = np.where(escaped[:, None], q, power(q) + c)
                escaped |= np.linalg.norm(q, axis=1) > 4.0
            assert escaped.all()
            # forward: r_{k+1} = (|q_k| + r_k)^D - |q_k|^D proves the ball from 0.999 r, and from 1.001 r at no k
            for factor, want in ((0.999, True), (1.001, False)):
                q, rk, proves = p[i:i + 1].copy(), r[i] * factor, False
                with np.errstate(all="ignore"):   # escaped orbits overflow to inf: no proof there
                    for _ in range(13):
                        a = np.linalg.norm(q)
                        proves |= np.isfinite(a) & (a - rk > 4.0)
                        # (a + r)^D - a^D without its cancellation where a is far larger than r
                        rk = rk * (2 * a + rk) if degree == 2 else rk * (3 * a * a + 3 * a * rk + rk * rk)
                        q = power(q) + c
                assert bool(proves) == want
    assert pb.best_ball(np.zeros((1, 4)), np.zeros(4), 12, 4.0, 2)[0] == 0.0   # 0 is inside for c = 0


def test_proof_budget_slab_is_proven():
    """benchmarks/studies/proof_budget.py's affine slab (three noise symbols): every point drawn in a
    slab it proves - any depth in it, anywhere across the block, the block's corners included -
    escapes (|q_k| > bailout for some k <= max_iter, iterated in float64); slabs through the set
    are not proven; and the margin grows as the slab shortens."""
    from pyjulia4d.reference.algebra.quaternion import alg_sqr
    from pyjulia4d.reference.enclose.julia import ladder
    from pyjulia4d.reference.formula import formula_of
    from pyjulia4d.reference.iterate import julia_inside
    from pyjulia4d.scene.model import Scene
    pb = load("proof_budget")
    rng = np.random.default_rng(8)
    s = Scene.default()
    c, mi, b = np.asarray(s.fractal.c, float), s.fractal.max_iter, s.fractal.bailout
    thr = ladder(c, mi, b, formula_of(s.fractal))[0]
    o = np.array([0.0, 0.0, -3.0, 0.0])
    D0 = np.column_stack([rng.normal(0, 0.15, 60), rng.normal(0, 0.15, 60), np.ones(60), np.zeros(60)])
    # slabs ending a little in front of where the centre ray meets the set (a scan of 3000 steps),
    # where a proof takes many iterations and every bound counts; the rays that meet it
    tau = np.linspace(0.0, 4.0, 3001)
    inside = julia_inside((o + tau[:, None, None] * D0[None]).reshape(-1, 4), c, mi, b).reshape(len(tau), 60)
    D0 = D0[inside.any(axis=0)][:24]
    n = len(D0)
    assert n >= 12
    hit = tau[inside[:, inside.any(axis=0)][:, :24].argmax(axis=0)]
    Du, Dv = np.tile([0.002, 0, 0, 0], (n, 1)), np.tile([0, 0.002, 0, 0], (n, 1))
    tb = hit - rng.uniform(0.02, 0.1, n)
    ta = tb - rng.uniform(0.005, 0.05, n)
    proven, its, margin = pb.slab_prove(o, D0, Du, Dv, ta, tb, c, mi, b, thr)
    assert 6 <= proven.sum() < n and its[proven].max() >= 6
    for i in np.nonzero(proven)[0]:
        tau = rng.uniform(ta[i], tb[i], 300)
        uv = np.vstack([rng.uniform(-1, 1, (296, 2)), [[-1, -1], [-1, 1], [1, -1], [1, 1]]])
        q = o + tau[:, None] * (D0[i] + uv[:, :1] * Du[i] + uv[:, 1:] * Dv[i])
        escaped = np.linalg.norm(q, axis=1) > b
        for _ in range(mi):
            q = np.where(escaped[:, None], q, alg_sqr(q) + c)
            escaped |= np.linalg.norm(q, axis=1) > b
        assert escaped.all(), i
    # slabs across the first crossing hold a point of the set, short or long: a long one's centre
    # escapes early, and only the form's second-order terms keep it from being proven (without
    # them, slabs of 0.2 and 0.5 here were)
    for before in (0.01, 0.2, 0.5, 1.0):
        for after in (0.0015, 0.01):
            assert not pb.slab_prove(o, D0, Du, Dv, hit - before, hit + after, c, mi, b, thr)[0].any()
    short = pb.slab_prove(o, D0[:1], Du[:1], Dv[:1], ta[:1], ta[:1] + 0.001, c, mi, b, thr)[2]
    long_ = pb.slab_prove(o, D0[:1], Du[:1], Dv[:1], ta[:1], ta[:1] + 0.3, c, mi, b, thr)[2]
    assert short[0] >= long_[0]


def test_proof_budget_report_runs(tmp_path):
    """benchmarks/studies/proof_budget.py, tiny (the float64 twin, no OpenCL): every row."""
    assert load("proof_budget").main(["--size", "16x12", "--beam-size", "32x24", "--affine-size", "48x32",
                                      "--affine-stride", "2", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "proof_budget.md").read_text()
    assert "commit" in md and "| proven march, normal preset |" in md and "Beam start at 32x24" in md
    assert "Lengths known in advance (at 16x12)" in md and "Affine beams of 8x8 pixels at 48x32" in md


def test_path_noise_sources_report_runs(tmp_path):
    """benchmarks/studies/path_noise_sources.py, tiny: a row per variant, finite deviations."""
    bench = load("path_noise_sources")
    assert bench.main(["--size", "16x12", "--samples", "4", "--out", str(tmp_path)]) == 0
    rows = [ln for ln in (tmp_path / "path_noise_sources.md").read_text().splitlines() if ln.startswith("| ") and "---" not in ln][1:]
    assert len(rows) == len(bench.VARIANTS)
    assert all(np.isfinite(float(ln.split("|")[3])) for ln in rows)


def test_precision_cost_runs(tmp_path, capsys):
    """benchmarks/accuracy/precision_cost.py on one pair, tiny: its row, both precisions."""
    from harness import device
    if "cl_khr_fp64" not in device().extensions:
        pytest.skip("the device has no double precision")
    assert load("precision_cost").main(["--size", "16x12", "--repeats", "1", "--only", "cquat_sqr",
                                        "--out", str(tmp_path)]) == 0
    row = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("| cquat sqr")]
    assert len(row) == 1 and len(row[0].split("|")) == 10
    assert "commit" in (tmp_path / "precision_cost.md").read_text()
