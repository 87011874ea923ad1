"""How many rays a work-item of the march carries on a device (kernels/common/lanes.cl, "Lanes").

CPUs run a packet of rays per work-item in their vector lanes (PoCL does not vectorise a
data-dependent loop across work-items: the packet march of the default scene runs 5x
(8 lanes) to 7x (16 lanes) faster than one ray per work-item on the 2-core AVX-512
development machine); GPUs run one ray per work-item.  Which widths a CPU driver survives
is found by a probe that cannot take a render down: a child process builds and runs the
packet march at 16, then 8, then 4 lanes on a tiny scene and compares it with the one-ray
kernel; the widest that passes is used.  Double precision has its own probe, of 8 and 4
lanes: eight doubles fill the register sixteen floats do, and 16 ran slower than 8 on both
CPU runtimes here (default scene, 320x240: 1.4x slower on Intel's, 1.0x on PoCL).  PyPI's
PoCL 3.0 killed the process with SIGSEGV on float16 kernels, which is why the probe runs
apart.  The answer is cached per device and
driver version in ``~/.cache/pyjulia4d/lanes.json`` and ``lanes_double.json``
(``PYJULIA4D_CACHE`` moves them); the proven march's own width in ``lanes_proven.json``
(PROVEN_LANES below).
"""
from __future__ import annotations

import subprocess
import sys
import warnings

import pyopencl as cl

from pyjulia4d.opencl.devices import device_type, remembered

WIDTHS = (16, 8, 4)
DOUBLE_WIDTHS = (8, 4)


_PROBE = r"""
import sys, warnings
warnings.simplefilter("ignore")
import numpy as np
from pyjulia4d import Scene
from pyjulia4d.opencl.devices import select_device
from pyjulia4d.opencl.executor import render
spec, lanes, prec = sys.argv[1], int(sys.argv[2]), sys.argv[3]
dev = select_device(spec)
s = Scene.default().with_overrides(["image.width=37", "image.height=29", "march.post_steps=6",
                                    "render.float=" + prec])
one = render(s, device=dev, lanes=1)
pk = render(s, device=dev, lanes=lanes)
same = np.mean(one.status == pk.status) >= 0.99
hit = (one.status == 1) & (pk.status == 1)
close = np.mean(np.abs(one.depth[hit] - pk.depth[hit]) <= one.bracket[hit] + pk.bracket[hit] + 1e-5) >= 0.99
print("ok" if same and close else "wrong")
"""


def device_spec(device: cl.Device) -> str:
    """The ``P:D`` index of ``device`` (devices.select_device understands it)."""
    for pi, p in enumerate(cl.get_platforms()):
        try:
            for di, d in enumerate(p.get_devices()):
                if d.int_ptr == device.int_ptr:
                    return f"{pi}:{di}"
        except cl.Error:
            continue
    raise ValueError("device not found among the platforms")


def probe(device: cl.Device, timeout: float = 120.0, double: bool = False) -> int | None:
    """The widest of WIDTHS (DOUBLE_WIDTHS with ``double``) whose packet march builds, runs and
    agrees with one ray per work-item in a child process; 1 if none does; None where no width
    passed and one ran out of ``timeout`` (undecided: a width that only timed out on a busy
    machine is not known to fail, so the answer is not cached)."""
    spec = device_spec(device)
    undecided = False
    for lanes in DOUBLE_WIDTHS if double else WIDTHS:
        said = _child(_PROBE, [spec, str(lanes), "double" if double else "single"], timeout)
        if said is None:
            undecided = True
        elif said == "ok":
            return lanes
    return None if undecided else 1


