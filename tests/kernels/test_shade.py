"""shade/shade.cl and shade/light.cl against reference.shade / reference.light_terms on
identical normals and points; whole renders with shadows, occlusion and colour maps against
the reference render."""
import dataclasses

import numpy as np
import pyopencl as cl
import pytest

from harness import Runner
from pyjulia4d.opencl.records import Packed, Precision
from pyjulia4d.pipeline import signatures
from pyjulia4d.pipeline.plan import make_plan
from pyjulia4d.pipeline import kernel_config
from pyjulia4d import reference as ref
from pyjulia4d.geometry.camera import camera_frame, extra_lights
from pyjulia4d.scene.model import Scene


@pytest.mark.parametrize("over", [["shading.light=eye"], ["shading.light=2,3,-4"], ["shading.specular=0"],
                                  ["shading.light=-1,2,-3,0.5", "shading.shininess=5",
                                   "shading.light_color=1,0.5,0.2", "shading.background=0.1,0.2,0.3"],
                                  ["shading.fog=0.7", "shading.background=0.3,0.4,0.5"],
                                  ["shading.sky=0.3,0.5,0.9", "shading.ambient=0.4",
                                   "shading.lights=position 3,1,-2 color 0.2,0.4,1 intensity 2; direction -1,0.5,0.2,0.3"],
                                  ["shading.reflection=0.4", "shading.fog=0.3"],
                                  ["shading.light=eye", "shading.shadow=hard",
                                   "shading.lights=direction 0,1,0 color 1,0.8,0.6; position 0,0,-3,1 intensity 0.5; position 2,2,2"]])
@pytest.mark.parametrize("fl", ["single", "double"])
def test_shade_matches_reference(over, fl):
    # shade.cl alone: no light terms (those are test_light_terms_in_render_match_reference's)
    s = Scene.default().with_overrides(["shading.shadow=none", "shading.ao=0"] + over + [f"render.float={fl}"])
    R = Runner(kernel_config.shade_config(s))
    fr = camera_frame(s)
    rng = np.random.default_rng(5)
    n = 4000
    status = rng.integers(0, 3, n).astype(np.int32)
    point = rng.normal(size=(n, 4)) * 0.5
    nrm = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm[:, 2] = np.abs(nrm[:, 2])  # facing the eye, like every visible surface
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    point, nrm = point.astype(R.real).astype(float), nrm.astype(R.real).astype(float)
    sh = s.shading
    geo, rgb = extra_lights(s)
    geo = geo.astype(R.real).astype(float)
    # the extra lights' visibility (light.cl's, given here): 1 with no shadows compiled
    vis = rng.uniform(0, 1, (n, 4)) if "EXTRA_SHADOWS" in kernel_config.scene_config(s).defines else np.ones((n, 4))
    # light.cl's terms (the key light's visibility, occlusion, colour value): none here
    terms = np.tile([1.0, 1.0, 0.0, 0.0], (n, 1))
    refl = rng.uniform(0, 1, (n, 4))   # reflect.cl's colour of the bounce (given here)
    out = R.out(n, cl.cltypes.float4)
    # kernel and twin take the same record: the plan's (pipeline/plan.ShadeArgs), the kernel's
    # packed by its signature (pipeline/signatures.py)
    plan = make_plan(s, "CPU", 1)
    sa = dataclasses.replace(plan.shade, fog_start=1.5, lights_geo=geo)
    packed = Packed(signatures.SHADE, {**plan.records(), "shade": sa}, Precision(fl == "double"),
                    lut=R.buf(np.zeros((2, 4)), np.float32), n_lut=2, lights_geo=R.buf4(geo),
                    lights_rgb=R.buf(rgb, np.float32))
    R("shade", (n,), *packed(status=R.buf(status, np.int32), normal=R.buf4(np.c_[nrm, np.zeros(n)]),
                             point=R.buf4(point), terms=R.buf(terms, np.float32), vis_extra=R.buf(vis, np.float32),
                             refl=R.buf(refl, np.float32), rgba=out))
    got = out.get().view(np.float32).reshape(4, n).T   # shade.cl's four planes
    want = ref.shade(status, nrm, point, fr, sa, terms=terms, vis_extra=vis,
                     refl=refl if sh.reflection > 0 else None)
    # the shading itself is float32 in both variants (colour needs no more; shade.cl):
    # float32 arithmetic on values of order 1 (pow() amplifies by the shininess: 40 x 6e-8)
    np.testing.assert_allclose(got, want, atol=2e-5)
    assert np.all(got[status != 1, 3] == 0) and np.all(got[status == 1, 3] == 1)


