"""Every device failure is one line naming the device, the step and the OpenCL error
(pyjulia4d/opencl/failures.py); where the user did not pick the device, the next one that
works takes over and the closing line says so.

The failures are real where a real one can be had: a build the compiler refuses (a
double-precision program built as if the device had no fp64: lanes.cl's #error), a kernel
the driver cannot make (Oclgrind told it has sub-groups, the very failure of
``sub_group_any`` that a compiler's macro once caused) and an enqueue the driver refuses
(a work-group larger than the device's).  A device lost mid-render cannot be had on demand:
the wait for a tile raises the error a lost device gives (OUT_OF_RESOURCES), as pyopencl
would."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pyopencl as cl
import pyopencl._cl as _cl
import pytest

from harness import device
from pyjulia4d import Scene
from pyjulia4d.opencl import build, capabilities as caps, devices, passes, runner
from pyjulia4d.opencl.executor import render
from pyjulia4d.opencl.failures import DeviceFailure

ROOT = Path(__file__).resolve().parents[2]
SMALL = Scene.default().with_overrides(["image.width=12", "image.height=9"])


def simulator():
    found = [d for _, _, d in devices.indexed_devices() if devices.is_simulator(d)]
    if not found:
        pytest.skip("Oclgrind is not installed (pip install '.[test]')")
    return found[0]


@pytest.fixture
def fresh_builds(monkeypatch):
    """No program or kernel kept from an earlier render, so the failure happens here."""
    monkeypatch.setattr(build, "_programs", {})
    monkeypatch.setattr(build, "_kernels", __import__("threading").local())


def one_line(e: BaseException) -> str:
    text = str(e)
    assert "\n" not in text and "Traceback" not in text
    return text


def no_fp64_on(dev):
    """build.options for ``dev`` without DEV_FP64: a double-precision build then hits lanes.cl's #error."""
    real = build.options

    def options(config, d):
        got = real(config, d)
        return [o for o in got if o != "-DDEV_FP64"] if d.int_ptr == dev.int_ptr else got
    return options


def test_a_failed_build(monkeypatch, fresh_builds):
    dev = device()
    monkeypatch.setattr(build, "options", no_fp64_on(dev))
    with pytest.raises(DeviceFailure) as e:
        render(SMALL.with_overrides(["render.float=double"]), device=dev, calibrate=False)
    text = one_line(e.value)
    assert text.startswith(f"device '{dev.name.strip()}' ({dev.platform.name.strip()}): the build of ")
    assert "BUILD_PROGRAM_FAILURE" in text and "cl_khr_fp64" in text


def test_a_kernel_that_cannot_be_made(monkeypatch, fresh_builds):
    sim = simulator()
    told = caps.Capabilities(fp64=True, subgroups="cl_intel_subgroups", named=("cl_intel_subgroups",), cl_c=120,
                             max_work_group=1024, local_mem=32768)
    monkeypatch.setitem(caps._known, sim.int_ptr, told)
    with pytest.raises(DeviceFailure) as e:
        render(SMALL, device=sim, calibrate=False)
    text = one_line(e.value)
    assert text.startswith("device 'Oclgrind Simulator' (Oclgrind): making kernel '") and "INVALID_KERNEL_NAME" in text


def test_an_enqueue_the_driver_refuses(monkeypatch, fresh_builds):
    sim = simulator()
    monkeypatch.setattr(runner, "local_size", lambda k, d: 4096)   # Oclgrind's largest work-group is 1024
    with pytest.raises(DeviceFailure) as e:
        render(SMALL, device=sim, calibrate=False)
    text = one_line(e.value)
    assert "running kernel 'cone_starts' failed: INVALID_WORK_" in text   # ITEM_SIZE or GROUP_SIZE, as the driver says


