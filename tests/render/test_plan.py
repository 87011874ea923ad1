"""The render plan (pyjulia4d/pipeline/plan.py) and its execution in tiles (render.TileRunner):
outputs kept on request, device memory independent of the image size, a plan that travels."""
import pickle
import subprocess
import sys

import numpy as np
import pytest

from harness import device
from pyjulia4d.pipeline import kernel_config, workload
from pyjulia4d.opencl.lanes import lanes_for
from pyjulia4d.pipeline.plan import TILE, make_plan, make_tiles
from pyjulia4d.opencl.executor import render
from pyjulia4d.opencl.runner import TileRunner
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError

SMALL = ["image.width=96", "image.height=72"]


def test_tiles_cover_the_image_once():
    for w, h, t, halo in [(96, 72, 16, 0), (97, 71, 16, 1), (5, 3, 512, 1), (1030, 520, 512, 0)]:
        seen = np.zeros((h, w), int)
        for tile in make_tiles(w, h, t, halo):
            seen[tile.dst()] += 1
            rows, cols = tile.own()
            # the box holds the tile, reaches at most `halo` past it and stays in the image
            assert rows.start >= 0 and cols.start >= 0 and rows.stop <= tile.ah and cols.stop <= tile.aw
            assert 0 <= tile.ax0 <= tile.x0 and tile.x0 - tile.ax0 <= halo
            assert tile.ax0 + tile.aw <= w and tile.ay0 + tile.ah <= h
        assert (seen == 1).all()


@pytest.mark.parametrize("normals", ["jacobian", "zbuffer"])
def test_depth_only_gives_the_same_depth(normals):
    # the depth-only render runs neither normals nor shading, yet its depth, bracket, counts
    # and march guards are those of the full render, bit for bit
    s = Scene.default().with_overrides(SMALL + [f"normals.method={normals}"])
    full = render(s, tile=32)
    part = render(s, tile=32, outputs=["depth"])
    for k in ("color", "alpha", "normal", "position", "status", "samples"):
        assert getattr(part, k) is None, k
    np.testing.assert_array_equal(part.depth, full.depth)
    np.testing.assert_array_equal(part.bracket, full.bracket)
    assert part.counts == full.counts and part.hit_fraction == full.hit_fraction
    assert part.bracket_stats() == full.bracket_stats()
    for k in ("ulp_step", "shell_miss", "eye_hit"):
        assert part.guards[k] == full.guards[k], k
    assert set(part.exr_channels()) == {"Z", "Z.bracket", "Z.unresolved"}
    # counts streamed per tile agree with the full status image
    assert full.counts["hit"] == int(np.sum(full.status == 1))
    assert full.capped == int(np.sum(full.status == 2))


def test_alpha_without_shading():
    s = Scene.default().with_overrides(SMALL)
    full = render(s)
    a = render(s, outputs=["alpha", "normal"])
    np.testing.assert_array_equal(a.alpha, full.alpha)
    np.testing.assert_array_equal(a.normal, full.normal)
    assert a.color is None


def test_unknown_output_is_refused():
    with pytest.raises(SceneError, match=r"^outputs: unknown output 'colour'"):
        render(Scene.default().with_overrides(SMALL), outputs=["colour"])


@pytest.mark.filterwarnings("ignore:image.width")
def test_device_memory_does_not_grow_with_the_image():
    # two tiles' buffers whatever the size: a 4096 x 4096 plan allocates what a 1024 x 600 one does
    dev = device()
    sizes = []
    for w, h in [(1024, 600), (4096, 4096)]:
        s = Scene.default().with_overrides([f"image.width={w}", f"image.height={h}"])
        runner = TileRunner(make_plan(s, dev, lanes_for(dev, "auto", False), outputs=["depth"]), dev)
        sizes.append(sum(b.nbytes for bufs, _ in runner.slots for b in bufs.values()))
    assert sizes[0] == sizes[1] <= TileRunner.SLOTS * TILE * TILE * 56


def test_channels_lie_in_planes_for_the_exr_writer():
    """The image's colour, normal and position channels are planes underneath (executor.
    store.ImageStore.empty): the result's (H, W, C) arrays are views of them, and every EXR channel is
    handed over without a copy (an EXR render's peak at 3840x2160: 1.04 GB -> 741 MiB)."""
    r = render(Scene.default().with_overrides(SMALL + ["shading.shadow=none", "shading.ao=0"]))
    assert r.normal.shape[2] == 3 and r.position.shape[2] == 4 and r.color.shape[2] == 3
    for name, ch in r.exr_channels().items():
        assert ch.flags.c_contiguous, name
    chans = r.exr_channels()
    assert np.shares_memory(chans["N.X"], r.normal) and np.shares_memory(chans["P.W"], r.position)
    assert np.shares_memory(chans["R"], r.color)
    np.testing.assert_array_equal(chans["N.Y"], r.normal[..., 1])


