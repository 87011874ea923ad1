"""OpenCL device discovery and selection."""
from __future__ import annotations

import pyopencl as cl


class DeviceError(ValueError):
    """No OpenCL device, or none matching the request."""


def _indexed() -> list[tuple[str, cl.Platform, cl.Device]]:
    """(``"P:D"``, platform, device) for every device; [] without OpenCL."""
    try:
        platforms = cl.get_platforms()
    except cl.Error:  # no ICD / no platform raises rather than returning []
        return []
    out = []
    for pi, p in enumerate(platforms):
        try:
            devices = p.get_devices()
        except cl.Error:  # a platform without devices raises DEVICE_NOT_FOUND
            continue
        out.extend((f"{pi}:{di}", p, d) for di, d in enumerate(devices))
    return out


def list_devices() -> list[tuple[cl.Platform, cl.Device]]:
    """Every (platform, device) pair, in platform then device order; [] without OpenCL."""
    return [(p, d) for _, p, d in _indexed()]


def device_type(device: cl.Device) -> str:
    """"GPU", "CPU", "ACCELERATOR" or "OTHER"."""
    t = device.type
    for name in ("GPU", "CPU", "ACCELERATOR"):
        if t & getattr(cl.device_type, name):
            return name
    return "OTHER"


def has_fp64(device: cl.Device) -> bool:
    """Whether the device can run the double-precision kernels."""
    try:
        if "cl_khr_fp64" in device.extensions.split():
            return True
        return bool(device.double_fp_config)
    except cl.Error:
        return False


def describe_devices() -> str:
    """One line per device: ``P:D  platform | device | type, N CUs, fp64 yes/no``."""
    rows = _indexed()
    if not rows:
        raise DeviceError("no OpenCL platform found (install pyopencl[pocl] for a CPU device)")
    return "\n".join(
        f"{idx}  {p.name.strip()} | {d.name.strip()} | {device_type(d)}, "
        f"{d.max_compute_units} compute units, fp64 {'yes' if has_fp64(d) else 'no'}"
        for idx, p, d in rows
    )


def select_device(spec: str | None = None) -> cl.Device:
    """Pick a device.

    ``None``: the first GPU on any platform, else the first CPU device.
    ``"P:D"``: platform and device indices as ``describe_devices`` prints them.
    ``"cpu"`` / ``"gpu"``: the first device of that type.
    Anything else: the first device whose platform name, platform vendor or
    device name contains it (case-insensitive).
    """
    rows = _indexed()
    if not rows:
        raise DeviceError("no OpenCL platform found (install pyopencl[pocl] for a CPU device)")
    hint = "(run 'python -m pyjulia4d devices' to list them)"
    if spec is None:
        for want in ("GPU", "CPU"):
            for _, _, d in rows:
                if device_type(d) == want:
                    return d
        return rows[0][2]
    s = spec.strip()
    if s.lower() in ("cpu", "gpu"):
        for _, _, d in rows:
            if device_type(d) == s.upper():
                return d
        raise DeviceError(f"--device {spec!r}: no {s.upper()} device found {hint}")
    for idx, _, d in rows:
        if s == idx:
            return d
    if ":" in s and all(part.strip().isdigit() for part in s.split(":")):
        raise DeviceError(f"--device {spec!r}: no device with that index {hint}")
    needle = s.lower()
    for _, p, d in rows:
        if needle and any(needle in n.lower() for n in (p.name, p.vendor, d.name)):
            return d
    raise DeviceError(f"--device {spec!r}: no matching OpenCL device {hint}")
