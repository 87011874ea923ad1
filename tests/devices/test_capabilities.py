"""Capabilities read from the device, never from a compiler's macros (pyjulia4d/opencl/capabilities.py)."""
from __future__ import annotations

import warnings

import pytest

from harness import device
from pyjulia4d.opencl import capabilities as caps
from pyjulia4d.opencl.build import options
from pyjulia4d.opencl.devices import forget_remembered, indexed_devices, is_simulator, select_device
from pyjulia4d.pipeline import kernel_config
from pyjulia4d import Scene


def simulator():
    found = [d for _, _, d in indexed_devices() if is_simulator(d)]
    if not found:
        pytest.skip("Oclgrind is not installed (pip install '.[test]')")
    return found[0]


@pytest.mark.parametrize("text, want", [("OpenCL C 1.2 (Oclgrind 21.10)", 120), ("OpenCL C 3.1 ", 310),
                                        ("OpenCL C 2.0 pocl", 200), ("", 120), ("garbage", 120)])
def test_opencl_c_version_read(text, want):
    assert caps.cl_c_version(text) == want


def test_every_build_carries_the_devices_switches():
    dev = device()
    c = caps.capabilities(dev)
    opts = options(kernel_config.march_config(Scene.default(), 1), dev)
    assert f"-DDEV_CL_C={c.cl_c}" in opts and f"-DDEV_MAX_WORK_GROUP={dev.max_work_group_size}" in opts
    assert f"-DDEV_LOCAL_MEM={dev.local_mem_size}" in opts
    assert ("-DDEV_FP64" in opts) == ("cl_khr_fp64" in dev.extensions.split() or bool(dev.double_fp_config))


def test_the_vote_is_found_by_running_it():
    # Intel's CPU runtime names cl_intel_subgroups and its vote works; Oclgrind's compiler
    # defines the macro but has no sub_group_any (clCreateKernel: INVALID_KERNEL_NAME)
    sim = simulator()
    assert not caps._vote_works(sim, "cl_intel_subgroups")
    intel = [d for _, p, d in indexed_devices() if p.name.strip() == "Intel(R) OpenCL"]
    if intel:
        assert caps._vote_works(intel[0], "cl_intel_subgroups")
        assert "DEV_SUBGROUPS" in caps.capabilities(intel[0]).defines()


def test_a_named_extension_that_does_not_link_falls_back_and_says_so_once(monkeypatch, tmp_path):
    sim = simulator()
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    real = caps._info
    monkeypatch.setattr(caps, "_info", lambda d, name, default: (real(d, name, default) + " cl_intel_subgroups"
                                                                  if name == "extensions" else real(d, name, default)))
    monkeypatch.setattr(caps, "_known", {})
    forget_remembered()
    try:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            got = caps.capabilities(sim)
            caps._known.clear()
            forget_remembered()
            again = caps.capabilities(sim)   # a later process: the answer is remembered, not said again
    finally:
        forget_remembered()
    assert got == again and got.named == ("cl_intel_subgroups",) and got.subgroups == ""
    assert "DEV_SUBGROUPS" not in got.defines()
    said = [str(w.message) for w in seen if "sub-group" in str(w.message)]
    assert len(said) == 1 and "Oclgrind" in said[0] and "built without sub-groups" in said[0]
    assert "does not link" in got.describe()


def test_a_simulator_is_never_the_default():
    sim = simulator()
    assert select_device(None).int_ptr != sim.int_ptr
    assert select_device("oclgrind").int_ptr == sim.int_ptr
    try:
        assert select_device("gpu").int_ptr != sim.int_ptr
    except ValueError as e:
        assert "simulator" in str(e)