def test_host_memory_follows_the_outputs():
    s = Scene.default().with_overrides(["image.width=20000", "image.height=20000"])
    # depth only: depth, bracket and unresolved, and as much again for the writer
    assert workload.host_bytes_per_pixel(["depth"]) == 24
    workload.check_memory(s, ["depth"])  # 9.6 GB: fits a machine of 24 GB or more
    if workload.physical_memory() and workload.physical_memory() < 1e12:
        with pytest.raises(SceneError, match="^image.width: 20000x20000"):
            workload.check_memory(s)


def test_plan_pickles():
    # a tile can be sent elsewhere as it is: the plan is plain values
    s = Scene.default().with_overrides(SMALL)
    p = make_plan(s, "CPU", 16, outputs=["depth"])
    q = pickle.loads(pickle.dumps(p))
    assert q.tiles == p.tiles and q.scene == s and q.outputs == p.outputs
    np.testing.assert_array_equal(q.frame.right, p.frame.right)


def test_cli_depth_only_exr(tmp_path):
    import OpenEXR

    out = tmp_path / "d.exr"
    r = subprocess.run([sys.executable, "-m", "pyjulia4d", "render", "-o", str(out), "--width", "40",
                        "--height", "30", "--channels", "Z"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert sorted(OpenEXR.File(str(out)).channels()) == ["Z", "Z.bracket", "Z.unresolved"]


@pytest.mark.parametrize("overrides", [[], ["normals.method=zbuffer"], ["image.samples=2"],
                                       ["fractal.algebra=hypercomplex", "fractal.function=exp",
                                        "shading.coloring=iteration"]])
def test_a_region_renders_as_the_same_pixels_of_the_whole(overrides):
    """The distributed renderer's unit: a region, cut across the tile grid (tiles start at
    its corner, not at multiples of the tile size), equals those pixels of the whole
    render bit for bit, halo-needing Z-buffer normals and supersampling included."""
    s = Scene.default().with_overrides(["image.width=70", "image.height=50"] + overrides)
    whole = render(s, device=device(), tile=16)
    part = render(s, device=device(), tile=16, region=(13, 7, 40, 30))
    for k in ("color", "alpha", "depth", "normal", "position", "status", "bracket"):
        assert np.array_equal(getattr(whole, k)[7:37, 13:53], getattr(part, k), equal_nan=True), k


@pytest.mark.parametrize("region", [(0, 0, 0, 5), (-1, 0, 5, 5), (60, 0, 20, 5), (0, 0, 70, 51), "abc"])
def test_a_region_outside_the_image_is_refused(region):
    s = Scene.default().with_overrides(["image.width=70", "image.height=50"])
    with pytest.raises(SceneError, match="region"):
        make_plan(s, "CPU", 1, region=region)


@pytest.mark.parametrize("keys", [
    [],
    ["march.method=fixed", "march.z_resolution=120", "shading.fog=0.4", "clip.planes=0,0,1,0.3"],
    ["fractal.algebra=hypercomplex", "fractal.function=sin", "fractal.c=-0.5,0.4,0,0", "fractal.max_iter=6",
     "camera.position=6,6,-8", "shading.reflection=0.3", "shading.light=eye"],
], ids=["default", "fixed-fog-clip", "hypercomplex-reflection"])
def test_one_plan_two_executors(keys):
    """Same plan, two executors (Mitsuba 3's variants, at the Python level): one make_plan,
    run by the OpenCL executor (run_plan) and by the float64 reference (reference.execute).
    float32 against float64: the pixel statuses agree almost everywhere (a ray grazing the
    surface may land either side), and where both hit, the depths agree within the two
    certified brackets plus float32's rounding of t; colours to a few 1e-3 of full scale."""
    from pyjulia4d import reference
    from pyjulia4d.opencl.executor import run_plan

    s = Scene.default().with_overrides(["image.width=40", "image.height=30"] + keys)
    dev = device()
    plan = make_plan(s, dev, 1)
    k = run_plan(plan, dev)
    r = reference.execute(plan)
    assert np.mean(k.status == r.status) > 0.98
    hit = (k.status == 1) & (r.status == 1)
    assert hit.sum() > 50
    tol = k.bracket[hit] + r.bracket[hit] + 1e-5 * (1 + np.abs(r.depth[hit]))
    assert np.mean(np.abs(k.depth[hit] - r.depth[hit]) <= tol) > 0.98
    assert np.median(np.abs(k.color[hit] - r.color[hit])) < 5e-3


def test_the_march_is_compiled_once_at_its_width():
    """kernel_config.shade_config: the scene's program holds no march, no Jacobian normals and no
    light terms (the march's program has them, at its width), and reads no march switch, so
    scenes that differ in the march alone share it."""
    s = Scene.default()
    for lanes in (1, 4):
        p = make_plan(s, "CPU", lanes)
        assert p.config == kernel_config.shade_config(s) and p.march_config == kernel_config.march_config(s, lanes)
        assert not {"march/march", "march/cone", "normals/jacobian", "shade/light"} & set(p.config.pieces)
        assert {"march/march", "march/cone", "normals/jacobian", "shade/light"} <= set(p.march_config.pieces)
    assert "CONE_START" not in p.config.defines and "SPECULAR" not in p.march_config.defines
    assert kernel_config.shade_config(s.with_overrides(["march.quality=final"])) == p.config
    assert "normals/gradient" in kernel_config.shade_config(s.with_overrides(["normals.method=gradient"])).pieces


def test_lights_in_camera_space_move_with_the_camera():
    """shading.light_space = "camera": a light at [x, y, z] is x along the picture's right,
    y up and z towards the viewer from the eye (a direction likewise), so it keeps its place
    in the picture as the camera moves; rendered, it is the scene-space light at the world
    point it names, to the bit."""
    from pyjulia4d.geometry.camera import camera_frame, light_position

    keys = ["shading.light_space=camera", "shading.light=1,2,3", "shading.lights=direction 0,0,1",
            "image.width=32", "image.height=24"]
    for pos in ("1.8,1.6,-2.2,0", "-2.5,0.5,1.5,0.3"):
        s = Scene.default().with_overrides(keys + [f"camera.position={pos}"])
        f = camera_frame(s)
        v = light_position(s, f) - f.position
        assert np.allclose([v @ f.right, v @ f.up, -(v @ f.forward)], [1, 2, 3])
        plan = make_plan(s, device(), 1)
        assert np.allclose(plan.shade.lights_geo[0], -f.forward)
    s = Scene.default().with_overrides(keys[:3] + keys[3:])
    world = light_position(s, camera_frame(s))
    same = s.with_overrides(["shading.light_space=scene", "shading.light=" + ",".join(map(repr, map(float, world))),
                             "shading.lights=direction " + ",".join(map(repr, map(float, -camera_frame(s).forward)))])
    a, b = render(s), render(same)
    assert np.array_equal(a.color, b.color)
    assert not np.array_equal(a.color, render(s.with_overrides(["shading.light_space=scene"])).color)


def test_slice_turn_turns_the_view_through_4d():
    """slice.turn: a rotation in each plane (turn_matrix: orthonormal, the xw turn by 90
    degrees takes x to w); the view turned by -90 degrees in xw is the slice whose normal is x
    (slice_rotation's, the same map); a zw turn leaves the default quaternion set's picture as
    it was (the set is symmetric about the plane of 1 and c), a yz turn does not."""
    from pyjulia4d.geometry.camera import camera_frame, slice_map, slice_rotation, turn_matrix

    g = turn_matrix([10, 20, 30, 40, 50, 60])
    assert np.allclose(g @ g.T, np.eye(4)) and np.isclose(np.linalg.det(g), 1.0)
    assert np.allclose(turn_matrix([0, 0, 90, 0, 0, 0]) @ [1, 0, 0, 0], [0, 0, 0, 1])
    base = Scene.default().with_overrides(["image.width=48", "image.height=36"])
    turned = base.with_overrides(["slice.turn=0,0,-90,0,0,0"])
    sliced = base.with_overrides(["slice.normal=1,0,0,0"])
    assert np.allclose(slice_map(turned)[0], slice_rotation([1, 0, 0, 0]))
    a, b = camera_frame(turned), camera_frame(sliced)
    assert np.allclose(a.position, b.position) and np.allclose(a.forward, b.forward)
    ra, rb = render(turned), render(sliced)
    hit = np.isfinite(ra.depth) & np.isfinite(rb.depth)
    assert np.mean(np.isfinite(ra.depth) == np.isfinite(rb.depth)) > 0.995
    assert np.abs(ra.depth[hit] - rb.depth[hit]).max() < 1e-3
    plain = np.isfinite(render(base).depth)
    same = lambda turn: np.mean(plain == np.isfinite(render(base.with_overrides([f"slice.turn={turn}"])).depth))  # noqa: E731
    assert same("0,0,0,0,0,30") > 0.995 and same("0,0,0,30,0,0") < 0.98
