"""Meshes (pyjulia4d/app/mesh.py, kernels/mesh/mesh.cl) against their float64 twin
(reference/mesh.py) and against the mathematics: the c = 0 set is a ball of known radius,
a set that fills its bounding ball is cut by the sphere, blocks of layers give the mesh one
grid gives, every format reads back, and bad input is one line."""
import dataclasses

import numpy as np
import pytest

import harness
from pyjulia4d.app import mesh as mesh_mod
from pyjulia4d.pipeline import mesh_plan
from pyjulia4d.pipeline.mesh_plan import make_mesh_plan
from pyjulia4d.reference import mesh as twin
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene

pytest.importorskip("mcubes")
trimesh = pytest.importorskip("trimesh")

BALL = Scene.default().replace(**{"fractal.c": [0.0, 0.0, 0.0, 0.0]})
# c = 0, q -> q^2: |q_N| = |q|^(2^N) <= bailout, so the truncated set is the ball of radius
# bailout^(1/2^N) (iterate.cl's definition; bailout 4, N = 12: 1.000338)
BALL_RADIUS = 4.0 ** (1.0 / 2 ** 12)

SCENES = {
    "default": Scene.default(),
    "hypercomplex-sin": Scene.default().replace(**{"fractal.algebra": "hypercomplex", "fractal.function": "sin",
                                                   "fractal.c": [0.2, 0.6, 0.1, 0.0], "fractal.max_iter": 8}),
    "cquat-cube": Scene.default().replace(**{"fractal.algebra": "cquat", "fractal.function": "cube",
                                             "fractal.c": [0.1, 0.3, 0.0, 0.0]}),
    "mandelbrot-slice": Scene.default().replace(**{"fractal.kind": "mandelbrot", "fractal.max_iter": 10,
                                                   "slice.normal": [0.0, 0.3, 0.0, 1.0], "slice.distance": 0.1}),
    "stack": Scene.default().replace(**{"fractal.kind": "julia_stack", "fractal.max_iter": 16}),
    # two planes, one oblique: a flat base and a slanted cut (kernels/mesh/mesh.cl, CLIP)
    "clipped": Scene.default().replace(**{"clip.planes": [[0.0, -1.0, 0.0, 0.3], [1.0, 0.2, 0.5, 0.4]]}),
}


def runner(plan):
    from pyjulia4d.opencl.mesh import MeshRunner
    return MeshRunner(plan, harness.device())


@pytest.mark.parametrize("name", SCENES)
def test_the_sampling_kernel_matches_its_twin(name):
    """float32 against float64: a grid point may be classified differently only where the two
    precisions' orbits part, within rounding of the surface - at most 0.5 % of the points, each
    next to a point of the other class in the twin's own mask."""
    plan = make_mesh_plan(SCENES[name], 24)
    got = runner(plan).sample(0, plan.n)
    want = twin.mesh_sample(plan, 0, plan.n)
    assert got.shape == want.shape == (24, 24, 24)
    assert 0 < want.sum() < want.size
    diff = np.argwhere(got != want)
    assert len(diff) <= 0.005 * want.size, len(diff)
    pad = np.pad(want, 1, mode="edge")
    for k, j, i in diff:
        nb = pad[k:k + 3, j:j + 3, i:i + 3]
        assert nb.min() != nb.max(), (k, j, i)


@pytest.mark.parametrize("name", ["default", "hypercomplex-sin", "stack", "clipped"])
def test_the_vertex_kernel_matches_its_twin(name):
    """The same grid edges through both executors: float32 vertices within 2e-6 of the float64
    ones (about 16 float32 ulps of a coordinate near 1: the level function's rounding near the
    surface; measured at most 7e-7), or, where the float32 orbit reads a point differently,
    within one grid spacing - on at most 2 % of them."""
    plan = make_mesh_plan(SCENES[name], 24)
    mask = twin.mesh_sample(plan, 0, plan.n)
    edges = np.argwhere(mask[:, :, 1:] != mask[:, :, :-1])    # x-edges whose ends differ
    lo = edges[:, ::-1].astype(float)
    hi = lo + [1.0, 0.0, 0.0]
    a, b = plan.to_world(lo), plan.to_world(hi)
    got, gw, gin = runner(plan).vertices(a, b)
    want, ww, win = twin.mesh_vertices(plan, a, b)
    assert np.all(ww >= 0) and np.all(ww <= plan.spacing / 2 ** (plan.steps - 1))
    err = np.linalg.norm(got - want, axis=1)
    assert np.all(err <= plan.spacing * 1.0001)
    assert np.mean(err > 2e-6) <= 0.02
    assert np.mean(np.linalg.norm(gin - win, axis=1) > 2e-6) <= 0.02


