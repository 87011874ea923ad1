"""What a device can do, read from the device at run time and passed to every build as -D switches.

A compiler's predefined macros say what its front end knows, not what the device links:
Oclgrind 21.10 defines ``cl_intel_subgroups`` and then has no ``sub_group_any`` ("Undefined
external function", and ``clCreateKernel`` fails with INVALID_KERNEL_NAME), and NVIDIA's and
AMD's compilers differ from Intel's in what they define.  So the kernels read only these
switches (kernels/common/lanes.cl):

- ``DEV_FP64``: the device names ``cl_khr_fp64`` (or reports a double-precision config);
- ``DEV_SUBGROUPS``: a sub-group vote (``sub_group_any``) builds, links and answers right
  on this device, through ``cl_intel_subgroups`` or ``cl_khr_subgroups``
  (``DEV_KHR_SUBGROUPS`` with the latter's pragma);
- ``DEV_CL_C``: the OpenCL C version, as 100 x major + 10 x minor (120 for 1.2);
- ``DEV_MAX_WORK_GROUP`` and ``DEV_LOCAL_MEM``: the largest work-group and the local
  memory in bytes.

Whether the vote works is found once per driver by running it (``devices.remembered``,
``<cache>/subgroups.json``): a tiny kernel is built, made and run on 128 items with one
vote raised, and its answer checked.  A device that names a sub-group extension but fails
that falls back to the per-work-item branch and says so once, where it is found.
"""
from __future__ import annotations

import re
import warnings
from dataclasses import dataclass

import numpy as np
import pyopencl as cl

from pyjulia4d.opencl.devices import build, has_fp64, remembered

# the extensions that give sub_group_any, by preference; the vote itself is the same builtin
SUBGROUP_EXTENSIONS = ("cl_intel_subgroups", "cl_khr_subgroups")

_VOTE = """
#ifdef DEV_KHR_SUBGROUPS
#pragma OPENCL EXTENSION cl_khr_subgroups : enable
#endif
__kernel void vote(__global const int *in, __global int *out)
{
    size_t i = get_global_id(0);
    out[i] = sub_group_any(in[i]) ? 1 : 0;
}
"""
VOTE_ITEMS = 128
VOTE_GROUP = 64


@dataclass(frozen=True)
class Capabilities:
    """One device's capabilities as the kernels see them (module docstring)."""
    fp64: bool
    subgroups: str          # the extension the vote links through; "" where none does
    named: tuple[str, ...]  # the sub-group extensions the device names
    cl_c: int               # OpenCL C version, 100 x major + 10 x minor
    max_work_group: int
    local_mem: int

    def defines(self) -> tuple[str, ...]:
        """The -D switches of every build on this device."""
        out = [f"DEV_CL_C={self.cl_c}", f"DEV_MAX_WORK_GROUP={self.max_work_group}",
               f"DEV_LOCAL_MEM={self.local_mem}"]
        if self.fp64:
            out.append("DEV_FP64")
        if self.subgroups:
            out.append("DEV_SUBGROUPS")
            if self.subgroups == "cl_khr_subgroups":
                out.append("DEV_KHR_SUBGROUPS")
        return tuple(out)

    def describe(self) -> str:
        """For ``pyjulia4d devices``: the sub-group vote, and why not where it is named but fails."""
        if self.subgroups:
            return f"sub-groups through {self.subgroups}"
        if self.named:
            return f"names {', '.join(self.named)} but its sub-group vote does not link: built without"
        return "no sub-groups"


def cl_c_version(text: str) -> int:
    """100 x major + 10 x minor of an ``OpenCL C <major>.<minor> ...`` text (120 where unreadable:
    the version every OpenCL 1.2 device has)."""
    m = re.search(r"OpenCL C (\d+)\.(\d+)", text or "")
    return 100 * int(m.group(1)) + 10 * int(m.group(2)) if m else 120


def _info(device: cl.Device, name: str, default):
    try:
        return getattr(device, name)
    except (cl.Error, AttributeError):
        return default


def _vote_works(device: cl.Device, extension: str) -> bool:
    """Whether sub_group_any builds, links, is made into a kernel and answers right through
    ``extension`` on ``device``: every item 0, every item 1, and one raised vote seen by its
    own item and by no item of another work-group."""
    try:
        ctx = cl.Context([device])
        opts = ["-DDEV_KHR_SUBGROUPS"] if extension == "cl_khr_subgroups" else []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prg = build(cl.Program(ctx, _VOTE), opts)
            k = cl.Kernel(prg, "vote")
        queue = cl.CommandQueue(ctx)
        mf = cl.mem_flags
        got = []
        for raised in (None, "all", 5):
            inp = np.zeros(VOTE_ITEMS, np.int32)
            if raised == "all":
                inp[:] = 1
            elif raised is not None:
                inp[raised] = 1
            a = cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=inp)
            b = cl.Buffer(ctx, mf.WRITE_ONLY, inp.nbytes)
            k(queue, (VOTE_ITEMS,), (VOTE_GROUP,), a, b)
            out = np.empty_like(inp)
            cl.enqueue_copy(queue, out, b)
            queue.finish()
            got.append(out)
        none, every, one = got
        return (not none.any() and every.all() and one[5] == 1
                and not one[VOTE_GROUP:].any() and set(np.unique(one)) <= {0, 1})
    except (cl.Error, RuntimeError, ValueError):
        return False


def _find_subgroups(device: cl.Device) -> str:
    """The first of SUBGROUP_EXTENSIONS the device names whose vote works; "" if none."""
    named = [e for e in SUBGROUP_EXTENSIONS if e in _info(device, "extensions", "").split()]
    for ext in named:
        if _vote_works(device, ext):
            return ext
    if named:
        warnings.warn(f"device '{device.name.strip()}' names {', '.join(named)} but its sub-group vote "
                      "does not build or run; its kernels are built without sub-groups",
                      RuntimeWarning, stacklevel=3)
    return ""


_known: dict[int, Capabilities] = {}


def capabilities(device: cl.Device) -> Capabilities:
    """The device's capabilities (module docstring), read once per device and process; the
    sub-group vote tried once per driver."""
    got = _known.get(device.int_ptr)
    if got is None:
        named = tuple(e for e in SUBGROUP_EXTENSIONS if e in _info(device, "extensions", "").split())
        subgroups = remembered("subgroups", device, str, _find_subgroups) if named else ""
        got = _known[device.int_ptr] = Capabilities(
            fp64=has_fp64(device), subgroups=subgroups, named=named,
            cl_c=cl_c_version(_info(device, "opencl_c_version", "")),
            max_work_group=int(_info(device, "max_work_group_size", 1)),
            local_mem=int(_info(device, "local_mem_size", 0)))
    return got
