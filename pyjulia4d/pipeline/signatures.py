"""Every kernel's parameters, declared once on the host: the record each launch packs.

A kernel's parameters after ``n_items`` (which ``opencl/runner.launch`` passes first) are
listed here in the order its ``.cl`` piece declares them, each with its OpenCL type, the
-D switch it is compiled under, and where its value comes from: a field of one of the
plan's records (``"march.c"``: ``Plan.records()["march"].c``) or, with no source, a value
the launch gives by name (the tile's place, a buffer).  Mandelbulber2 declares each
kernel's parameters once, as one struct shared by host and device; pbrt-v4 declares each
stage's records once.  OpenCL 1.2 kernels take no structs of vectors portably across
devices, so the host's one declaration is checked against the device's instead:
tests/kernels/test_signatures.py builds every kernel with ``-cl-kernel-arg-info`` under the
switches real plans use and compares names, types and order with these tables.  Adding a
parameter touches its ``.cl`` piece, its row here and its float64 twin; the test holds the
three together.

Pure Python: opencl/records.py packs a signature for a device's precision.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    """One kernel parameter: ``type`` as the .cl declares it, less a by-value ``const``
    ("int", "real4", "global const real4*"); ``source`` the plan record's field it takes
    ("" : given at launch by ``name``); ``when`` the -D switches it is compiled under, comma
    separated, all to hold ("X"; "!X": only without X; "" : always)."""
    name: str
    type: str
    source: str = ""
    when: str = ""

    @property
    def buffer(self) -> bool:
        return self.type.endswith("*")

    def compiled(self, defines) -> bool:
        """Whether a program built with ``defines`` (its -D switches) has this parameter."""
        names = {d.split("=")[0] for d in defines}
        return all((w[1:] not in names) if w.startswith("!") else (w in names)
                   for w in self.when.split(",") if w)


def P(decl: str, source: str = "", when: str = "") -> Param:
    """A Param from its declaration, "type name" ("global const real4* point")."""
    type_, _, name = decl.rpartition(" ")
    return Param(name, type_, source, when)


@dataclass(frozen=True)
class Signature:
    """A kernel's name, the piece that declares it, and its parameters after n_items."""
    kernel: str
    piece: str
    params: tuple[Param, ...]

    def compiled(self, defines) -> tuple[Param, ...]:
        """The parameters a program built with ``defines`` declares, in order."""
        return tuple(p for p in self.params if p.compiled(defines))

    def all_given(self) -> "Signature":
        """The same parameters, each value given at launch by name (no plan's records: the
        tests' runs of a kernel on values of their own)."""
        return Signature(self.kernel, self.piece, tuple(Param(p.name, p.type, "", p.when) for p in self.params))


def group(when: str, *params: Param) -> tuple[Param, ...]:
    """``params``, each compiled under ``when``."""
    return tuple(Param(p.name, p.type, p.source, when) for p in params)


# ---------------------------------------------------------------- the parameters several kernels share

CAMERA = (P("real4 eye", "camera.position"), P("real4 forward", "camera.forward"), P("real4 right", "camera.right"),
          P("real4 up", "camera.up"), P("real tan_half_fov", "camera.tan_half_fov"),
          P("int image_w", "image.width"), P("int image_h", "image.height"))
BASIS = (P("real4 right", "camera.right"), P("real4 up", "camera.up"), P("real4 forward", "camera.forward"))
ORBIT = (P("real4 c", "march.c"), P("int max_iter", "march.max_iter"), P("real bailout", "march.bailout"))
MARCH_CONSTANTS = ORBIT + (
    P("real epsilon", "march.epsilon"), P("real radius", "march.radius"), P("real near_set", "march.near"),
    P("real far_set", "march.far"), P("int z_resolution", "march.z_resolution"),
    P("int post_steps", "march.post_steps"), P("int max_steps", "march.max_steps"))
MARCH_OUT = (P("global real* depth"), P("global real4* point"), P("global int* status"), P("global int* samples"),
             P("global int* flags"), P("global real* bracket"), P("global real* unresolved"))