def test_colormaps_exist_in_matplotlib():
    import matplotlib

    from pyjulia4d.scene.ranges import COLORMAPS
    for name in COLORMAPS:
        assert name in matplotlib.colormaps, name


def test_a_colour_table_maps_the_value_then_the_gradient():
    """colormap.table_of: a map's table unchanged where the value is not mapped (the renders of
    before, bit for bit); with color_scale, color_offset and color_repeat the table holds the
    map at offset + scale v, clamped, repeated or mirrored; a gradient's stops are its colours
    there (linear light)."""
    from pyjulia4d.pipeline import colormap as cm

    assert np.array_equal(cm.table_of(cm.ColorSpec("viridis")), cm.table("viridis"))
    base = cm.table("viridis").astype(np.float64)
    v = np.linspace(0.013, 0.987, 97)
    for repeat, want in (("clamp", np.clip(0.2 + 3 * v, 0, 1)), ("repeat", np.mod(0.2 + 3 * v, 1)),
                         ("mirror", 1 - np.abs(np.mod(0.2 + 3 * v, 2) - 1))):
        got = cm.lookup(cm.table_of(cm.ColorSpec("viridis", None, 0.2, 3.0, repeat)).astype(np.float64), v)
        seam = np.abs(np.mod(0.2 + 3 * v + 0.5, 1) - 0.5) < 0.01   # a wrap between two entries
        err = np.abs(got - cm.lookup(base, want)).max(axis=1)
        # matplotlib's viridis is 256 flat bins: tables sampled at other values differ by a bin
        assert err[~seam].max() < 0.025, (repeat, err[~seam].max())
    stops = ((0.0, 0.0, 0.0, 0.0), (0.25, 1.0, 0.0, 0.0), (0.75, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0, 1.0))
    tab = cm.table_of(cm.ColorSpec("viridis", stops)).astype(np.float64)
    got = cm.lookup(tab, np.array([0.0, 0.25, 0.75, 1.0]))
    # a stop between two entries is a kink the table rounds by its spacing, 1/255
    np.testing.assert_allclose(got, cm.srgb_to_linear(np.array([s[1:] for s in stops])), atol=0.02)


def test_colormap_table_is_linear_light():
    from pyjulia4d.pipeline import colormap
    t = colormap.table("viridis")
    assert t.shape == (256, 4) and t.dtype == np.float32
    # the PNG writer's sRGB encoding gives the map's own colours back
    import matplotlib
    srgb = np.asarray(matplotlib.colormaps["viridis"](np.linspace(0, 1, 256)))[:, :3]
    np.testing.assert_allclose(colormap.linear_to_srgb(t[:, :3]), srgb, atol=1e-6)