def _child(source: str, args: list[str], timeout: float) -> str | None:
    """The last word a probe (Python ``source`` run apart, with ``args``) printed where it
    exited cleanly, "" where it failed, None where it ran out of ``timeout``."""
    try:
        p = subprocess.run([sys.executable, "-c", source, *args], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    words = p.stdout.split()
    return words[-1] if p.returncode == 0 and words else ""


# The proven march's lanes part ways more than the scan's or the estimate's (each proves
# segments of its own lengths, each enclosure runs to its own iteration), so narrower packets
# may idle less; which width is faster depends on the CPU.  On an AMD EPYC at 8 lanes it took
# 0.74-0.88x its time at 16 on the hypercomplex sin, cosh and pwr, the CQuat cube and the
# quaternion default (320x240, normal, interleaved renders); on an Intel Xeon, with partial
# proofs, 16 lanes took 0.55-1.0x the time of 8 on the same scenes at 640x480
# (benchmarks/speed/proven_speed.py).  So where the device takes wider packets, a timed probe
# (a child process: the default scene at normal, 160x120, both widths built, then the least
# march time of three interleaved renders each) picks between PROVEN_LANES and the width,
# once per device and driver (``lanes_proven.json``).
PROVEN_LANES = 8

_PROVEN_PROBE = r"""
import sys, warnings
warnings.simplefilter("ignore")
from pyjulia4d import Scene
from pyjulia4d.opencl.devices import select_device
from pyjulia4d.opencl.executor import render
dev = select_device(sys.argv[1])
widths = [int(w) for w in sys.argv[2:]]
s = Scene.default().with_overrides(["image.width=160", "image.height=120", "march.quality=normal"])
for w in widths:
    render(s, device=dev, lanes=w, calibrate=False)   # built and warm
best = {w: float("inf") for w in widths}
for _ in range(3):
    for w in widths:
        best[w] = min(best[w], render(s, device=dev, lanes=w, calibrate=False).kernel_seconds)
print(min(widths, key=lambda w: best[w]))
"""


def probe_proven(device: cl.Device, widths: tuple[int, ...], timeout: float = 120.0) -> int | None:
    """The fastest of ``widths`` for the proven march on ``device`` (the timed probe above, in a
    child process); None where it failed or ran out of ``timeout`` (undecided: not cached)."""
    try:
        said = _child(_PROVEN_PROBE, [device_spec(device), *map(str, widths)], timeout)
    except ValueError:   # the device is on no platform
        return None
    return int(said) if said and said.isdigit() and int(said) in widths else None


def march_lanes(width: int, method: str, device: cl.Device | None = None) -> int:
    """The packet width of a march: the probed ``width``; for the proven march (march.method
    resolved), where ``width`` is wider than PROVEN_LANES, the faster of the two on ``device``
    (probe_proven, remembered), else PROVEN_LANES."""
    if method != "proven" or width <= PROVEN_LANES:
        return width
    if device is None:
        return PROVEN_LANES
    got = remembered("lanes_proven", device, int, lambda d: probe_proven(d, (PROVEN_LANES, width)))
    return got if got in (PROVEN_LANES, width) else PROVEN_LANES


def lanes_for(device: cl.Device, variant: str, double: bool) -> int:
    """Rays per work-item of the march for ``render.variant`` on ``device``: 1 for
    "scalar" and for GPUs under "auto"; for "packet", or a CPU under "auto", the width
    probed for the precision (cached)."""
    if variant == "scalar":
        return 1
    if variant == "auto" and device_type(device) != "CPU":
        return 1
    if double:
        width = remembered("lanes_double", device, int, lambda d: probe(d, double=True))
    else:
        width = remembered("lanes", device, int, probe)
    if width is None:
        warnings.warn("render.variant: the packet-width probe ran out of time (a busy machine?); "
                      "this process marches one ray per work-item, and the next one probes again",
                      RuntimeWarning, stacklevel=2)
        return 1
    return int(width)


def packet_pairs(device: cl.Device, lanes: int, double: bool) -> bool:
    """Whether a work-item of the march takes two packets of ``lanes`` rays (kernel_config.
    march_packets): where one packet fills no more than one of the device's vector registers
    (its native vector width in floats or doubles; 16 floats in AVX-512).  There one packet's
    march is a single chain of dependent operations that leaves the vector units waiting, and two
    side by side took 0.83x the march's time and 0.78x the light terms' on the default scene;
    with AVX2's 8-float registers a packet of 16 is already two chains, and pairs took 1.02x
    (benchmarks/speed/commit_ratio.py, docs/performance.md)."""
    if lanes <= 1:
        return False
    try:
        width = device.native_vector_width_double if double else device.native_vector_width_float
    except (cl.Error, AttributeError):
        return False
    return 0 < width and lanes <= width