def test_the_c0_set_meshes_to_its_ball():
    r = mesh_mod.build_mesh(BALL, 48, harness.device())
    m = r.mesh
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0
    radii = np.linalg.norm(m.vertices, axis=1)
    # every vertex on the sphere to float32's rounding of a point near radius 1 (measured 9e-8)
    assert np.max(np.abs(radii - BALL_RADIUS)) < 5e-7
    exact = 4.0 / 3.0 * np.pi * BALL_RADIUS ** 3
    # an inscribed polyhedron: a little inside, by O(h^2) (h = 0.045 here: 0.3 %)
    assert 0.995 * exact < m.volume < exact
    assert abs(r.voxel_volume - exact) < 0.03 * exact
    # outward normals: a vertex's normal along its position
    assert np.mean(np.sum(m.vertex_normals * m.vertices, axis=1) / radii > 0.99) > 0.99


def test_a_clip_plane_cuts_a_flat_base():
    """clip.planes cut the mesh as they cut the render: the kept half-space y >= -0.3 gives a
    closed mesh whose lowest points lie on the plane, with a flat face there pointing down
    (its outward normal), and nothing below it; the cut mesh is the whole one's part above."""
    whole = mesh_mod.build_mesh(SCENES["default"], 64, harness.device())
    cut = mesh_mod.build_mesh(SCENES["default"].replace(**{"clip.planes": [[0.0, -1.0, 0.0, 0.3]]}), 64,
                              harness.device())
    m = cut.mesh
    assert m.is_watertight and m.volume > 0
    v = m.vertices
    assert v[:, 1].min() >= -0.3 - 1e-6 and whole.mesh.vertices[:, 1].min() < -0.5
    base = np.all(np.abs(v[m.faces][:, :, 1] + 0.3) < 1e-6, axis=1)
    assert m.area_faces[base].sum() > 0.2   # the cut face (measured 0.40 at 128^3)
    assert np.allclose(m.face_normals[base], [0.0, -1.0, 0.0], atol=1e-6)
    assert 0.5 * whole.mesh.volume < m.volume < whole.mesh.volume
    # every grid point the cut keeps is one the whole mesh has, above the plane
    assert cut.inside_points < whole.inside_points


def test_the_ball_cuts_a_set_that_fills_it():
    """A set reaching its bounding ball (hypercomplex reciprocal stays bounded almost everywhere,
    bounds.bounding_radius): closed by the sphere, those vertices exactly on it."""
    scene = Scene.default().replace(**{"fractal.algebra": "hypercomplex", "fractal.function": "reciprocal",
                                       "fractal.c": [0.1, 0.2, 0.0, 0.0], "fractal.max_iter": 6})
    r = mesh_mod.build_mesh(scene, 32, harness.device())
    assert r.mesh.is_watertight
    world = r.mesh.vertices @ r.plan.axes + r.plan.offset
    on_sphere = np.abs(np.linalg.norm(world, axis=1) - r.plan.radius) < 1e-5 * r.plan.radius
    assert np.mean(on_sphere) > 0.05


def test_blocks_of_layers_give_the_mesh_of_one_block(monkeypatch):
    whole = mesh_mod.build_mesh(SCENES["default"], 40, harness.device())
    monkeypatch.setattr(mesh_plan, "BLOCK_POINTS", 40 * 40 * 3)   # 3 layers a launch
    blocks = mesh_mod.build_mesh(SCENES["default"], 40, harness.device())
    assert blocks.plan.block == 3
    assert len(blocks.mesh.faces) == len(whole.mesh.faces) and blocks.inside_points == whole.inside_points
    assert np.allclose(np.sort(blocks.mesh.vertices, axis=0), np.sort(whole.mesh.vertices, axis=0), atol=0)
    assert blocks.mesh.is_watertight == whole.mesh.is_watertight