LIGHT_SCENES = {
    "default": [],
    "fog": ["shading.fog=0.8", "shading.background=0.2,0.2,0.3"],
    "fog+trap+cut": ["shading.fog=0.5", "shading.coloring=trap", "clip.planes=0,0,-1,0", "image.samples=2"],
    "soft+ao": ["shading.light=-3,4,-2", "shading.shadow=soft", "shading.ao=0.8"],
    "hard+trap": ["shading.light=-3,4,-2", "shading.shadow=hard", "shading.coloring=trap",
                  "shading.colormap=inferno"],
    "iteration": ["shading.coloring=iteration", "fractal.c=-0.1,0.65,0,0", "fractal.max_iter=8",
                  "shading.shadow=none", "shading.ao=0"],
    "w": ["shading.coloring=w", "camera.position=1.8,1.6,-2.2,0.6", "shading.ao=0.5"],
    "fixed-hard-ao": ["march.method=fixed", "shading.light=-3,4,-2", "shading.shadow=hard", "shading.ao=0.8"],
    "three-lights-soft": ["shading.light=-3,4,-2", "shading.shadow=soft", "shading.sky=0.5,0.6,1",
                          "shading.lights=position 3,2,-1 color 0.3,0.5,1 intensity 0.8; direction 0,-1,0.2 "
                          "color 1,0.5,0.2 intensity 0.4"],
    # a distant light along limbo has no direction in the rays' 3D space: shade.cl lights along
    # the view instead, so its shadow rays are traced from every hit
    "limbo-light": ["shading.light=eye", "shading.shadow=hard", "shading.lights=direction 0,0,0,1 intensity 0.8"],
    "eye-and-lights-hard-fixed": ["march.method=fixed", "shading.light=eye", "shading.shadow=hard",
                                  "shading.lights=position -2,3,-3 intensity 0.7; direction 1,1,-1,0.2"],
    "reflection": ["shading.reflection=0.5", "shading.background=0.2,0.3,0.5"],
    "gradient": ["shading.coloring=trap", "shading.gradient=[[0, 0.1, 0, 0.2], [0.5, 1, 0.4, 0], [1, 1, 1, 0.8]]",
                 "shading.color_scale=3", "shading.color_offset=0.1", "shading.color_repeat=mirror"],
    "reflection-fixed-cut-eye": ["march.method=fixed", "shading.light=eye", "shading.reflection=0.3",
                                 "clip.planes=0,0,-1,0.1", "normals.method=gradient"],
    "mandelbrot-trap": ["fractal.kind=mandelbrot", "fractal.max_iter=10", "shading.coloring=trap",
                        "shading.trap=-1,0,0,0", "camera.position=0.4,2.2,-3.2,0", "camera.target=-0.5,0,0,0"],
    "mandelbrot-iteration": ["fractal.kind=mandelbrot", "fractal.max_iter=8", "shading.coloring=iteration",
                             "shading.shadow=none", "camera.position=0.4,2.2,-3.2,0", "camera.target=-0.5,0,0,0"],
    "hypercomplex": ["fractal.algebra=hypercomplex", "fractal.function=sin", "fractal.c=0.5,0.8,0.2,0.1",
                     "fractal.max_iter=6", "camera.position=3.6,3.2,-4.4,0", "shading.light=-5,6,-3",
                     "shading.shadow=hard", "shading.ao=0.6", "shading.coloring=iteration"],
}


# the default run samples the light scenes (each builds programs of its own from cold); the
# rest, whose switches the sampled ones share, run with -m slow
LIGHT_SAMPLE = ("default", "fog+trap+cut", "three-lights-soft", "reflection-fixed-cut-eye", "hypercomplex", "gradient")


@pytest.mark.parametrize("name", [pytest.param(n, marks=[] if n in LIGHT_SAMPLE else [pytest.mark.slow])
                                  for n in LIGHT_SCENES])
def test_light_terms_in_render_match_reference(name):
    # kernels (in packets where the march has them) against the float64 reference render:
    # on pixels both hit with the same depth to 1e-5, the shadow, occlusion and colour terms
    # follow the surface, so colours agree except where a shadow ray grazes the set
    from pyjulia4d.opencl.executor import render
    # the scan or the estimate (march.quality custom): the light terms are the subject, and the
    # proven march's kernel and twin part on grazing rays a little more
    s = Scene.default().with_overrides(LIGHT_SCENES[name] + ["image.width=40", "image.height=30",
                                                             "march.quality=custom"])
    k, r = render(s), ref.render(s)
    with np.errstate(invalid="ignore"):   # inf - inf on misses
        both = (k.status == 1) & (r.status == 1) & (np.abs(k.depth - r.depth) < 1e-5)
    assert both.sum() > 100
    dc = np.abs(k.color[both] - r.color[both]).max(axis=-1)
    assert np.median(dc) < 1e-3 and np.mean(dc < 0.02) > 0.95, np.percentile(dc, [50, 95, 100])
    assert np.all(np.isfinite(k.color))