CLIP_NORMALS = (P("real4 clip_n0", "clip.clip_n0"), P("real4 clip_n1", "clip.clip_n1"),
                P("real4 clip_n2", "clip.clip_n2"), P("real4 clip_n3", "clip.clip_n3"))
SURFACE_COLOR = (P("float4 color", "shade.color"), P("float4 background", "shade.background"),
                 P("float4 light_color", "shade.light_color"), P("float4 sky", "shade.sky"),
                 P("float ambient", "shade.ambient"), P("float diffuse", "shade.diffuse"))

# ---------------------------------------------------------------- a render's kernels

CONE_STARTS = Signature("cone_starts", "march/cone", (
    P("int blocks_w"), P("int bx0"), P("int by0"), *CAMERA, *ORBIT, P("real radius", "march.radius"),
    P("real near_set", "march.near"), P("real far_set", "march.far"), P("int max_steps", "march.max_steps"),
    P("global real2* cone")))

MARCH = Signature("march", "march/march", (
    P("int tile_w"),
    # camera rays made in the kernel, or -D RAYS_FROM_BUFFERS: given rays (reflections, the tests)
    *group("!RAYS_FROM_BUFFERS", *CAMERA, P("int x0"), P("int y0"), P("int pixel_sample"), P("int pixel_samples")),
    *group("RAYS_FROM_BUFFERS", P("global const real4* origins"), P("global const real4* dirs")),
    *MARCH_CONSTANTS, *MARCH_OUT,
    P("global int* iter_count", when="COUNT_ITERATIONS,!LANES"),
    *group("CLIP", P("int n_clip", "clip.n_clip"), *CLIP_NORMALS, P("real4 clip_off", "clip.clip_off")),
    *group("CONE_START", P("global const real2* cone"), P("int cone_w"))))

NORMALS_JACOBIAN = Signature("normals_jacobian", "normals/jacobian", (
    P("global const real4* point"), P("global const int* status"), *ORBIT, *BASIS,
    P("global real4* normal"), P("global int* flags")))

NORMALS_GRADIENT = Signature("normals_gradient", "normals/gradient", (
    P("global const real4* point"), P("global const int* status"), *ORBIT, P("real h", "normals.step"),
    P("real h_per_distance", "normals.step_per_distance"), P("real4 eye", "camera.position"), *BASIS,
    P("global real4* normal"), P("global int* flags")))

NORMALS_ZBUFFER = Signature("normals_zbuffer", "normals/zbuffer", (
    P("global const real4* point"), P("global const real* depth"), P("global const int* status"), P("int width"),
    P("int height"), P("real4 eye", "camera.position"), *BASIS, P("global real4* normal"), P("global int* flags")))

CLIP = Signature("clip_normals", "march/clip", (
    P("global const int* flags"), P("global const int* status"), *BASIS, *CLIP_NORMALS, P("global real4* normal")))

LIGHT_TERMS = Signature("light_terms", "shade/light", (
    P("int tile_w"), P("global const real4* point"), P("global const real4* normal"), P("global const int* status"),
    P("global const real* bracket"), P("real4 eye", "camera.position"), *ORBIT, P("real epsilon", "march.epsilon"),
    *BASIS, P("real4 light_pos", "shade.light"), P("real radius", "march.radius"), P("real step", "light.step"),
    P("real bias", "light.bias"), P("real softness", "light.softness"), P("int max_steps", "light.max_steps"),
    P("real ao_distance", "light.ao_distance"), P("real ao_strength", "light.ao_strength"),
    P("real4 trap", "light.trap"), P("global const real4* lights_geo"), P("global const float4* lights_rgb"),
    P("global float4* terms"), P("global float4* vis_extra")))

SHADE = Signature("shade", "shade/shade", (
    P("global const int* status"), P("global const real4* normal"), P("global const real4* point"),
    P("real4 eye", "camera.position"), *BASIS, P("real4 light_pos", "shade.light"), *SURFACE_COLOR,
    P("float specular", "shade.specular"),
    P("float shininess", "shade.shininess"), P("global const float4* terms"), P("global const float4* lut"),
    P("int n_lut"), P("float fog", "shade.fog"), P("float fog_start", "shade.fog_start"),
    P("global const real4* lights_geo"), P("global const float4* lights_rgb"), P("global const float4* vis_extra"),
    P("global const float4* refl"), P("float reflection", "shade.reflection"), P("global float* rgba")))