def test_the_reference_executor_meshes_the_same_set():
    a = mesh_mod.build_mesh(SCENES["default"], 20, harness.device())
    b = mesh_mod.build_mesh(SCENES["default"], 20, executor="reference")
    assert abs(len(a.mesh.faces) - len(b.mesh.faces)) <= 0.02 * len(b.mesh.faces)
    assert abs(a.mesh.volume - b.mesh.volume) <= 0.02 * b.mesh.volume


@pytest.mark.parametrize("suffix", [".stl", ".ply", ".obj", ".glb"])
def test_every_format_reads_back(tmp_path, suffix):
    r = mesh_mod.build_mesh(BALL, 24, harness.device())
    out = mesh_mod.check_mesh_path(tmp_path / f"ball{suffix}")
    mesh_mod.write_mesh(out, r)
    back = trimesh.load(out, force="mesh")
    assert len(back.faces) == len(r.mesh.faces)
    assert back.is_watertight and abs(back.volume - r.mesh.volume) < 1e-5 * r.mesh.volume
    if suffix in (".ply", ".glb"):   # formats that carry vertex colours
        assert back.visual.kind == "vertex"
    raw = out.read_bytes()
    # vertex normals where the format has them: PLY's nx ny nz, OBJ's vn, glTF's NORMAL
    marker = {".ply": b"property float nx", ".obj": b"\nvn ", ".glb": b'"NORMAL"'}.get(suffix)
    if marker is not None:
        assert marker in raw, suffix
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


def test_smoothing_keeps_it_closed_and_its_volume():
    r0 = mesh_mod.build_mesh(SCENES["default"], 40, harness.device())
    r1 = mesh_mod.build_mesh(SCENES["default"], 40, harness.device(), smooth=10)
    assert r1.mesh.is_watertight and len(r1.mesh.faces) == len(r0.mesh.faces)
    assert abs(r1.mesh.volume - r0.mesh.volume) < 0.05 * r0.mesh.volume
    # what the closing line says of the vertices stays true: smoothing moved them off their
    # brackets by the largest move, and it says so
    moved = float(np.max(np.linalg.norm(np.asarray(r1.mesh.vertices) - np.asarray(r0.mesh.vertices), axis=1)))
    assert r1.moved == pytest.approx(moved, rel=1e-9) and moved > 10 * r0.widest_bracket
    assert f"vertices within {r0.widest_bracket:.2g} of the surface," in r0.summary()
    assert f"moved up to {moved:.2g} by smoothing" in r1.summary()
    assert f"vertices within {r1.widest_bracket + moved:.2g} of the surface" in r1.summary()