def test_scene_without_light_terms_compiles_none():
    plain = Scene.default().with_overrides(["shading.shadow=none", "shading.ao=0"])
    src = kernel_config.source(kernel_config.scene_config(plain))
    assert '"shade/light.cl"' not in src
    src = kernel_config.source(kernel_config.scene_config(plain.with_overrides(["shading.ao=0.5"])))
    assert '"shade/light.cl"' in src and "#define" in src


def test_shadows_compiled_only_where_they_show():
    # the light at the eye casts no visible shadow: none traced; soft without an estimate is hard
    assert "SHADOW_SOFT" not in kernel_config.scene_config(Scene.default().with_overrides(["shading.light=eye"])).defines
    s = Scene.default().with_overrides(["fractal.algebra=hypercomplex", "shading.shadow=soft"])
    assert "SHADOW_SOFT" in kernel_config.scene_config(s).defines     # light.cl takes the hard path: no estimate


@pytest.mark.parametrize("over,key", [
    (["shading.colormap=jet2"], "shading.colormap"),
    (["shading.shadow=penumbra"], "shading.shadow"),
    (["shading.ao=2"], "shading.ao"),
])
def test_light_settings_refused(over, key):
    from pyjulia4d.scene.checks import SceneError
    with pytest.raises(SceneError) as e:
        Scene.default().with_overrides(over)
    assert str(e.value).startswith(key + ": ")


EVERYTHING = ["shading.light=-3,4,-2", "shading.ao=0.5", "shading.fog=0.3", "clip.planes=0,0,-1,0;1,0,0,0.5",
              "image.samples=2", "image.width=16", "image.height=12"]


@pytest.mark.parametrize("extra", [
    ["shading.shadow=soft", "shading.coloring=iteration", "shading.reflection=0.3",
     "shading.lights=position 2,1,-2; direction 0,-1,0 intensity 0.3"],
    pytest.param(["shading.shadow=hard", "shading.coloring=trap", "march.method=fixed", "normals.method=zbuffer",
                  "image.adaptive=true"], marks=pytest.mark.slow),
    ["shading.shadow=soft", "shading.coloring=w", "render.float=double", "normals.method=gradient",
     "shading.reflection=0.5", "shading.lights=direction 1,1,-1 color 0.2,0.3,1"],
    pytest.param(["shading.coloring=trap", "fractal.algebra=hypercomplex", "fractal.function=sin",
                  "shading.lights=position -2,2,-2; position 2,-2,-2; position 0,3,0"], marks=pytest.mark.slow),
    pytest.param(["shading.coloring=iteration", "fractal.algebra=cquat", "shading.specular=0",
                  "fractal.kind=mandelbrot", "fractal.max_iter=8", "shading.reflection=0.2"], marks=pytest.mark.slow),
    ["shading.shadow=soft", "fractal.algebra=hypercomplex", "fractal.function=cube", "render.variant=scalar",
     "shading.reflection=0.4", "image.adaptive=true", "shading.sky=0.5,0.6,1"],
])
def test_every_switch_together_builds_and_stays_finite(extra):
    # the -D switches of one scene meet in one program: none may clash (a shared name, a
    # missing piece); the picture stays finite
    from pyjulia4d.opencl.executor import render
    r = render(Scene.default().with_overrides(EVERYTHING + extra))
    assert np.all(np.isfinite(r.color)) and np.all(np.isfinite(r.alpha))
    assert r.hit_fraction > 0