REFLECT_RAYS = Signature("reflect_rays", "shade/reflect", (
    P("global const real4* point"), P("global const real4* normal"), P("global const int* status"),
    P("real4 eye", "camera.position"), *BASIS, P("real bias", "light.bias"), P("real radius", "march.radius"),
    P("global real4* origins"), P("global real4* dirs")))

REFLECT_COLOR = Signature("reflect_color", "shade/reflect", (
    P("global const int* status"), P("global const real4* normal"), P("global const real4* point"),
    P("global const real4* dirs"), *BASIS, P("real4 light_pos", "shade.light"), *SURFACE_COLOR,
    P("global float4* refl")))

# ---------------------------------------------------------------- the path tracer's kernels (kernels/path/path.cl)

TILE_PLACE = (P("int tile_w"), P("int x0"), P("int y0"))

PATH_CAMERA = Signature("path_camera", "path/path", (
    P("int n_pix"), *TILE_PLACE, P("real4 eye", "camera.position"), P("real4 forward", "camera.forward"),
    P("real4 right", "camera.right"), P("real4 up", "camera.up"), P("real tan_half_fov", "camera.tan_half_fov"),
    P("int image_w", "image.width"), P("int image_h", "image.height"), P("real aperture", "path.aperture"),
    P("real focus", "path.focus"), P("real radius", "march.radius"), P("int sample"), P("float noise", "path.noise"),
    P("int min_samples", "path.min_samples"), P("global const float4* film_m2"), P("global const int* film_count"),
    P("global real4* origins"), P("global real4* dirs"), P("global float4* thru"), P("global float4* rad")))

PATH_BOUNCE = Signature("path_bounce", "path/path", (
    P("int n_pix"), *TILE_PLACE, P("int image_w", "image.width"), P("int sample"), P("int bounce"), P("int bounces", "path.bounces"),
    P("global const int* status"), P("global const real4* point"), P("global const real4* normal"),
    P("global const real* bracket"), *ORBIT, *BASIS, P("real4 light_pos", "shade.light"),
    P("float4 light_color", "shade.light_color"), P("float light_radius", "shade.light_radius"),
    P("global const real4* lights_geo"), P("global const float4* lights_rgb"), P("global const float* lights_size"),
    P("float4 color", "shade.color"), P("float4 background", "shade.background"), P("float4 sky", "path.sky"), P("real sky_weight", "path.sky_weight"),
    P("real metallic", "path.metallic"), P("real alpha2", "path.alpha2"),
    P("real f0s", "path.f0s"), P("real emission", "path.emission"), P("real bias", "light.bias"), P("real radius", "march.radius"),
    P("real4 trap", "light.trap"), P("global const float4* lut"), P("int n_lut"), P("global real4* origins"),
    P("global real4* dirs"), P("global float4* thru"), P("global float4* rad"), P("global float4* pending"),
    P("global real4* s_origins"), P("global real4* s_dirs"), P("global float4* albedo"),
    P("global float4* first_normal"),
    *group("ENV_MAP", P("global const float4* env"), P("global const real* env_rows"), P("global const real* env_cols"),
           P("int env_w", "path.env_w"), P("int env_h", "path.env_h"), P("real4 env_x", "path.env_x"),
           P("real4 env_y", "path.env_y"), P("real4 env_z", "path.env_z"))))

PATH_SHADOW = Signature("path_shadow", "path/path", (
    P("global const int* status"), P("global const real* depth"), P("global const float4* pending"),
    P("global float4* rad")))

PATH_FILM = Signature("path_film", "path/path", (
    P("int batch"), P("global const float4* rad"), P("global const float4* albedo"), P("global const float4* first_normal"),
    P("global float4* film_mean"), P("global float4* film_m2"), P("global float4* film_albedo"),
    P("global float4* film_normal"), P("global int* film_count")))