@pytest.mark.parametrize("args,says", [
    (["--resolution", "7"], "--resolution: expected a whole number of grid points a side in [8, 2048], got 7"),
    (["--resolution", "1e3"], "--resolution: expected a whole number"),
    (["--resolution", "99999999999999999999999"], "--resolution: expected a whole number"),
    (["--smooth", "1001"], "--smooth: expected a whole number of smoothing passes"),
    (["--decimate", "0"], "--decimate: expected the share of triangles to keep, in (0, 1], got 0.0"),
    (["--decimate", "half"], "--decimate: expected the share of triangles to keep, in (0, 1], got 'half'"),
    (["--size", "0"], "--size: expected the longest side in millimetres, in (0, 100000], got 0.0"),
    (["--size", "nan"], "--size: expected the longest side in millimetres"),
    (["--size", "1e9"], "--size: expected the longest side in millimetres"),
    (["-o", "x.fbx"], "x.fbx: unsupported mesh format '.fbx' (use .stl, .ply, .obj or .glb)"),
    (["-o", "x"], "x: unsupported mesh format '(none)'"),
    (["-o", "nodir/x.stl"], "x.stl: directory 'nodir' does not exist"),
    (["--set", "slice.distance=3"], "slice.distance: 3.0 is outside the set's bounding ball"),
    (["--set", "fractal.c=0,0,0"], "fractal.c"),
    (["--resolution", "2048", "--set", "fractal.max_iter=100000"], "h of sampling; lower it, or --force"),
    (["missing.toml"], "missing.toml: cannot read"),
])
def test_bad_mesh_input_is_one_line_status_2_and_no_file(tmp_path, capsys, monkeypatch, args, says):
    from pyjulia4d.app.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["mesh", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pyjulia4d: error: ") and says in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("ext, unit_mm", [("stl", 1.0), ("glb", 1000.0)])
def test_a_sized_mesh_prints_at_its_size(tmp_path, capsys, ext, unit_mm):
    """--size MM: the longest side MM millimetres in the file's unit (a slicer reads STL in
    millimetres, glTF is in metres), the closing line giving the scale."""
    import trimesh
    from pyjulia4d.app.cli import main

    out = tmp_path / f"m.{ext}"
    assert main(["mesh", "--resolution", "24", "--size", "80", "-o", str(out)]) == 0
    line = capsys.readouterr().out
    got = trimesh.load(str(out), force="mesh")
    assert max(got.extents) == pytest.approx(80.0 / unit_mm, rel=1e-6)
    assert "scaled to 80 mm along its longest side (1 scene unit = " in line


def test_the_command_writes_the_mesh_it_reports(tmp_path, capsys, monkeypatch):
    from pyjulia4d.app.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["mesh", "--resolution", "24", "--set", "fractal.c=0,0,0,0", "-o", "ball.ply"]) == 0
    line = capsys.readouterr().out
    back = trimesh.load(tmp_path / "ball.ply", force="mesh")
    assert line.startswith("wrote ball.ply") and f"{len(back.faces)} triangles" in line
    assert [p.name for p in tmp_path.iterdir()] == ["ball.ply"]


def test_plans_refuse_what_is_no_scene():
    with pytest.raises(SceneError, match="scene: expected a pyjulia4d.Scene"):
        make_mesh_plan({"fractal": {}}, 32)
    for bad in (True, 7, 2049, 32.0, "32", None):
        with pytest.raises(SceneError, match="--resolution"):
            make_mesh_plan(Scene.default(), bad)


def test_the_grid_covers_the_balls_section_with_a_layer_outside():
    plan = make_mesh_plan(dataclasses.replace(Scene.default()), 32)
    r = np.sqrt(plan.radius ** 2 - plan.scene.slice.distance ** 2)
    assert plan.origin[0] == pytest.approx(-r - plan.spacing)
    assert plan.origin[0] + plan.spacing * (plan.n - 1) == pytest.approx(r + plan.spacing)


def test_vertex_colours_follow_the_renders_colouring():
    from pyjulia4d.pipeline.colormap import linear_to_srgb, table

    flat = mesh_mod.build_mesh(SCENES["default"], 24, harness.device())
    want = np.rint(linear_to_srgb(np.asarray(Scene.default().shading.color)) * 255)
    assert np.all(flat.mesh.visual.vertex_colors[:, :3] == want)
    # w over [-R/2, R/2] through the colour map: a slice tilted into w spans colours in order
    scene = SCENES["default"].replace(**{"shading.coloring": "w", "shading.colormap": "viridis",
                                         "slice.normal": [0.0, 0.0, 0.6, 1.0]})
    r = mesh_mod.build_mesh(scene, 24, harness.device())
    world = r.mesh.vertices @ r.plan.axes + r.plan.offset
    lo, hi = np.argmin(world[:, 3]), np.argmax(world[:, 3])
    lut = np.rint(linear_to_srgb(table("viridis")[:, :3].astype(float)) * 255)
    cols = r.mesh.visual.vertex_colors[:, :3].astype(float)
    # the lowest w nearer the map's low end than its high end, and the highest the other way
    d = lambda c, k: np.abs(c - lut[k]).sum()
    assert d(cols[lo], 0) < d(cols[lo], -1) and d(cols[hi], -1) < d(cols[hi], 0)