@pytest.mark.parametrize("light", ["eye", "2,3,-4"])
@pytest.mark.parametrize("fl", ["single", "double"])
def test_reflect_kernels_match_reference(light, fl):
    """shade/reflect.cl's two kernels against their twins on the same random hits: the
    reflected rays to float rounding of their precision, the bounce's colour to float32."""
    s = Scene.default().with_overrides([f"shading.light={light}", "shading.reflection=0.5",
                                        "shading.sky=0.3,0.5,0.9", f"render.float={fl}"])
    R = Runner(kernel_config.shade_config(s))
    fr = camera_frame(s)
    rng = np.random.default_rng(7)
    n = 3000
    status = rng.integers(0, 3, n).astype(np.int32)
    point = (rng.normal(size=(n, 4)) * 0.5).astype(R.real).astype(float)
    nrm = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = nrm.astype(R.real).astype(float)
    o, d = R.out4(n), R.out4(n)
    R.named("reflect_rays", (n,), point=R.buf4(point), normal=R.buf4(np.c_[nrm, np.zeros(n)]),
            status=R.buf(status, np.int32), eye=fr.position, right=fr.right, up=fr.up,
            forward=fr.forward, bias=0.01, radius=2.0, origins=o, dirs=d)
    got_o, got_d = R.get4(o), R.get4(d)
    want_o, want_d = ref.reflect_rays(point, nrm, status, fr, 0.01, 2.0)
    tol = 1e-5 if fl == "single" else 1e-12
    np.testing.assert_allclose(got_d, want_d, atol=tol)
    np.testing.assert_allclose(got_o, want_o, atol=tol)
    hit = status == 1
    # a mirror keeps the angle: d'.n = -d.n, and |d'| = 1
    nw = nrm[:, :1] * fr.right + nrm[:, 1:2] * fr.up - nrm[:, 2:3] * fr.forward
    dv = point - fr.position
    dv /= np.linalg.norm(dv, axis=1, keepdims=True)
    np.testing.assert_allclose(np.sum(got_d * nw, 1)[hit], -np.sum(dv * nw, 1)[hit], atol=10 * tol)
    # the bounce's colour: kernel and twin take the plan's shading record
    plan = make_plan(s, "CPU", 1)
    out = R.out(n, cl.cltypes.float4)
    packed = Packed(signatures.REFLECT_COLOR, plan.records(), Precision(fl == "double"))
    R("reflect_color", (n,), *packed(status=R.buf(status, np.int32), normal=R.buf4(np.c_[nrm, np.zeros(n)]),
                                     point=R.buf4(point), dirs=R.buf4(want_d), refl=out))
    got = out.get().view(np.float32).reshape(n, 4)
    want = ref.reflect_color(status, nrm, point, want_d.astype(R.real).astype(float), plan.frame, plan.shade)
    np.testing.assert_allclose(got, want, atol=2e-5)


def test_reflection_shows_in_the_picture_and_zbuffer_is_refused():
    from pyjulia4d.opencl.executor import render
    from pyjulia4d.scene.checks import SceneError
    base = Scene.default().with_overrides(["image.width=48", "image.height=36", "shading.background=0,0,1"])
    plain, mirror = render(base), render(base.with_overrides(["shading.reflection=0.5"]))
    np.testing.assert_array_equal(plain.depth, mirror.depth)
    hit = plain.status == 1
    # half the colour is now the bounce's: the blue background shows in the set's surface
    assert mirror.color[hit][:, 2].mean() > plain.color[hit][:, 2].mean() + 0.05
    with pytest.raises(SceneError, match=r"^shading\.reflection: needs normals\.method"):
        base.with_overrides(["shading.reflection=0.5", "normals.method=zbuffer"])