# ---------------------------------------------------------------- the mesh's kernels (pipeline/mesh_plan.py)

MESH_ORBIT = (P("real radius2", "mesh.radius2"), P("real4 c", "mesh.c"), P("int max_iter", "mesh.max_iter"),
              P("real bailout", "mesh.bailout"))

MESH_CLIP = group("CLIP", P("int n_clip", "clip.n_clip"), *CLIP_NORMALS, P("real4 clip_off", "clip.clip_off"))

MESH_SAMPLE = Signature("mesh_sample", "mesh/mesh", (
    P("int nx"), P("int ny"), P("int k0"), P("real4 origin", "mesh.origin4"), P("real spacing", "mesh.spacing"),
    P("real4 rx", "mesh.rx"), P("real4 ry", "mesh.ry"), P("real4 rz", "mesh.rz"), P("real4 offset", "mesh.offset"),
    *MESH_ORBIT, *MESH_CLIP, P("global uchar* inside")))

MESH_VERTICES = Signature("mesh_vertices", "mesh/mesh", (
    P("global const real4* ends_a"), P("global const real4* ends_b"), *MESH_ORBIT, *MESH_CLIP, P("int steps", "mesh.steps"),
    P("global real4* vertex"), P("global real* width"), P("global real4* inside_end")))

# ---------------------------------------------------------------- the tests' kernels (each value given at launch)

GENERATE_RAYS = Signature("generate_rays", "rays", (
    P("real4 position"), P("real4 forward"), P("real4 right"), P("real4 up"), P("real tan_half_fov"),
    P("int width"), P("int height"), P("int x0"), P("int y0"), P("int tile_w"), P("global real4* origins"),
    P("global real4* dirs")))

PROBE_ITERATE = Signature("probe_iterate", "probe", (
    P("global const real4* points"), P("real4 c"), P("int max_iter"), P("real bailout"), P("global int* inside"),
    P("global real* distance"), P("global real* formula")))

PROBE_STEP = Signature("probe_step", "probe", (
    P("global const real4* points"), P("global const real4* dirs"), P("real4 c"), P("global real4* value"),
    P("global real4* jvp")))

PROBE_LBOUND = Signature("probe_lbound", "probe", (P("global const real4* points"), P("global real* lbound")))

PROBE_CFUN = Signature("probe_cfun", "probe", (
    P("global const real* re"), P("global const real* im"), P("global real* f_re"), P("global real* f_im"),
    P("global real* d_re"), P("global real* d_im")))

PROVE_SEGMENTS = Signature("prove_segments", "march/proven", (
    P("global const real4* origins"), P("global const real4* dirs"), P("global const real* t0s"),
    P("global const real* t1s"), P("real4 c"), P("int max_iter"), P("real bailout"), P("global int* proven"),
    P("global real* margins"), P("global real* prefixes")))

CAFF_OPS = Signature("caff_ops", "enclose/caff", (
    P("global const real4* a_mv"), P("global const real* a_r"), P("global const real4* b_mv"),
    P("global const real* b_r"), P("real4 k"), P("real bailout"), P("global real4* mul_mv"), P("global real* mul_r"),
    P("global real4* add_mv"), P("global real* add_r"), P("global real4* scale_mv"), P("global real* scale_r"),
    P("global int* outside")))

SIGNATURES = {s.kernel: s for s in (
    CONE_STARTS, MARCH, NORMALS_JACOBIAN, NORMALS_GRADIENT, NORMALS_ZBUFFER, CLIP, LIGHT_TERMS, SHADE, REFLECT_RAYS,
    REFLECT_COLOR, PATH_CAMERA, PATH_BOUNCE, PATH_SHADOW, PATH_FILM, MESH_SAMPLE, MESH_VERTICES, GENERATE_RAYS, PROBE_ITERATE, PROBE_STEP, PROBE_LBOUND,
    PROBE_CFUN,
    PROVE_SEGMENTS, CAFF_OPS)}

NORMALS = {"jacobian": NORMALS_JACOBIAN, "gradient": NORMALS_GRADIENT, "zbuffer": NORMALS_ZBUFFER}