@pytest.mark.parametrize("coloring", ["iteration", "trap"])
def test_orbit_colourings_take_the_values_the_render_takes(coloring):
    """The render's colour value at its hits (the smooth escape count or the orbit trap of each
    bracket's inside end, shade/light.cl) and the mesh's at its vertices span the same range:
    the same surface, coloured the same way (to 0.02 of the map, for the pixels' and vertices'
    different sample points)."""
    from pyjulia4d import render
    from pyjulia4d.geometry.camera import camera_frame
    from pyjulia4d.reference.formula import formula_of
    from pyjulia4d.reference.shade import orbit_iteration, orbit_trap

    # a camera of its own: the hits sample the side of the set it sees, and framing is not
    # what this measures
    scene = Scene.from_dict({"fractal": {"c": [-0.75, 0.11, 0.0, 0.0]}, "image": {"width": 64, "height": 48},
                             "camera": {"position": [1.8, 1.6, -2.2, 0.0]},
                             "shading": {"coloring": coloring, "trap": [0.3, 0.2, 0.0, 0.0]}})
    shot = render(scene, device=harness.device())
    s = shot.scene
    hit = np.isfinite(shot.bracket)
    p = shot.position[hit].astype(float)
    d = p - camera_frame(s).position
    pin = p + shot.bracket[hit][:, None] * d / np.linalg.norm(d, axis=1)[:, None]
    f = s.fractal
    if coloring == "iteration":
        seen = orbit_iteration(pin, f.c, f.max_iter, f.bailout, formula_of(f))
    else:
        from pyjulia4d.geometry.camera import to_world
        seen = orbit_trap(pin, f.c, f.max_iter, f.bailout, to_world(s, s.shading.trap), formula_of(f))
    r = mesh_mod.build_mesh(s, 48, harness.device())
    world = r.mesh.vertices @ r.plan.axes + r.plan.offset
    inner = world   # the vertices lie within 1e-8 of their brackets' inside ends
    got = mesh_mod.colouring_values(s, world, inner)
    assert got.min() > seen.min() - 0.02 and got.max() < seen.max() + 0.02
    assert abs(np.median(got) - np.median(seen)) < 0.02


def test_decimation_keeps_the_share_asked_and_says_whether_it_is_closed():
    full = mesh_mod.build_mesh(SCENES["default"], 40, harness.device())
    half = mesh_mod.build_mesh(SCENES["default"], 40, harness.device(), decimate=0.5)
    assert abs(len(half.mesh.faces) - 0.5 * len(full.mesh.faces)) <= 0.02 * len(full.mesh.faces)
    assert len(half.mesh.visual.vertex_colors) == len(half.mesh.vertices)
    assert ("not watertight" in half.summary()) != half.mesh.is_watertight
    for bad in (0, 0.0, -0.5, 1.5, float("nan"), True, "0.5"):
        with pytest.raises(SceneError, match="--decimate"):
            mesh_mod.check_decimate(bad)
    # a share that keeps fewer triangles than a closed surface has (1e-300 kept none, and an
    # empty file was written)
    for tiny in (1e-300, 3.0 / len(full.mesh.faces)):
        with pytest.raises(SceneError, match=r"--decimate: .* triangles keeps [0-3], fewer than the 4"):
            mesh_mod.build_mesh(SCENES["default"], 40, harness.device(), decimate=tiny)


def _first_hits(origin, dirs, tri):
    """Distance along each ray to its first triangle (Moller-Trumbore over every triangle), inf
    for none."""
    v0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    out = np.full(len(dirs), np.inf)
    for k, d in enumerate(dirs):
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = origin - v0
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
        if hit.any():
            out[k] = t[hit].min()
    return out


