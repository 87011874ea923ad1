"""The kernel configuration a scene needs: which .cl pieces, in which order, with which -D
switches, and their concatenated source.

A scene compiles only the pieces it uses (the way Mandelbulber2 stitches only the
formula files a scene uses): one .cl file per concern, concatenated in data-flow
order, with -D switches for the optional terms.  Pure Python: the plan holds these
configurations, and build.py turns one into an OpenCL program.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from pyjulia4d.fractal.registry import (ALGEBRAS_TABLE, FUNCTIONS_TABLE, KINDS_TABLE, has_distance_estimate,
                                        kind_hooks, march_method)
from pyjulia4d.resources import kernel_dir
from pyjulia4d.scene.model import Scene


@dataclass(frozen=True)
class KernelConfig:
    """What to compile: the pieces (file stems, in order) and the -D switches."""
    pieces: tuple[str, ...]
    defines: tuple[str, ...] = ()


def iteration_pieces(scene: Scene) -> tuple[str, ...]:
    """common/codes.cl (status and guard codes), common/lanes.cl, complex arithmetic, the scene's one
    function (function/<name>.cl: a complex function and its derivative) and one algebra
    (algebra/<name>.cl: the map q -> f(q) + c built from them; a table algebra's powers from
    algebra/power.cl), the iteration: the pieces the registry (fractal/registry.py) names."""
    f = scene.fractal
    algebra = ALGEBRAS_TABLE[f.algebra]
    power = ("algebra/power",) if algebra.table else ()
    # fractal.theta != 0: the rotated map (kind/rotate.cl); fractal.kind other than "julia":
    # its set test after iterate.cl (kind/<kind>.cl, with kind/level.cl).  The default compiles
    # neither.
    rotate = ("kind/rotate",) if f.theta != 0 else ()
    kind_piece = KINDS_TABLE[f.kind].piece
    kind = ("kind/level", kind_piece) if kind_piece else ()
    return (("common/codes", "common/lanes", "algebra/complex", FUNCTIONS_TABLE[f.function].piece, algebra.piece) + power
            + rotate + ("iterate",) + kind)


def fractal_defines(scene: Scene) -> tuple[str, ...]:
    """pwr's complex exponent, compiled in (function/pwr.cl); the rotation's cos and sin
    (kind/rotate.cl); the kind's switches (fractal/kinds/<kind>.py defines: KIND_MANDELBROT for
    normals/jacobian.cl, a stack's c-line, the locus's critical point)."""
    f = scene.fractal
    out = ()
    if f.function == "pwr":
        out += (f"FUNC_EXPONENT_RE={f.exponent[0]!r}", f"FUNC_EXPONENT_IM={f.exponent[1]!r}")
        if f.exponent[1] == 0 and float(f.exponent[0]).is_integer():   # analytic across log's cut
            out += ("PWR_INTEGER",)
    if f.theta != 0:
        t = math.radians(f.theta)
        out += (f"ROTATE_COS={math.cos(t)!r}", f"ROTATE_SIN={math.sin(t)!r}")
    return out + kind_hooks(f.kind).defines(scene)   # the kind's own (fractal/kinds/<kind>.py)


def precision_defines(scene: Scene) -> tuple[str, ...]:
    return ("REAL_DOUBLE",) if scene.precision == "double" else ()


def cone_start(scene: Scene) -> bool:
    """Whether the camera rays' march starts where a cone of the block's centre ray reached
    (-D CONE_START, kernels/march/cone.cl): the distance-estimate march, unclipped."""
    return march_method(scene) == "de" and not scene.clip.planes


def scene_config(scene: Scene, ray_buffers: bool = False) -> KernelConfig:
    """Every piece and switch a scene uses, which march_config and shade_config divide between
    a render's two programs (the tests build it whole to reach any kernel).  The march makes its rays
    from the camera; ``ray_buffers`` (-D RAYS_FROM_BUFFERS) builds it to read given rays
    instead (the tests' and benchmarks' arbitrary rays)."""
    m = scene.march
    pieces = list(iteration_pieces(scene))
    defines = list(precision_defines(scene)) + list(fractal_defines(scene))
    if march_method(scene) == "proven":
        # circular arithmetic before the function pieces, which give their enclosures under
        # -D ENCLOSE; the algebra's orbit enclosure after the iteration, then the kind's orbits
        # (kernels/enclose/)
        i = pieces.index("algebra/complex") + 1
        pieces[i:i] = ["enclose/disc", "enclose/caff"]
        kind = KINDS_TABLE[scene.fractal.kind]
        pieces += ([] if kind.own_map else [ALGEBRAS_TABLE[scene.fractal.algebra].enclosure_piece]) + [kind.enclosure_piece]
        defines.append("ENCLOSE")
    pieces.append("march/refine")
    if m.refine == "itp":
        defines.append("REFINE_ITP")
    if ray_buffers:
        defines.append("RAYS_FROM_BUFFERS")
    if scene.clip.planes:
        defines.append("CLIP")
    pieces += [f"march/{march_method(scene)}", "rays"]
    if cone_start(scene) and not ray_buffers:
        pieces.append("march/cone")
        defines.append("CONE_START")
    pieces.append("march/march")
    if scene.clip.planes:
        pieces.append("march/clip")
    pieces.append(f"normals/{scene.normals.method}")
    light = light_defines(scene)
    if light:
        pieces.append("shade/light")
    if scene.shading.reflection > 0:   # one mirror bounce (shade/reflect.cl)
        pieces.append("shade/reflect")
        defines.append("REFLECTION")
    pieces.append("shade/shade")
    defines += light
    if scene.shading.specular > 0:
        defines.append("SPECULAR")
    if scene.shading.fog > 0:
        defines.append("FOG")
    if not isinstance(scene.shading.light, str):
        defines.append("LIGHT_POINT")
    if scene.shading.lights:   # shading.lights: compiled to their count
        defines.append(f"EXTRA_LIGHTS={len(scene.shading.lights)}")
    return KernelConfig(tuple(pieces), tuple(defines))


def shade_config(scene: Scene) -> KernelConfig:
    """The scene's program beside its march's (march_config): the iteration (for the gradient
    normal), rays.cl, the normals but the Jacobian, the cut faces' normals, shading and the
    mirror bounce, with the switches those read.  The march, the Jacobian normals and the
    light terms are the march's program's alone: compiled once, at its width (the one-ray
    march in this program too had taken three quarters of its build)."""
    cfg = scene_config(scene)
    keep = {"march/clip", "rays", "shade/reflect", "shade/shade", "normals/gradient", "normals/zbuffer"}
    pieces = iteration_pieces(scene) + tuple(p for p in cfg.pieces if p in keep)
    return KernelConfig(pieces, read_by(cfg.defines, {"shade"}))


# The programs' pieces that read each -D switch (a name, or a prefix ending in "_"), for the
# switches not every program's pieces read: a program leaves out those none of its pieces
# reads, so that scenes differing there alone share it.  "shade": shade/shade.cl,
# shade/reflect.cl, march/clip.cl; "light": shade/light.cl; "march": the march's pieces (the
# functions' enclosures, march/*.cl).  The rest (precision, the fractal's) every program reads.
SWITCH_READERS = {
    "SPECULAR": {"shade"}, "FOG": {"shade"}, "REFLECTION": {"shade"}, "LIGHT_TERMS": {"shade"},
    "COLORMAP": {"shade"},
    "LIGHT_POINT": {"shade", "light"}, "EXTRA_LIGHTS": {"shade", "light"}, "EXTRA_SHADOWS": {"shade", "light"},
    "AO": {"light"}, "SHADOW_": {"light"}, "COLOR_": {"light"},
    "CLIP": {"shade", "march"}, "ENCLOSE": {"march"}, "REFINE_ITP": {"march"}, "CONE_START": {"march"},
    "RAYS_FROM_BUFFERS": {"march"},
}


def read_by(defines, readers: set[str]) -> tuple[str, ...]:
    """The switches of ``defines`` that a program of ``readers`` (SWITCH_READERS' names) reads."""
    def wanted(d: str) -> bool:
        name = d.split("=")[0]
        key = next((k for k in SWITCH_READERS if name == k or (k.endswith("_") and name.startswith(k))), None)
        return key is None or bool(SWITCH_READERS[key] & readers)
    return tuple(d for d in defines if wanted(d))


def light_defines(scene: Scene) -> tuple[str, ...]:
    """The switches of shade/light.cl a scene uses (none: the piece is not compiled)."""
    sh = scene.shading
    out = []
    # the light at the eye lights every point the eye sees: its shadows are invisible, so
    # none are traced; soft shadows need the estimate (shade/light.cl: hard without one)
    if sh.shadow != "none" and (not isinstance(sh.light, str) or sh.lights):
        out.append(f"SHADOW_{sh.shadow.upper()}")
    if sh.shadow != "none" and sh.lights:
        out.append("EXTRA_SHADOWS")
    if sh.ao > 0:
        out.append("AO")
    if sh.coloring != "flat":
        out += [f"COLOR_{sh.coloring.upper()}", "COLORMAP"]
    return tuple(out + ["LIGHT_TERMS"]) if out else ()


# The pixel block a packet of rays covers, by lane count (kernels/common/lanes.cl BLOCK_W x
# BLOCK_H): square blocks keep a packet's rays closer together than a row would (the
# default scene's march: 0.031 s in 4x4 blocks against 0.040 s in rows of 16).
PACKET_BLOCKS = {16: (4, 4), 8: (4, 2), 4: (2, 2)}


def packet_block(lanes: int) -> tuple[int, int]:
    """(width, height) in pixels of a packet of ``lanes`` rays."""
    return PACKET_BLOCKS.get(lanes, (lanes, 1))


def march_packets(scene: Scene, lanes: int, pairs: bool = True) -> int:
    """Packets of ``lanes`` rays that a work-item of the march takes (kernels/march/march.cl): two
    (-D PACKET_PAIRS), their estimates computed side by side, where ``pairs`` asks for them
    (opencl/lanes.py packet_pairs: where a packet fills one vector register) and the march
    steps by the estimate of a Julia or Mandelbrot set (julia_distance_formula_pair,
    julia_level_pair: iterate.cl, kind/mandelbrot.cl); one otherwise, and with one ray per
    work-item."""
    f = scene.fractal
    both = pairs and lanes > 1 and march_method(scene) == "de" and KINDS_TABLE[f.kind].packet_pairs
    return 2 if both else 1


def light_packets(scene: Scene, lanes: int, pairs: bool = True) -> int:
    """Packets of ``lanes`` rays that a work-item of the light terms takes (kernels/shade/light.cl):
    the march's, or two where the march takes one but the shadow rays and occlusion step by a
    distance estimate all the same (the proven march of a set with one: -D MARCH_UNPAIRED), which
    took 0.70x their time on the default scene at the normal preset."""
    f = scene.fractal   # a march in pairs (the estimate's) implies all of these (scene/rules.py)
    return 2 if pairs and lanes > 1 and KINDS_TABLE[f.kind].packet_pairs and has_distance_estimate(f) else 1


def config_packets(config: KernelConfig) -> int:
    """The march's packets per work-item in a program built from ``config`` (march_packets)."""
    return 2 if "PACKET_PAIRS" in config.defines and "MARCH_UNPAIRED" not in config.defines else 1


def config_light_packets(config: KernelConfig) -> int:
    """The light terms' packets per work-item in a program built from ``config`` (light_packets)."""
    return 2 if "PACKET_PAIRS" in config.defines else 1


def march_config(scene: Scene, lanes: int, ray_buffers: bool = False, pairs: bool = False) -> KernelConfig:
    """The march's program: the march, its cone, the Jacobian normals when the scene uses them and
    the light terms, with ``lanes`` rays per work-item (-D LANES, kernels/common/lanes.cl; 1:
    one ray) and, with ``pairs``, two packets per work-item of the march where they apply
    (march_packets); the same pieces as scene_config up to march/march.cl.  The other normals
    and shading are shade_config's, one pixel per work-item."""
    cfg = scene_config(scene, ray_buffers)
    pieces = cfg.pieces[: cfg.pieces.index("march/march") + 1]
    if scene.normals.method == "jacobian":
        pieces += ("normals/jacobian",)
    light = "shade/light" in cfg.pieces
    if light:
        pieces += ("shade/light",)
    # scenes that differ in shading alone share this program, the costliest build (the
    # iteration inlined at every call, in packets)
    defines = read_by(cfg.defines, {"march", "light"} if light else {"march"})
    if lanes == 1:
        return KernelConfig(pieces, defines)
    bw, bh = packet_block(lanes)
    two = ("PACKET_PAIRS",) if march_packets(scene, lanes, pairs) == 2 else ()
    if not two and light and light_packets(scene, lanes, pairs) == 2:
        two = ("PACKET_PAIRS", "MARCH_UNPAIRED")
    return KernelConfig(pieces, defines + (f"LANES={lanes}", f"BLOCK_W={bw}", f"BLOCK_H={bh}") + two)



def mesh_config(scene: Scene) -> KernelConfig:
    """The mesh's sampling and vertex kernels (kernels/mesh/mesh.cl): the iteration, the
    scene's refinement (march/refine.cl) and the mesh piece, cut by the clip planes (CLIP)."""
    defines = precision_defines(scene) + fractal_defines(scene)
    if scene.march.refine == "itp":
        defines += ("REFINE_ITP",)
    if scene.clip.planes:
        defines += ("CLIP",)
    return KernelConfig(iteration_pieces(scene) + ("march/refine", "mesh/mesh"), defines)


def probe_config(scene: Scene) -> KernelConfig:
    """The iteration alone, wrapped for the tests (kernels/probe.cl)."""
    return KernelConfig(iteration_pieces(scene) + ("probe",), precision_defines(scene) + fractal_defines(scene))


def source(config: KernelConfig) -> str:
    """Concatenated source; #line keeps compiler messages pointing at the .cl file."""
    d = kernel_dir()
    parts = []
    for name in config.pieces:
        path = d / f"{name}.cl"
        parts.append(f'#line 1 "{name}.cl"\n' + path.read_text())
    return "\n".join(parts)
