"""End to end: the whole kernel pipeline against reference.render, and real renders
through the command line to PNG and OpenEXR."""
import subprocess
import sys

import numpy as np
import OpenEXR
import pyopencl as cl
import pytest
from PIL import Image

from pyjulia4d import Scene, reference, render


@pytest.mark.parametrize("over", [[], ["march.method=fixed", "march.post_steps=10", "normals.method=zbuffer"],
                                  ["normals.method=gradient", "shading.light=2,3,-4"],
                                  ["normals.method=gradient", "normals.step=pixel"]])
def test_pipeline_matches_reference(over):
    s = Scene.default().with_overrides(over + ["image.width=56", "image.height=42"])
    a, b = render(s), reference.render(s)
    # float32 may move a grazing ray's first hit to a neighbouring sample (see test_march)
    assert np.mean(a.status != b.status) <= 0.01
    both = (a.status == 1) & (b.status == 1)
    assert np.median(np.abs(a.depth[both] - b.depth[both])) < 1e-5
    # colour differences follow the normals' (test_normals): tiny but for a few pixels
    dc = np.abs(a.color - b.color)[both]
    assert np.median(dc) < 1e-3 and np.percentile(dc, 99) < 0.05
    assert np.array_equal(a.alpha == 1, a.status == 1)


def test_pixel_step_normals_do_not_speckle():
    """normals.step = "pixel" (Hart, Sandin & Kauffman's linear clarity): a quaternion cube at
    max_iter 50 wrinkles far below a pixel, and its exact (jacobian) normals leave about 1 % of
    the surface's pixels brighter or darker than all eight neighbours (salt and pepper); the
    gradient over a pixel's footprint leaves about a quarter of that (measured 1.17 % against
    0.31 % at 240x180, 1.05 % against 0.28 % at 480x360).  Its step is a hit's distance from the
    eye times 2 tan(fov/2) / height."""
    from scipy.ndimage import maximum_filter, minimum_filter

    from pyjulia4d.pipeline.plan import make_plan
    base = ["fractal.function=cube", "fractal.c=0.2078,0.5425,0.0047,0.3379", "fractal.max_iter=50",
            "camera.position=1.983,1.621,3.474,-0.494", "camera.target=0,0,0,-0.494", "camera.fit=true",
            "slice.normal=0,0,-0.371,1", "image.width=240", "image.height=180", "march.quality=draft"]
    ring = np.ones((3, 3), bool)
    ring[1, 1] = False

    def isolated(over):
        r = render(Scene.default().with_overrides(base + over))
        hit = r.status == 1
        lum = r.color.mean(-1)
        inner = hit & (minimum_filter(hit.astype(np.uint8), 3) == 1)
        odd = (lum < minimum_filter(lum, footprint=ring) - 0.03) | (lum > maximum_filter(lum, footprint=ring) + 0.03)
        return np.mean(odd[inner])

    exact, pixel = isolated([]), isolated(["normals.method=gradient", "normals.step=pixel"])
    assert exact > 0.008 and pixel < 0.5 * exact, (exact, pixel)
    plan = make_plan(Scene.default().with_overrides(["normals.method=gradient", "normals.step=pixel"]), "CPU", 1)
    assert plan.normals_args.step == 1e-5   # no finer than the floor of "auto" in single precision
    assert plan.normals_args.step_per_distance == pytest.approx(2 * plan.frame.tan_half_fov / plan.scene.image.height)


def test_outputs_have_no_nan_or_inf_where_they_should_not():
    r = render(Scene.default().with_overrides(["image.width=64", "image.height=48"]))
    hit = r.status == 1
    assert 0.1 < r.hit_fraction < 0.9
    assert np.all(np.isfinite(r.depth[hit])) and np.all(np.isposinf(r.depth[~hit]))
    np.testing.assert_allclose(np.linalg.norm(r.normal[hit], axis=-1), 1, atol=1e-5)
    assert np.all(r.normal[~hit] == 0)
    assert np.all(np.isfinite(r.position[hit])) and np.all(np.isnan(r.position[~hit]))
    assert np.all(np.isfinite(r.color))


def cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "pyjulia4d", "render", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def test_cli_renders_exr_with_all_channels(tmp_path):
    p = cli("--width", "40", "--height", "30", "--set", "fractal.c=-0.8,0.4,0,0", "-o", "out.exr", "--verbose",
            cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert p.stdout.count("\n") == 1 and "% of pixels hit" in p.stdout
    f = OpenEXR.File(str(tmp_path / "out.exr"), separate_channels=True)
    ch = {k: v.pixels for k, v in f.channels().items()}
    assert set(ch) == {"R", "G", "B", "A", "Z", "Z.bracket", "Z.unresolved", "N.X", "N.Y", "N.Z", "P.X", "P.Y", "P.Z", "P.W"}
    hit = ch["A"] == 1
    assert np.all(np.isfinite(ch["Z.bracket"][hit])) and np.all(ch["Z.bracket"][hit] >= 0)
    assert np.all(np.isposinf(ch["Z.bracket"][~hit]))
    assert all(v.dtype == np.float32 and v.shape == (30, 40) for v in ch.values())
    hit = ch["A"] == 1
    assert hit.any() and (~hit).any()
    assert np.all(np.isposinf(ch["Z"][~hit])) and np.all(np.isnan(ch["P.W"][~hit]))
    n = np.stack([ch["N.X"], ch["N.Y"], ch["N.Z"]], -1)
    np.testing.assert_allclose(np.linalg.norm(n[hit], axis=-1), 1, atol=1e-5)
    h = f.header()
    (tmp_path / "back.toml").write_text(h["pyjulia4d.scene"])
    back = Scene.from_toml(tmp_path / "back.toml")
    assert back.fractal.c == (-0.8, 0.4, 0.0, 0.0) and back.image.width == 40
    assert h["pyjulia4d.device"] and float(h["pyjulia4d.render_seconds"]) > 0
    assert h["pyjulia4d.capped_pixels"] == "0" and "normal_fallback=" in h["pyjulia4d.guards"]


def test_cli_reports_guards_that_fired(tmp_path):
    """The eye inside the set: every pixel is a hit at the eye; the closing line counts it."""
    p = cli("--width", "8", "--height", "6", "--set", "camera.position=0.05,0.1,-0.1,0",
            "--set", "camera.target=0,0,1,0", "-o", "in.png", "--verbose", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    # the eye is the first inside point of every ray: depth 0, bracket 0 (exact)
    assert p.stdout.strip().endswith("100.0% of pixels hit; guards fired: eye_hit 48; "
                                     "depth bracket p50 0 p99 0 max 0")


def test_cli_reports_the_bracket_and_the_preset_bound(tmp_path):
    p = cli("--width", "32", "--height", "24", "--set", "march.quality=final", "-o", "f.exr", "--verbose", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "; depth error p50 " in p.stdout and "preset's stated" in p.stdout
    hdr = OpenEXR.File(str(tmp_path / "f.exr")).header()
    for key in ("pyjulia4d.depth_bracket", "pyjulia4d.depth_error"):
        stats = dict(kv.split("=") for kv in str(hdr[key]).split())
        assert set(stats) == {"p50", "p99", "max"}
        assert 0 <= float(stats["p50"]) <= float(stats["p99"]) <= float(stats["max"])
    assert str(hdr["pyjulia4d.preset_bound_met"]) in ("yes", "no")
    assert str(hdr["pyjulia4d.space_proven"]) == "yes"
    un = dict(kv.split("=") for kv in str(hdr["pyjulia4d.unresolved_pixels"]).split())
    assert set(un) == {"hit", "miss"} and all(int(v) >= 0 for v in un.values())
    ch = OpenEXR.File(str(tmp_path / "f.exr")).channels()
    z, zu, zb = (np.asarray(ch[k].pixels) for k in ("Z", "Z.unresolved", "Z.bracket"))
    hit = np.isfinite(z)
    assert np.all(zu >= 0) and np.all(np.isfinite(zu)) and np.all(zb[hit] >= 0)


def test_cli_default_scene_png(tmp_path):
    p = cli("--width", "32", "--height", "24", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    im = Image.open(tmp_path / "julia.png")
    assert im.mode == "RGBA" and im.size == (32, 24)
    a = np.asarray(im)[..., 3]
    assert set(np.unique(a)) <= {0, 255} and (a == 255).any()


@pytest.mark.parametrize("normals", ["jacobian", "zbuffer"])
def test_tiles_give_the_same_image(normals):
    # any size renders in tiles of bounded device memory; the Z-buffer normals difference
    # neighbours across tile edges through a one-pixel halo, so the tiling is invisible
    s = Scene.default().with_overrides(["image.width=53", "image.height=41", f"normals.method={normals}"])
    whole = render(s)
    tiled = render(s, tile=16)
    for k in ("depth", "bracket", "status", "samples", "normal", "color", "alpha"):
        np.testing.assert_array_equal(getattr(tiled, k), getattr(whole, k), err_msg=k)
    assert tiled.guards == whole.guards


@pytest.mark.parametrize("ahead", [False, True])
def test_tiles_queued_ahead_or_not_give_the_same_image(monkeypatch, ahead):
    # passes.run_tiles: a CPU device has the next tile queued once the last one is done,
    # a GPU before the host waits for it; either order gives the same pixels, filed from
    # buffers mapped while the next tile's kernels write the other slot's
    from pyjulia4d.opencl import passes

    s = Scene.default().with_overrides(["image.width=53", "image.height=41", "image.samples=2"])
    want = render(s, tile=512)
    monkeypatch.setattr(passes, "queue_ahead", lambda dev: ahead)
    got = render(s, tile=16)
    for k in ("depth", "bracket", "status", "samples", "normal", "position", "color", "alpha"):
        np.testing.assert_array_equal(getattr(got, k), getattr(want, k), err_msg=k)
    assert got.guards == want.guards and got.counts == want.counts


# a program built here through pyopencl's own cache: Intel's runtime writes its vectorizer's
# remarks into every build log, which pyopencl turns into a CompilerWarning
@pytest.mark.filterwarnings("ignore::pyopencl.CompilerWarning")
def test_kernel_arguments_are_typed_once_and_checked():
    # runner.launch tells pyopencl each kernel's argument types on its first launch; a
    # Python number (whose width would be guessed) is refused by name
    from harness import device
    from pyjulia4d.opencl import build
    from pyjulia4d.opencl.runner import constant, launch, queue_for, type_arguments

    ctx, q = queue_for(device())
    src = ("__kernel void twice(const int n, const float a, __global float *out)"
           " { size_t i = get_global_id(0); if (i < (size_t)n) out[i] = 2 * a; }")
    k = build.kernel(cl.Program(ctx, src).build(), "twice")
    out = cl.Buffer(ctx, cl.mem_flags.WRITE_ONLY, 4 * 8)
    launch(q, k, 8, np.float32(1.5), out).wait()
    launch(q, k, 8, np.float32(2.5), out).wait()
    got = np.empty(8, np.float32)
    cl.enqueue_copy(q, got, out)
    assert np.all(got == 5)
    with pytest.raises(TypeError, match="twice: argument of type float"):
        type_arguments(cl.Kernel(cl.Program(ctx, src).build(), "twice"), (np.int32(8), 2.5, out))
    a = constant(q, np.arange(4, dtype=np.float32))
    assert constant(q, np.arange(4, dtype=np.float32)) is a
    assert constant(q, np.arange(4, dtype=np.float64)) is not a
    assert np.array_equal(a.get(), np.arange(4))


def test_image_too_large_for_memory_refused_before_rendering():
    from pyjulia4d.pipeline import workload
    from pyjulia4d.scene.checks import SceneError

    for w, h in [(1_000_000_000, 1), (100_000, 100_000), (46341, 46341), (65536, 65536)]:
        s = Scene.default().with_overrides([f"image.width={w}", f"image.height={h}"])
        with pytest.raises(SceneError, match=r"^image\.(width|height): .* pixels needs ~.* GiB"):
            workload.check(s, force=True)


def test_cli_says_whether_the_preset_target_was_met(tmp_path):
    # a proven preset: the closing line gives the error the render proves and compares it
    # with the preset's target; a march that proves nothing says so
    p = cli("--width", "16", "--height", "12", "--set", "march.quality=draft", "-o", "n.png", "--verbose",
            cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "depth error p50" in p.stdout and "the preset's stated" in p.stdout
    p = cli("--width", "16", "--height", "12", "--set", "march.method=fixed", "-o", "f.png", "--verbose", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "not proven empty" in p.stdout


def test_the_closing_line_reads_at_a_glance(tmp_path):
    """Without --verbose: the time, size and device, the error the render states in one
    figure, and what to do where it is above a preset the user chose - no preset is named
    where none was chosen, no device reasoning, no repository path; the full report is in
    the image's header."""
    p = cli("--width", "32", "--height", "24", "--set", "fractal.algebra=cquat", "--set", "fractal.function=cube",
            "-o", "a.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    line = p.stdout.strip()
    assert line.startswith("rendered a.png (32x24) in ") and "; depth error p99 " in line
    assert "preset" not in line and "benchmarks/" not in line and "the default:" not in line and len(line) < 200
    p = cli("--width", "32", "--height", "24", "--set", "fractal.algebra=cquat", "--set", "fractal.function=cube",
            "--set", "march.quality=normal", "-o", "b.png", cwd=tmp_path)
    assert "above the preset's 1e-03 (a finer march.quality proves more)" in p.stdout
    from pyjulia4d.app.output import read_header
    hdr = read_header(tmp_path / "a.png")
    assert hdr["pyjulia4d.depth_error"] and hdr["pyjulia4d.guards"]


def test_program_binaries_cached_on_disk(tmp_path, monkeypatch):
    # build.program keeps each program's binary under <cache>/programs, keyed by source,
    # options and device; a later process loads it instead of compiling, and a binary that
    # no longer loads is rebuilt from source
    from harness import device
    from pyjulia4d.opencl import build
    from pyjulia4d.pipeline import kernel_config
    from pyjulia4d.opencl.runner import queue_for

    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    ctx, _ = queue_for(device())
    cfg = kernel_config.KernelConfig(kernel_config.probe_config(Scene.default()).pieces, ("PROBE_CACHE_TEST",))
    build._programs.pop((ctx.int_ptr, cfg), None)
    build.program(ctx, cfg)
    [binary] = list((tmp_path / "programs").glob("*.bin"))
    assert binary.stat().st_size > 0
    build._programs.pop((ctx.int_ptr, cfg))
    assert build._from_binary(ctx, ctx.devices[0], binary, ["-DPROBE_CACHE_TEST"]) is not None
    binary.write_bytes(b"not a program")
    assert build._from_binary(ctx, ctx.devices[0], binary, ["-DPROBE_CACHE_TEST"]) is None
    prg = build.program(ctx, cfg)                      # rebuilt from source, cache rewritten
    assert prg.get_info(cl.program_info.KERNEL_NAMES)
    assert binary.read_bytes() != b"not a program"


def test_programs_never_go_through_pyopencls_cache(tmp_path, monkeypatch):
    # devices.build builds with cache_dir=False: pyopencl's own binary cache, keyed without the
    # runtime's settings, once handed Intel's runtime a binary it refused (INVALID_BINARY),
    # and pyopencl's error path then raised a KeyError; pyjulia4d keeps binaries itself
    import pyopencl.cache
    from harness import device
    from pyjulia4d.opencl import build
    from pyjulia4d.pipeline import kernel_config
    from pyjulia4d.opencl.runner import queue_for

    built = pyopencl.cache.create_built_program_from_source_cached
    seen = []

    def no_cache(*args, cache_dir=None, **kwargs):   # pyopencl passes cache_dir by name
        seen.append(cache_dir)
        if cache_dir is not False:
            raise AssertionError("pyopencl's binary cache was used")
        return built(*args, cache_dir=cache_dir, **kwargs)

    monkeypatch.setattr(pyopencl.cache, "create_built_program_from_source_cached", no_cache)
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    ctx, _ = queue_for(device())
    cfg = kernel_config.KernelConfig(kernel_config.probe_config(Scene.default()).pieces, ("PYOPENCL_CACHE_TEST",))
    build._programs.pop((ctx.int_ptr, cfg), None)
    prg = build.program(ctx, cfg)
    # drivers that cache builds themselves (PoCL, NVIDIA's: pyopencl.characterize.has_src_build_cache)
    # are built by pyopencl without its cache function at all
    assert prg.get_info(cl.program_info.KERNEL_NAMES) and all(c is False for c in seen)
    build._programs.pop((ctx.int_ptr, cfg))


def test_a_failed_build_leaves_no_file(tmp_path, monkeypatch):
    # pyopencl saves a failed build's source in a temporary file ("(source saved as ...)");
    # devices.build removes it (a driver that cannot compile fails every build, the compile
    # probe's included), and the error still carries the build log
    import tempfile
    from harness import device
    from pyjulia4d.opencl.devices import build
    from pyjulia4d.opencl.runner import queue_for

    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr(tempfile, "tempdir", None)   # gettempdir() reads TMPDIR again
    ctx, _ = queue_for(device())
    with pytest.raises(cl.Error) as e:
        build(cl.Program(ctx, "__kernel void k(__global float *a) { a[0] = no_such_name; }"))
    assert "no_such_name" in str(e.value)
    assert list(tmp_path.iterdir()) == []


def test_kernels_made_once_per_thread():
    # build.kernel: one kernel object per (program, name) and thread - a kernel holds its
    # arguments from set to enqueue, so two threads rendering at once must not share one -
    # and threads rendering at once give the image of one thread alone
    import threading
    from harness import device
    from pyjulia4d.opencl import build
    from pyjulia4d.opencl.runner import queue_for
    from pyjulia4d.pipeline import kernel_config

    ctx, _ = queue_for(device())
    prg = build.program(ctx, kernel_config.shade_config(Scene.default()))
    k = build.kernel(prg, "shade")
    names = prg.get_info(cl.program_info.KERNEL_NAMES).split(";")
    assert build.kernel(prg, "shade") is k
    assert all(build.kernel(prg, n) is not k for n in names if n != "shade")
    other = []
    t = threading.Thread(target=lambda: other.append(build.kernel(prg, "shade")))
    t.start()
    t.join()
    assert other[0] is not k and other[0].function_name == "shade"

    scene = Scene.default().with_overrides(["image.width=48", "image.height=36"])
    want = render(scene).color
    got = [None] * 3
    def run(i, s):
        got[i] = render(s).color
    threads = [threading.Thread(target=run, args=(i, scene)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(g is not None and np.array_equal(g, want) for g in got)


@pytest.mark.parametrize("over", [["clip.planes=0,0,-1,0"], ["clip.planes=-1,0,-1,0;0,1,0,0.3", "march.method=fixed"],
                                  ["clip.planes=0,0,-1,0.1", "fractal.algebra=hypercomplex",
                                   "fractal.c=-0.123,0,-0.745,0", "camera.position=1.7,5.7,-5.7"]])
def test_cut_away_planes_match_reference(over):
    # march.cl's clipped intervals and march/clip.cl's cut-face normals against the float64
    # twin; the cut face is a hit at its plane's first point, width 0, with the plane's normal
    from pyjulia4d import reference as ref
    s = Scene.default().with_overrides(over + ["image.width=40", "image.height=30"])
    k, r = render(s), ref.render(s)
    assert np.mean(k.status != r.status) < 0.01
    both = (k.status == 1) & (r.status == 1)
    face = both & (r.bracket == 0)
    assert face.sum() > 10
    np.testing.assert_allclose(k.depth[face], r.depth[face], rtol=1e-5, atol=1e-6)
    cos = np.sum(k.normal[face] * r.normal[face], axis=-1)
    assert np.median(cos) > 0.99999
    # every hit lies in every kept half-space
    from pyjulia4d.geometry.camera import clip_planes
    for m, e in clip_planes(s):
        assert np.all(k.position[k.status == 1] @ m <= e + 1e-4)


def test_clip_planes_refused():
    from pyjulia4d.scene.checks import SceneError
    for bad, msg in [("0,0,0,1", "plane 0: zero normal"), ("1,2,3", "plane 0: expected"),
                     ("1,0,0,0;0,1,0,0;0,0,1,0;1,1,0,0;1,0,1,0", "at most 4 planes"),
                     ("1,0,0,nan", "plane 0: element 3: not a finite number")]:
        with pytest.raises(SceneError, match="^clip.planes: " + msg):
            Scene.default().with_overrides([f"clip.planes={bad}"])


def test_closing_line_says_which_device_and_why(tmp_path):
    """The default device is picked by a fixed rule (the first GPU that compiles, else a
    CPU that compiles, Intel's runtime first), and the closing line says which and why; a
    named device needs no why."""
    from pyjulia4d.opencl.devices import indexed_devices, default_reason, select_device
    dev = select_device(None)
    why = default_reason(dev)
    idx = next(i for i, _, d in indexed_devices() if d.int_ptr == dev.int_ptr)
    assert why.startswith(f"{idx}, the default: ")
    p = cli("--width", "8", "--height", "6", "-o", "a.png", "--verbose", cwd=tmp_path)
    assert p.returncode == 0 and f"({why})" in p.stdout, p.stdout
    p = cli("--width", "8", "--height", "6", "-o", "b.png", "--device", idx, cwd=tmp_path)
    assert p.returncode == 0 and "the default" not in p.stdout, p.stdout


def test_guard_counts_are_pixel_by_pixel_counts():
    """count_guards ORs every flag first and counts only the flags that fired: the counts must be
    those of a plain pixel-by-pixel count, with no flag, one flag, and every flag set somewhere
    (normal_fallback and jacobian_tiny on hits alone; eye_hit: a hit at depth 0)."""
    from pyjulia4d.pipeline.codes import (GUARD_JACOBIAN_TINY, GUARD_NORMAL_FALLBACK, GUARD_SHELL_MISS,
                                          GUARD_ULP_STEP, STATUS_CAPPED, STATUS_HIT, STATUS_MISS)
    from pyjulia4d.pipeline.result import count_guards
    flags = (GUARD_ULP_STEP, GUARD_NORMAL_FALLBACK, GUARD_JACOBIAN_TINY, GUARD_SHELL_MISS)
    rng = np.random.default_rng(7)
    for case in range(12):
        n = 3000
        status = rng.choice([STATUS_MISS, STATUS_HIT, STATUS_CAPPED], n).astype(np.int32)
        depth = np.where(status == STATUS_HIT, rng.uniform(0, 3, n), np.inf).astype(np.float32)
        depth[rng.random(n) < (0.01 if case % 3 else 0)] = 0.0
        guard = np.zeros(n, np.int32)
        for f in flags[:case % 5]:
            guard[rng.random(n) < 0.02] |= f
        got = count_guards(status.reshape(50, 60), depth.reshape(50, 60), guard.reshape(50, 60))
        hit = status == STATUS_HIT
        want = {"ulp_step": int(np.sum(guard & GUARD_ULP_STEP != 0)),
                "normal_fallback": int(np.sum((guard & GUARD_NORMAL_FALLBACK != 0) & hit)),
                "jacobian_tiny": int(np.sum((guard & GUARD_JACOBIAN_TINY != 0) & hit)),
                "shell_miss": int(np.sum(guard & GUARD_SHELL_MISS != 0)),
                "eye_hit": int(np.sum(hit & (depth == 0)))}
        assert got == want, case