def test_the_mesh_is_where_the_renderer_sees_the_surface():
    """Camera rays cast against the mesh meet it at the renderer's certified depth (the proven
    march, whose space in front of each hit is proven empty): within one grid spacing h on
    most rays; never more than 2h in front of it (that would be surface where the proof found
    none); behind it by more than 2h only where the grid missed a part thinner than h (at
    most 10 % of the rays; measured 4 of 60 at 128^3, 1 of 60 at 256^3)."""
    from pyjulia4d import render
    from pyjulia4d.geometry.camera import camera_frame
    from pyjulia4d.reference.rays import generate_rays

    scene = SCENES["default"].replace(**{"image.width": 40, "image.height": 30, "march.quality": "final"})
    shot = render(scene, device=harness.device())
    r = mesh_mod.build_mesh(scene, 128, harness.device())
    origins, dirs = generate_rays(camera_frame(scene), 40, 30)
    hit = np.isfinite(shot.bracket).ravel()
    pick = np.random.default_rng(3).choice(np.nonzero(hit)[0], 60, replace=False)
    # the default slice: world = scene coordinates, w = 0 on every ray
    got = _first_hits(origins[0, :3], dirs[pick, :3], r.mesh.vertices[r.mesh.faces])
    err = (got - shot.depth.ravel()[pick]) / r.plan.spacing   # +inf: the ray missed the mesh
    assert np.mean(np.abs(err) <= 1.0) >= 0.85
    assert np.all(err >= -2.0)
    assert np.mean(err > 2.0) <= 0.10


@pytest.mark.parametrize("distance,n", [(0.0, 24), (0.99, 32)])
def test_the_thinnest_wall_of_a_ball_is_its_diameter(distance, n):
    """The c = 0 set cut at slice distance d is a ball of radius sqrt(R^2 - d^2): its thinnest
    wall is its diameter, found to within 3 grid spacings (thinnest_wall's bound)."""
    scene = BALL.replace(**{"slice.distance": distance})
    r = mesh_mod.build_mesh(scene, n, harness.device(), walls=True)
    thick, where = r.wall
    diameter = 2 * np.sqrt(BALL_RADIUS ** 2 - distance ** 2)
    assert where is not None and abs(thick - diameter) <= 3 * r.plan.spacing
    assert np.linalg.norm(where) <= 2 * r.plan.spacing   # about the ball's centre
    assert "thinnest wall about" in r.summary()


def test_no_wall_thinner_than_the_margin_is_said_so():
    r = mesh_mod.build_mesh(BALL, 96, harness.device(), walls=True)
    thick, where = r.wall
    assert where is None and thick == pytest.approx((2 * mesh_mod.WALL_MARGIN - 1) * r.plan.spacing)
    assert thick < 2 * BALL_RADIUS   # a true statement: the ball is thicker


def test_thin_walls_of_a_julia_set_are_found_and_lie_in_the_set():
    r = mesh_mod.build_mesh(SCENES["default"], 64, harness.device(), walls=True)
    thick, where = r.wall
    assert where is not None and r.plan.spacing * 0.5 <= thick <= 4 * r.plan.spacing
    # the thinnest point is a grid point inside the set (its own inside test, in float64)
    from pyjulia4d.reference.formula import formula_of
    from pyjulia4d.reference.iterate import julia_inside
    p = where @ r.plan.axes + r.plan.offset
    f = r.plan.scene.fractal
    assert julia_inside(p[None], f.c, f.max_iter, f.bailout, formula_of(f))[0]


@pytest.mark.parametrize("kwargs,says", [
    ({"device": 5}, "device: expected None, a pyopencl Device"),
    ({"force": "no"}, "force: expected True or False"),
    ({"progress": 1}, "progress: expected True or False"),
    ({"walls": "yes"}, "walls: expected True or False"),
    ({"warn": "stderr"}, "warn: expected None or a callable"),
    ({"smooth": 2.0}, "--smooth"),
    ({"decimate": None}, "--decimate"),
    ({"executor": "gpu"}, "executor: expected 'opencl' or 'reference'"),
    ({"resolution": [32]}, "--resolution"),
])
def test_build_mesh_refuses_bad_arguments_in_one_line(kwargs, says):
    with pytest.raises(SceneError, match=says.replace("(", r"\(")) as e:
        mesh_mod.build_mesh(BALL, **{"resolution": 16, **kwargs})
    assert "\n" not in str(e.value)
