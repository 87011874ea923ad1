"""OpenCL from PyPI with no system driver (opencl/runtimes.py): Intel's CPU runtime registered
beside the system's drivers, a user's own choice left alone, caches and terminals that cannot
be used costing only time; and which CPU runtime is chosen, and why (opencl/devices.py)."""
from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path

import pytest

from pyjulia4d.opencl import runtimes

from processes import cli_process as _cli, python_process as _python, subprocess_env as _env


# ------------------------------------------------------------------ OpenCL from PyPI

INTEL = runtimes.intel_library()
needs_intel = pytest.mark.skipif(INTEL is None, reason="intel-opencl-rt is not installed (not x86-64 Linux)")


def test_intel_runtime_is_a_dependency_on_x86_64_linux() -> None:
    if platform.system() == "Linux" and platform.machine() == "x86_64":
        assert INTEL is not None and INTEL.name == "libintelocl.so"


@needs_intel
def test_registration_adds_intel_beside_the_system_drivers(tmp_path: Path) -> None:
    """The vendors folder holds the wheel's runtime by its real path and a copy of every
    system .icd file (OCL_ICD_VENDORS replaces the system folder, so none may be lost)."""
    system = tmp_path / "system"
    system.mkdir()
    (system / "gpu.icd").write_text("/opt/some/libgpu.so\n")
    cache = tmp_path / "cache"
    p = _python("import os, pyjulia4d; print(os.environ['OCL_ICD_VENDORS'])",
                OPENCL_VENDOR_PATH=str(system), PYJULIA4D_CACHE=str(cache))
    assert p.returncode == 0, p.stderr
    folder = Path(p.stdout.strip())
    assert folder.parent == cache / "icd"
    icds = {f.name: f.read_text().strip() for f in folder.iterdir()}
    assert icds == {"gpu.icd": "/opt/some/libgpu.so", "pyjulia4d-intel-cpu.icd": str(INTEL)}
    assert not [f for f in (cache / "icd").iterdir() if f.name.startswith(".")]   # no temp folder left


@pytest.mark.parametrize("env,why", [({"OCL_ICD_VENDORS": "/nonexistent"}, "OCL_ICD_VENDORS is set"),
                                     ({"PYJULIA4D_NO_BUNDLED_OPENCL": "1"}, "PYJULIA4D_NO_BUNDLED_OPENCL is set")])
def test_registration_leaves_a_users_choice_alone(tmp_path: Path, env, why) -> None:
    p = _python("import os, pyjulia4d; from pyjulia4d import runtimes; "
                "print(os.environ.get('OCL_ICD_VENDORS')); print(runtimes.registered['why_not'])",
                PYJULIA4D_CACHE=str(tmp_path), **env)
    assert p.returncode == 0, p.stderr
    assert p.stdout.splitlines() == [env.get("OCL_ICD_VENDORS", "None"), why]
    assert not (tmp_path / "icd").exists()


def test_a_cache_folder_that_cannot_be_made_costs_only_time(tmp_path: Path) -> None:
    """XDG_CACHE_HOME under a file: pyopencl's cache of argument setters cannot be made there
    (it stopped the first render with a traceback); pyopencl's caches are turned off and the
    render goes on, whatever PYOPENCL_NO_CACHE said; where the folder can be made, a user's
    own PYOPENCL_NO_CACHE stands."""
    code = ("import os, pyjulia4d; from pyjulia4d import Scene, render; "
            "r = render(Scene.default().with_overrides(['image.width=16', 'image.height=12'])); "
            "print(os.environ.get('PYOPENCL_NO_CACHE'), r.hit_fraction > 0.1)")
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    p = _python(code, XDG_CACHE_HOME=str(blocker / "cache"), PYJULIA4D_CACHE=str(tmp_path / "c"))
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
    assert p.stdout.split() == ["1", "True"]
    p = _python(code, XDG_CACHE_HOME=str(tmp_path / "xdg"), PYJULIA4D_CACHE=str(tmp_path / "c"))
    assert p.returncode == 0 and p.stdout.split() == ["None", "True"], p.stderr
    p = _python(code, XDG_CACHE_HOME=str(blocker / "cache"), PYOPENCL_NO_CACHE="0",
                PYJULIA4D_CACHE=str(tmp_path / "c"))
    assert p.returncode == 0 and p.stdout.split() == ["1", "True"], p.stderr
    p = _python(code, XDG_CACHE_HOME=str(tmp_path / "xdg"), PYOPENCL_NO_CACHE="1",
                PYJULIA4D_CACHE=str(tmp_path / "c"))
    assert p.returncode == 0 and p.stdout.split() == ["1", "True"], p.stderr