def test_a_device_lost_mid_render(monkeypatch):
    dev = device()
    real, calls = cl.wait_for_events, []

    def lost(events):
        calls.append(1)
        if len(calls) > 1:   # the first tile came back; then the device is gone
            raise cl.RuntimeError(_cl._ErrorRecord("clWaitForEvents failed: OUT_OF_RESOURCES",
                                                   cl.status_code.OUT_OF_RESOURCES, "clWaitForEvents"))
        return real(events)
    monkeypatch.setattr(passes.cl, "wait_for_events", lost)
    with pytest.raises(DeviceFailure) as e:
        render(SMALL.with_overrides(["image.width=64", "image.height=64"]), device=dev, tile=16, calibrate=False)
    text = one_line(e.value)
    assert f"device '{dev.name.strip()}'" in text and "the render after kernel '" in text and "OUT_OF_RESOURCES" in text


def test_the_next_device_takes_over_where_none_was_picked(monkeypatch, fresh_builds):
    simulator()
    # a machine here may have one real device only: the simulator stands in for a second,
    # taken as a default for this test (so the default is now the simulator, a "GPU")
    monkeypatch.setattr(devices, "is_simulator", lambda d: False)
    dflt = devices.select_device(None)
    monkeypatch.setattr(build, "options", no_fp64_on(dflt))
    got = render(SMALL.with_overrides(["render.float=double"]), calibrate=False)
    assert got.device_name != dflt.name.strip()
    assert got.fell_back.startswith(f"device '{dflt.name.strip()}'") and "BUILD_PROGRAM_FAILURE" in got.fell_back
    assert got.hit_fraction > 0.3
    assert got.report()[0]["pyjulia4d.device_failed"] == got.fell_back


def test_a_picked_device_that_fails_is_not_replaced(monkeypatch, fresh_builds):
    dflt = devices.select_device(None)
    monkeypatch.setattr(build, "options", no_fp64_on(dflt))
    with pytest.raises(DeviceFailure):
        render(SMALL.with_overrides(["render.float=double"]), device=dflt, calibrate=False)


CLI = r"""
import sys
from pyjulia4d.opencl import capabilities as caps
from pyjulia4d.opencl.devices import select_device
sim = select_device("oclgrind")
caps._known[sim.int_ptr] = caps.Capabilities(True, "cl_intel_subgroups", ("cl_intel_subgroups",), 120, 1024, 32768)
from pyjulia4d.app.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_the_command_line_says_it_in_one_line_and_leaves_nothing(tmp_path):
    simulator()
    out = tmp_path / "out" / "x.png"
    out.parent.mkdir()
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYJULIA4D_CACHE=str(tmp_path / "cache"))
    p = subprocess.run([sys.executable, "-c", CLI, "render", "--width", "12", "--height", "9", "--device", "oclgrind",
                        "-o", str(out)], capture_output=True, text=True, env=env, timeout=300, cwd=tmp_path)
    assert p.returncode == 2, p.stderr[-2000:]
    # Oclgrind writes its own diagnosis to the same stderr ("Undefined external function:
    # sub_group_any"), the driver's words; pyjulia4d's are one line, with no traceback
    assert "Traceback" not in p.stderr
    lines = [ln for ln in p.stderr.splitlines() if ln.startswith("pyjulia4d")]
    assert len(lines) == 1 and lines[0].startswith("pyjulia4d: error: device 'Oclgrind Simulator' (Oclgrind): making "
                                                  "kernel '") and "INVALID_KERNEL_NAME" in lines[0], p.stderr
    assert list(out.parent.iterdir()) == []


def test_no_usable_opencl_at_all(tmp_path):
    # the loader pointed at an ICD file that is not there: no platform at all
    out = tmp_path / "x.png"
    env = dict(os.environ, PYTHONPATH=str(ROOT), OCL_ICD_VENDORS=str(tmp_path / "none.icd"),
               PYJULIA4D_CACHE=str(tmp_path / "cache"))
    p = subprocess.run([sys.executable, "-m", "pyjulia4d", "render", "--width", "8", "--height", "6", "-o", str(out)],
                       capture_output=True, text=True, env=env, timeout=120, cwd=tmp_path)
    assert p.returncode == 2 and p.stderr.strip().splitlines() == [
        "pyjulia4d: error: no OpenCL platform found (install pyopencl[pocl] for a CPU device)"], p.stderr
    assert [x.name for x in tmp_path.iterdir() if x.name != "cache"] == []