def test_lights_and_reflection_compile_only_where_used():
    """shade/reflect.cl and the extra lights' code are compiled only in scenes that use them
    (-D REFLECTION, -D EXTRA_LIGHTS=k, -D EXTRA_SHADOWS)."""
    plain = Scene.default()
    src = kernel_config.source(kernel_config.scene_config(plain))
    assert '"shade/reflect.cl"' not in src and "EXTRA_LIGHTS" not in kernel_config.scene_config(plain).defines
    lit = plain.with_overrides(["shading.lights=position 1,2,3; direction 0,1,0", "shading.reflection=0.2"])
    cfg = kernel_config.scene_config(lit)
    assert '"shade/reflect.cl"' in kernel_config.source(cfg)
    assert {"REFLECTION", "EXTRA_LIGHTS=2", "EXTRA_SHADOWS"} <= set(cfg.defines)
    # no shadows: the extra lights shine, but no shadow rays are compiled for them
    assert "EXTRA_SHADOWS" not in kernel_config.scene_config(lit.with_overrides(["shading.shadow=none"])).defines


@pytest.mark.parametrize("name", ["soft+ao", "hard+trap", "three-lights-soft", "w", "mandelbrot-trap",
                                  "proven-soft+ao"])
def test_packet_pairs_light_the_same_pixels(name):
    """Two packets per work-item (-D PACKET_PAIRS: the march's and the light terms' shadow rays
    and occlusion, their estimates side by side; for the proven march, the light terms' alone,
    -D MARCH_UNPAIRED) give every output of one packet per work-item, bit for bit, on a tile
    whose last pair of blocks is cut by the edge."""
    import dataclasses

    from harness import device, packet_widths
    from pyjulia4d.opencl.executor import run_plan
    from pyjulia4d.pipeline.plan import make_plan

    lanes = max(packet_widths((8, 16)), default=None)
    if lanes is None:
        pytest.skip("no packet width on this device")
    proven = name.startswith("proven-")
    over = LIGHT_SCENES[name.removeprefix("proven-")] + (["march.quality=normal"] if proven else [])
    s = Scene.default().with_overrides(over + ["image.width=44", "image.height=30"])
    dev = device()
    pair, one = make_plan(s, dev, lanes, pairs=True), make_plan(s, dev, lanes, pairs=False)
    assert pair.march_packets == (1 if proven else 2) and one.march_packets == 1 and pair.light_terms
    assert pair.light_packets == 2 and one.light_packets == 1
    a, b = run_plan(pair, dev), run_plan(one, dev)
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y, equal_nan=True), f.name


@pytest.mark.parametrize("kind", ["julia", "mandelbrot"])
def test_iteration_value_matches_its_twin(kind):
    # the colour value alone: ambient light only, through a ramp that is the identity in sRGB,
    # so each hit's colour is its iteration value (the smooth time its orbit stays in the unit
    # ball, shade/light.cl orbit_value); kernel and float64 twin on pixels both hit at one
    # depth: the value's float32 rounding, except where an orbit grazes |q| = 1 and the two
    # precisions leave the ball an iteration apart (measured: none at 1e-3 on 99 %)
    from pyjulia4d.opencl.executor import render
    from pyjulia4d.pipeline.colormap import linear_to_srgb

    keys = ["shading.coloring=iteration", "shading.gradient=[[0, 0, 0, 0], [1, 1, 1, 1]]", "shading.ambient=1",
            "shading.diffuse=0", "shading.specular=0", "shading.shadow=none", "shading.ao=0", "image.width=40",
            "image.height=30", "march.quality=custom", "fractal.max_iter=10"]
    if kind == "mandelbrot":
        keys += ["fractal.kind=mandelbrot", "camera.position=0.4,2.2,-3.2,0", "camera.target=-0.5,0,0,0"]
    s = Scene.default().with_overrides(keys)
    k, r = render(s), ref.render(s)
    with np.errstate(invalid="ignore"):
        both = (k.status == 1) & (r.status == 1) & (np.abs(k.depth - r.depth) < 1e-5)
    vk, vr = (linear_to_srgb(np.clip(x.color[both][:, 0], 0, 1)) for x in (k, r))
    assert both.sum() > 100 and np.ptp(vr) > 0.2   # the value varies over the surface
    assert np.mean(np.abs(vk - vr) < 1e-3) > 0.99, np.percentile(np.abs(vk - vr), [50, 99, 100])