def test_a_terminal_that_cannot_show_a_name_gets_it_escaped(tmp_path: Path) -> None:
    """PYTHONIOENCODING=ascii and an output named é.png: the render was written, then its
    closing line failed (UnicodeEncodeError, a ValueError) and the command said "error"."""
    p = subprocess.run([sys.executable, "-m", "pyjulia4d", "render", "--width", "8", "--height", "6",
                        "-o", "\u00e9.png"], cwd=tmp_path, env=_env(PYTHONIOENCODING="ascii"),
                       capture_output=True, text=True, encoding="ascii", timeout=300)
    assert p.returncode == 0 and p.stderr == "", p.stderr
    assert p.stdout.startswith("rendered \\xe9.png (8x6)")
    assert [f.name for f in tmp_path.iterdir()] == ["\u00e9.png"]


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full here")
def test_standard_output_that_fails_is_one_line_and_no_traceback(tmp_path: Path) -> None:
    """Standard output full (/dev/full): one line and status 1, where a traceback came; its
    reader gone (`| head`): no word, and 141 as the shell's own tools (SIGPIPE).  Each had
    left a traceback, and the render's file was written before its closing line failed."""
    cmd = [sys.executable, "-m", "pyjulia4d", "render", "--width", "8", "--height", "6", "-o", "x.png"]
    with open("/dev/full", "w") as full:
        p = subprocess.run(cmd, cwd=tmp_path, env=_env(), stdout=full, stderr=subprocess.PIPE, text=True,
                           timeout=300)
    assert p.returncode == 1 and p.stderr == ("pyjulia4d: error: cannot write to standard output: No space "
                                              "left on device\n"), p.stderr
    q = subprocess.Popen(cmd[:3] + ["keys"], cwd=tmp_path, env=_env(), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    q.stdout.close()   # the reader goes away before the command writes
    err = q.stderr.read()
    assert q.wait(timeout=300) == 141 and err == "", err


@needs_intel
def test_a_device_compiles_with_no_system_driver(tmp_path: Path) -> None:
    """No system .icd file at all (an empty vendors folder): the default device comes from
    PyPI alone and renders a picture with hits."""
    empty = tmp_path / "vendors"
    empty.mkdir()
    p = _python("from pyjulia4d import Scene, render; from pyjulia4d.opencl.devices import select_device; "
                "d = select_device(None); r = render(Scene.default().with_overrides(['image.width=24', "
                "'image.height=18']), device=d); print(d.platform.name.strip(), r.hit_fraction > 0.1)",
                OPENCL_VENDOR_PATH=str(empty), PYJULIA4D_CACHE=str(tmp_path / "cache"))
    assert p.returncode == 0, p.stderr
    assert p.stdout.split()[-1] == "True"


def test_an_unwritable_cache_costs_the_runtime_only(tmp_path: Path) -> None:
    """A cache folder that cannot be written: no exception at import, a reason recorded, and
    said in the closing line where another CPU runtime takes over (it was said by `devices`
    alone, while a render went on on PoCL), or in the one-line error where none that is left
    compiles (PyPI's PoCL on a CPU its LLVM does not know)."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    p = _python("import pyjulia4d; from pyjulia4d import runtimes; print(repr(runtimes.registered['why_not']))",
                PYJULIA4D_CACHE=str(blocker / "cache"))
    assert p.returncode == 0, p.stderr
    if INTEL is not None:
        assert "cannot write the vendors folder" in p.stdout
        q = _cli(["render", "--width", "8", "--height", "6", "-o", "x.png"], tmp_path,
                 PYJULIA4D_CACHE=str(blocker / "cache"))
        if q.returncode == 0 and "no GPU" in q.stdout:   # a CPU took it: another runtime than Intel's
            assert "Intel's CPU runtime from PyPI is not registered: cannot write the vendors folder" in q.stdout
        elif q.returncode == 2 and "cannot compile OpenCL C" in q.stderr:   # none that is left compiles here
            # the cause named, not "pick another --device" where there is no other
            assert q.stderr.count("\n") == 1 and "Intel's CPU runtime from PyPI is not registered: cannot write " \
                "the vendors folder" in q.stderr and "point PYJULIA4D_CACHE at a folder that can be written" in q.stderr


# ------------------------------------------------------------------ which CPU runtime

class _Platform:
    def __init__(self, name: str) -> None:
        self.name = name


class _Device:
    def __init__(self, platform_name: str, n: int) -> None:
        self.platform = _Platform(platform_name)
        self.int_ptr = n
        self.name = "cpu"


def test_cpu_runtime_preference(monkeypatch) -> None:
    """Of the CPUs that compile, Intel's runtime is preferred whatever the platform order;
    a GPU still comes first; a CPU that cannot compile is never picked."""
    from pyjulia4d.opencl import devices

    pocl, intel, broken = _Device("Portable Computing Language", 1), _Device("Intel(R) OpenCL", 2), \
        _Device("Intel(R) OpenCL", 3)
    rows = [("0:0", None, pocl), ("1:0", None, broken), ("2:0", None, intel)]
    monkeypatch.setattr(devices, "indexed_devices", lambda: rows)
    monkeypatch.setattr(devices, "device_type", lambda d: "GPU" if d.platform.name == "GPU" else "CPU")
    monkeypatch.setattr(devices, "compile_error", lambda d: "boom" if d is broken else "")
    assert devices.select_device(None) is intel
    why = devices.default_reason(intel)
    assert why.startswith("2:0, the default: no GPU; of the CPU runtimes that compile, Intel(R) OpenCL is "
                          "preferred") and "over 0:0" in why and "1:0 cannot compile" in why
    gpu = _Device("GPU", 4)
    rows.append(("3:0", None, gpu))
    assert devices.select_device(None) is gpu
    assert devices.select_device("0:0") is pocl   # an explicit choice stands


def test_device_keys_are_made_once_per_device() -> None:
    """devices.device_key: the same text from a new wrapper of the same device, made once (a
    driver answered one of its parts in 90 us, asked for every device at each render)."""
    import pyopencl as cl
    from pyjulia4d.opencl import devices

    for _, p, d in devices.indexed_devices():
        key = devices.device_key(d)
        assert devices._keys[d.int_ptr] == key
        again = next(x for x in p.get_devices() if x.int_ptr == d.int_ptr)   # a new wrapper
        assert devices.device_key(again) == key
        assert key == " | ".join(x.strip() for x in (p.name, p.version, d.name, d.version, d.driver_version))
    assert not any(isinstance(x, cl.Device) for x in devices._keys)


def test_devices_says_the_default_and_the_registration() -> None:
    from pyjulia4d.opencl.listing import describe_devices

    lines = describe_devices().splitlines()
    assert sum(line.endswith("(default)") for line in lines) == 1
    assert any(", the default: " in line for line in lines)
    assert lines[-1].startswith("Intel's CPU runtime from PyPI: ")
