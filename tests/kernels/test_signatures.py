"""Every kernel's host-side record (pipeline/signatures.py) matches the kernel the device
compiles: each program a plan builds is built again with -cl-kernel-arg-info, and every
kernel's parameters - names, types, address space, const - must be the signature's, in its
order, under the program's own -D switches.  A parameter added to a .cl piece and not to its
record (or two swapped) fails here, where packing would otherwise pass it silently by type.
Also: every kernel declared in kernels/ has a signature, and every signature a kernel."""
from __future__ import annotations

import re
import warnings

import pyopencl as cl
import pytest

from harness import device
from pyjulia4d import Scene
from pyjulia4d.opencl import build
from pyjulia4d.opencl.runner import queue_for
from pyjulia4d.pipeline import kernel_config, signatures
from pyjulia4d.pipeline.kernel_config import KernelConfig
from pyjulia4d.pipeline.path_plan import path_config
from pyjulia4d.resources import kernel_dir

K = kernel_config


def _scene(*keys: str) -> Scene:
    return Scene.default().with_overrides(["image.width=8", "image.height=6", *keys])


SHADING = ("shading.coloring=trap", "shading.reflection=0.3", "shading.fog=0.2", "clip.planes=0,0,1,0.2",
           "shading.lights=position 3,1,-2 color 0.3,0.5,1 intensity 0.9", "shading.ao=0.5")

# (name, config): the programs real plans build, across the switches that change signatures
CONFIGS = {
    "march_one_ray": lambda: K.march_config(_scene(), 1),
    "march_packets_pairs": lambda: K.march_config(_scene(), 8, pairs=True),
    "march_clip_light": lambda: K.march_config(_scene(*SHADING), 4),
    "march_given_rays": lambda: K.march_config(_scene(*SHADING), 4, ray_buffers=True),
    "march_proven_double": lambda: K.march_config(_scene("march.quality=normal", "render.float=double"), 1),
    "march_counted": lambda: KernelConfig(K.march_config(_scene(), 1).pieces,
                                          K.march_config(_scene(), 1).defines + ("COUNT_ITERATIONS",)),
    "shade": lambda: K.shade_config(_scene(*SHADING)),
    "shade_gradient": lambda: K.shade_config(_scene("normals.method=gradient", *SHADING)),
    "shade_zbuffer": lambda: K.shade_config(_scene("normals.method=zbuffer")),
    "whole_scene": lambda: K.scene_config(_scene("march.quality=normal", *SHADING), ray_buffers=True),
    "path": lambda: path_config(_scene("shading.integrator=path", *SHADING)),
    "path_gradient_double": lambda: path_config(_scene("shading.integrator=path", "normals.method=gradient",
                                                       "render.float=double")),
    "mesh": lambda: K.mesh_config(_scene()),
    "mesh_clip": lambda: K.mesh_config(_scene("clip.planes=0,-1,0,0.3")),
    "probe": lambda: K.probe_config(_scene()),
}
SAMPLE = ("march_packets_pairs", "march_clip_light", "shade", "path", "mesh", "mesh_clip")


def _declared(kernel: cl.Kernel) -> list[tuple[str, str]]:
    """(name, type as signatures.py writes it) of each of the compiled kernel's parameters."""
    info, out = cl.kernel_arg_info, []
    for i in range(kernel.num_args):
        name = kernel.get_arg_info(i, info.NAME)
        type_ = kernel.get_arg_info(i, info.TYPE_NAME)
        if kernel.get_arg_info(i, info.ADDRESS_QUALIFIER) == cl.kernel_arg_address_qualifier.GLOBAL:
            const = kernel.get_arg_info(i, info.TYPE_QUALIFIER) & cl.kernel_arg_type_qualifier.CONST
            type_ = f"global {'const ' if const else ''}{type_}"
        out.append((name, type_))
    return out


@pytest.mark.parametrize("name", [pytest.param(n, marks=() if n in SAMPLE else pytest.mark.slow) for n in CONFIGS])
def test_kernel_parameters_match_their_signature(name: str) -> None:
    config = CONFIGS[name]()
    ctx, _ = queue_for(device())
    # built from source every time: a binary from pyopencl's cache carries no argument info
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cl.CompilerWarning)
        prg = cl.Program(ctx, K.source(config)).build(
            options=build.options(config, device()) + ["-cl-kernel-arg-info"], cache_dir=False)
    kernels = prg.all_kernels()
    assert kernels
    for k in kernels:
        sig = signatures.SIGNATURES[k.function_name]
        got = _declared(k)
        assert got[0] in (("n_items", "int"), ("n", "int")), (k.function_name, got[0])   # launch() passes it
        want = [(p.name, p.type) for p in sig.compiled(config.defines)]
        assert got[1:] == want, k.function_name


KERNEL = re.compile(r"^(?:__kernel|PACKET_KERNEL)\s+void\s+(\w+)\s*\(", re.M)


def test_every_kernel_has_one_signature() -> None:
    """The kernels the .cl files declare and the signatures are the same set, each signature
    naming the piece that declares its kernel."""
    declared = {}
    for path in kernel_dir().rglob("*.cl"):
        for m in KERNEL.finditer(path.read_text()):
            declared[m.group(1)] = path.relative_to(kernel_dir()).with_suffix("").as_posix()
    assert declared == {s.kernel: s.piece for s in signatures.SIGNATURES.values()}


def test_packing_refuses_a_missing_or_unknown_name() -> None:
    import numpy as np

    from pyjulia4d.opencl.records import Packed, Precision
    from pyjulia4d.pipeline.plan import make_plan

    plan = make_plan(_scene("clip.planes=0,0,1,0.2"), "CPU", 1)
    packed = Packed(signatures.CLIP, plan.records(), Precision(False))
    args = packed(flags=1, status=2, normal=3)
    assert args[-1] == 3 and args[:2] == (1, 2)
    assert np.array_equal(np.array(args[2].tolist()), np.array(tuple(plan.frame.right)).astype(np.float32))
    with pytest.raises(TypeError, match="missing \\['normal'\\]"):
        packed(flags=1, status=2)
    with pytest.raises(TypeError, match="unexpected \\['depth'\\]"):
        packed(flags=1, status=2, normal=3, depth=4)
