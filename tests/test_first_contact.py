"""What a new user meets first: OpenCL from PyPI with no system driver (runtimes.py), the
CPU runtime chosen and why (devices.py), the command line people expect (--version, keys,
re-rendering an image), scenes checked when built in Python, the optional extras, and the
bugs of first contact (the cluster's header camera, camera.fit beyond the coordinate
range, double precision refused before any build)."""
from __future__ import annotations

import dataclasses
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import pyjulia4d
from pyjulia4d import Scene, SceneError
from pyjulia4d.app import cli
from pyjulia4d.scene import keys
from pyjulia4d.opencl import runtimes
from pyjulia4d.scene.model import key_names, valid_range

PKG_ROOT = str(Path(pyjulia4d.__file__).resolve().parent.parent)


def _env(**extra: str) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [PKG_ROOT, env.get("PYTHONPATH")]))
    env.pop("OCL_ICD_VENDORS", None)   # set by this process's own registration
    env.update(extra)
    return env


def _python(code: str, **extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code], env=_env(**extra), capture_output=True, text=True,
                          timeout=300)


def _cli(args: list[str], cwd: Path, prelude: str = "", **extra: str) -> subprocess.CompletedProcess[str]:
    code = prelude + "import sys; from pyjulia4d.app.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run([sys.executable, "-c", code, *args], cwd=cwd, env=_env(**extra),
                          capture_output=True, text=True, timeout=300)


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
    alone, while a render went on on PoCL)."""
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
    from pyjulia4d.opencl.devices import describe_devices

    lines = describe_devices().splitlines()
    assert sum(line.endswith("(default)") for line in lines) == 1
    assert any(", the default: " in line for line in lines)
    assert lines[-1].startswith("Intel's CPU runtime from PyPI: ")


# ------------------------------------------------------------------ the command line

def test_version(capsys) -> None:
    with pytest.raises(SystemExit) as e:
        cli.main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"pyjulia4d {pyjulia4d.__version__}"


def test_help_names_the_command(capsys) -> None:
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    assert capsys.readouterr().out.startswith("usage: pyjulia4d ")


def test_keys_lists_every_key_with_default_range_and_meaning(capsys) -> None:
    assert cli.main(["keys"]) == 0
    out = capsys.readouterr().out
    for key in key_names():
        i = out.index(f"\n{key} = " if out.index(key) else f"{key} = ")
        block = out[i:].strip().splitlines()[:3]
        assert block[0] == f"{key} = {keys.default_text(key)}"
        assert block[1] == f"    range: {valid_range(key)}"
        assert block[2].startswith("    ") and len(block[2].strip()) > 3
    assert set(keys.MEANINGS) == set(key_names())


def test_keys_defaults_are_the_scenes() -> None:
    """Every default printed reads back as the default scene's value (camera.fit aside; the
    march keys that march.quality "auto" sets are custom's defaults, which it takes for the
    default scene's quaternion square)."""
    d = Scene.default()
    for key in key_names():
        if key == "camera.fit":
            continue
        section, _, name = key.partition(".")
        text = keys.default_text(key)
        back = Scene.from_dict({"camera": {"position": list(Scene.default().camera.position)}},
                               [f"{key}={text.strip('[]').strip(chr(34))}"] if text != "[]" else [])
        assert getattr(getattr(back, section), name) == getattr(getattr(d, section), name), key


def test_keys_section_and_bad_section(capsys) -> None:
    assert cli.main(["keys", "image"]) == 0
    out = capsys.readouterr().out
    assert [ln.split(" = ")[0] for ln in out.splitlines() if not ln.startswith(" ")] == \
        ["image.width", "image.height", "image.samples", "image.adaptive", "image.bits",
         "image.exr"]
    assert cli.main(["keys", "octonion"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pyjulia4d: error: octonion: unknown section") and err.count("\n") == 1


@pytest.mark.parametrize("fmt", [".png", ".exr"])
def test_render_an_image_again(tmp_path: Path, fmt: str) -> None:
    """render IMAGE reads the scene from its header - the camera camera.fit chose included -
    and gives the same picture."""
    first = tmp_path / f"first{fmt}"
    assert cli.main(["render", "--width", "40", "--height", "30", "-o", str(first)]) == 0
    again = tmp_path / "again.png"
    assert cli.main(["render", str(first), "-o", str(again)]) == 0
    if fmt == ".png":
        assert np.array_equal(np.asarray(Image.open(first)), np.asarray(Image.open(again)))
    from pyjulia4d.app.output import read_header

    assert read_header(first)["pyjulia4d.scene"] == read_header(again)["pyjulia4d.scene"]
    assert "fit = false" in read_header(again)["pyjulia4d.scene"]


def test_render_an_image_default_output_and_overrides(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert cli.main(["render", "--width", "20", "--height", "16", "-o", "a.png"]) == 0
    assert cli.main(["render", "a.png", "--width", "10"]) == 0
    with Image.open(tmp_path / "a-rerender.png") as im:
        assert im.size == (10, 16)


@pytest.mark.parametrize("make,why", [
    (lambda p: None, "cannot read: no such file"),
    (lambda p: p.write_bytes(b"not a png"), "not a readable PNG file"),
    (lambda p: p.mkdir(), "is a directory, not an image"),
    (lambda p: Image.new("RGB", (4, 4)).save(p), "holds no pyjulia4d scene"),
    (lambda p: os.mkfifo(p), "not a regular file"),   # was "no such file"
])
def test_render_an_image_bad(tmp_path: Path, capsys, make, why) -> None:
    src = tmp_path / "src.png"
    make(src)
    before = set(tmp_path.iterdir())
    assert cli.main(["render", str(src), "-o", str(tmp_path / "out.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pyjulia4d: error: {src}: {why}") and err.count("\n") == 1
    assert set(tmp_path.iterdir()) == before


@pytest.mark.parametrize("description", ["{", "[" * 100000 + "]" * 100000, '"a string"', "made by a scanner"])
def test_a_tiff_described_by_another_program_holds_no_scene(tmp_path: Path, capsys, description) -> None:
    """A readable TIFF whose description is not pyjulia4d's JSON object: it holds no scene (it was
    called damaged, "not a readable TIF file")."""
    import tifffile

    src = tmp_path / "src.tif"
    tifffile.imwrite(src, np.zeros((4, 4, 4), np.uint8), description=description)
    assert cli.main(["render", str(src), "-o", str(tmp_path / "out.png")]) == 2
    assert capsys.readouterr().err == f"pyjulia4d: error: {src}: holds no pyjulia4d scene (not rendered by " \
                                      f"pyjulia4d, or its metadata was stripped)\n"


def test_render_an_image_with_a_bad_embedded_scene(tmp_path: Path, capsys) -> None:
    from PIL import PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("pyjulia4d.scene", "[fractal]\nmax_iter = -3\n")
    src = tmp_path / "src.png"
    Image.new("RGBA", (4, 4)).save(src, pnginfo=info)
    assert cli.main(["render", str(src), "-o", str(tmp_path / "out.png")]) == 2
    assert capsys.readouterr().err == "pyjulia4d: error: fractal.max_iter: must be in [1, 1000000], got -3\n"
    assert not (tmp_path / "out.png").exists()


# ------------------------------------------------------------------ Python scenes

D = Scene.default()


@pytest.mark.parametrize("build,message", [
    (lambda: dataclasses.replace(D.fractal, max_iter=-5), "fractal.max_iter: must be in [1, 1000000], got -5"),
    (lambda: dataclasses.replace(D.fractal, c=(float("nan"), 0, 0, 0)), "fractal.c: element 0: not a finite number"),
    (lambda: dataclasses.replace(D.image, width=0), "image.width: must be in [1, 2147483647], got 0"),
    (lambda: dataclasses.replace(D.fractal, algebra="octonion"), "fractal.algebra: expected one of"),
    (lambda: dataclasses.replace(D.march, epsilon="small"), "march.epsilon: expected a number"),
    (lambda: dataclasses.replace(D, fractal="x"), "fractal: expected a pyjulia4d.scene.Fractal"),
    (lambda: dataclasses.replace(D, camera=dataclasses.replace(D.camera, target=D.camera.position)),
     "camera.target: equals camera.position"),
    (lambda: dataclasses.replace(D, fractal=dataclasses.replace(D.fractal, algebra="cquat", function="sin")),
     "fractal.function: 'sin' is not defined for the cquat algebra"),
    (lambda: dataclasses.replace(D, march=dataclasses.replace(D.march, near=2.0, far=1.0)),
     "march.far: must be greater than march.near"),
    (lambda: pyjulia4d.scene.Light(), "shading.lights[]: give exactly one of position and direction"),
])
def test_python_scenes_are_checked_when_built(build, message) -> None:
    with pytest.raises(SceneError) as e:
        build()
    assert str(e.value).startswith(message)


def test_python_values_are_normalised() -> None:
    f = dataclasses.replace(D.fractal, c=[0, 1, 0, 0], bailout=3)
    assert f.c == (0.0, 1.0, 0.0, 0.0) and isinstance(f.bailout, float)
    cam = dataclasses.replace(D.camera, position=[1, 2, 3])
    assert cam.position == (1.0, 2.0, 3.0, 0.0)
    assert hash(Scene(fractal=f, camera=cam))   # frozen and hashable, as from a file


def test_render_refuses_a_non_scene() -> None:
    from pyjulia4d import render

    with pytest.raises(SceneError, match=r"^scene: expected a pyjulia4d.Scene, got dict$"):
        render({"fractal": {}})


def test_default_scene_and_command_line_scene_differ_in_camera_only() -> None:
    a, b = Scene.default().to_dict(), Scene.from_dict({}).to_dict()
    assert b["camera"]["fit"] is True and a["camera"]["fit"] is False
    a["camera"]["fit"] = True
    assert a == b


# ------------------------------------------------------------------ extras

@pytest.mark.parametrize("args,message", [
    (["--workers", "2"], "pyjulia4d: error: --workers: needs Dask distributed, which is not installed: "
                         "pip install 'pyjulia4d[cluster]'"),
    (["--scheduler", "tcp://127.0.0.1:1"], "pyjulia4d: error: --scheduler: needs Dask distributed"),
    (["--video", "out.mp4", "--workers", "0"], "pyjulia4d: error: out.mp4: video needs imageio-ffmpeg, which is "
                                                "not installed: pip install 'pyjulia4d[video]'"),
])
def test_missing_extras_get_one_line(tmp_path: Path, args, message) -> None:
    scene = tmp_path / "a.toml"
    scene.write_text("[image]\nwidth = 8\nheight = 6\n[animation]\nframes = 2\n"
                     "[[keyframe]]\nframe = 0\nfractal.max_iter = 8\n[[keyframe]]\nframe = 1\nfractal.max_iter = 9\n")
    p = _cli(["animate", str(scene), "-o", str(tmp_path / "f_##.png"), *args], tmp_path,
             prelude="import sys; sys.modules['distributed'] = None; sys.modules['imageio_ffmpeg'] = None; ")
    assert p.returncode == 2, p.stderr
    assert p.stderr.startswith(message) and p.stderr.count("\n") == 1
    assert sorted(f.name for f in tmp_path.iterdir()) == ["a.toml"]


def test_animate_without_the_cluster_extra_renders_in_process(tmp_path: Path) -> None:
    scene = tmp_path / "a.toml"
    scene.write_text("[image]\nwidth = 8\nheight = 6\n[animation]\nframes = 2\n"
                     "[[keyframe]]\nframe = 0\nfractal.max_iter = 8\n[[keyframe]]\nframe = 1\nfractal.max_iter = 9\n")
    p = _cli(["animate", str(scene), "-o", str(tmp_path / "f_##.png")], tmp_path,
             prelude="import sys; sys.modules['distributed'] = None; ")
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "f_00.png").is_file() and (tmp_path / "f_01.png").is_file()


# ------------------------------------------------------------------ bugs of first contact

def test_camera_fit_beyond_the_coordinate_range_names_the_bailout() -> None:
    """bailout 1e6 on a pair without a polynomial escape bound: the bound is the bailout
    ball, which no camera within +-1e6 frames; refused before any pass, naming the key that
    made it so (not camera.position, which the user never set)."""
    from pyjulia4d import render

    scene = Scene.from_dict({"fractal": {"algebra": "cquat", "bailout": 1e6}, "image": {"width": 16, "height": 12}})
    with pytest.raises(SceneError, match=r"^fractal\.bailout: camera\.fit: the first pass would need a camera"):
        render(scene)


def test_double_refused_before_any_build(monkeypatch) -> None:
    """A device without cl_khr_fp64: the one-line message comes before camera.fit's pass, the
    probe or any program build."""
    from pyjulia4d.opencl import build
    render_module = sys.modules["pyjulia4d.opencl.executor"]   # the package's name "render" is the function

    def no_build(*a, **k):
        raise AssertionError("a program was built")

    monkeypatch.setattr(render_module, "has_fp64", lambda dev: False)
    monkeypatch.setattr(build, "program", no_build)
    scene = Scene.from_dict({"render": {"float": "double"}, "image": {"width": 16, "height": 12}})
    assert scene.camera.fit
    with pytest.raises(SceneError, match=r"^render\.float: device '.*' has no cl_khr_fp64"):
        render_module.render(scene)


def test_cluster_tiles_record_the_fitted_camera() -> None:
    """render --workers: the result's scene (the header's) is the camera the tiles used."""
    from harness import device
    from pyjulia4d import render
    from pyjulia4d.app.cluster import render_tiled

    scene = Scene.from_dict({"image": {"width": 48, "height": 36}})
    result, used = render_tiled(None, scene, tile=16)   # the tiles' device: PYJULIA4D_DEVICE's, else the default
    assert result.scene == used and not used.camera.fit
    whole = render(scene, device=device())              # the same device: its fit is the same to the bit
    assert whole.scene == used
    assert np.array_equal(whole.color, result.color)


# ------------------------------------------------------------------ render()'s own arguments

@pytest.mark.parametrize("kw,message", [
    (dict(outputs=3), "outputs: expected a list of output names"),
    (dict(outputs=[1, 2]), "outputs: expected output names"),
    (dict(outputs=["bogus"]), "outputs: unknown output 'bogus'"),
    (dict(region=(0.5, 0, 4, 4)), "region: expected (x0, y0, width, height), whole numbers"),
    (dict(region="abcd"), "region: expected (x0, y0, width, height)"),
    (dict(region=(0, 0, 100, 100)), "region: (0, 0, 100, 100) is not inside the 16x12 image"),
    (dict(device=123), "device: expected None, a pyopencl Device or a --device text"),
    (dict(lanes=7), "lanes: expected one of 1, 4, 8, 16 rays per work-item, got 7"),
    (dict(lanes=0), "lanes: expected one of 1, 4, 8, 16"),
    (dict(lanes="x"), "lanes: expected one of 1, 4, 8, 16"),
    (dict(lanes=True), "lanes: expected one of 1, 4, 8, 16"),
    (dict(tile=0), "tile: expected a tile side in [1, 8192] pixels, got 0"),
    (dict(tile=10 ** 9), "tile: expected a tile side in [1, 8192]"),
    (dict(tile="a"), "tile: expected a tile side"),
    (dict(progress="yes"), "progress: expected True or False, got 'yes'"),
    (dict(force="no"), "force: expected True or False"),
    (dict(calibrate=None), "calibrate: expected True or False"),
])
def test_render_arguments_are_checked(kw, message) -> None:
    """Bad Python arguments get the one-line SceneError naming the argument, before any
    kernel is built - never a TypeError, a ZeroDivisionError or a driver's build failure."""
    from pyjulia4d import render

    with pytest.raises(SceneError) as e:
        render(Scene.default().with_overrides(["image.width=16", "image.height=12"]), **kw)
    assert str(e.value).startswith(message)


class Hostile:
    """An object whose every protocol method fails: a bad argument must still be named in
    one line, never let the object's own exception through."""
    def __iter__(self):
        raise RuntimeError("boom")

    def __eq__(self, other):
        raise RuntimeError("boom")

    def __hash__(self):
        return 1

    def __repr__(self):
        raise RuntimeError("boom")

    def __len__(self):
        return 4


@pytest.mark.parametrize("kw,message", [
    (dict(region=Hostile()), "region: expected (x0, y0, width, height), whole numbers, got <a Hostile>"),
    (dict(outputs=Hostile()), "outputs: expected a list of output names"),
    (dict(outputs=[Hostile(), Hostile()]), "outputs: expected a list of output names"),
    (dict(tile=Hostile()), "tile: expected a tile side in [1, 8192] pixels, got <a Hostile>"),
    (dict(lanes=Hostile()), "lanes: expected one of 1, 4, 8, 16 rays per work-item, got <a Hostile>"),
    (dict(force=Hostile()), "force: expected True or False, got <a Hostile>"),
])
def test_hostile_objects_are_named_in_one_line(kw, message) -> None:
    from pyjulia4d import render

    with pytest.raises(SceneError) as e:
        render(Scene.default().with_overrides(["image.width=16", "image.height=12"]), **kw)
    assert str(e.value).startswith(message) and "\n" not in str(e.value)


def test_hostile_objects_in_the_scene_and_output_interfaces(tmp_path) -> None:
    from pyjulia4d.app.mesh import build_mesh
    from pyjulia4d.app.output import OutputError, write_image

    with pytest.raises(SceneError, match=r"^overrides: expected a list of SECTION.KEY=VALUE texts, got <a Hostile>$"):
        Scene.default().with_overrides(Hostile())
    with pytest.raises(SceneError, match=r"^--resolution: expected a whole number .* got <a Hostile>$"):
        build_mesh(Scene.default(), resolution=Hostile())
    with pytest.raises(OutputError, match=r"^output path: expected a str or an os.PathLike, got Hostile$"):
        write_image(Hostile(), None)


@pytest.mark.parametrize("path", [0, 5, None, b"scene.toml", 2.5])
def test_a_scene_path_must_be_a_path(path) -> None:
    """An int would be opened as a file descriptor - and closed after the read: refused
    before anything is opened; so are bytes, None and other types."""
    import os

    r, w = os.pipe()
    try:
        with pytest.raises(SceneError, match=r"^scene: expected the path of a scene file"):
            Scene.from_toml(path if path != 5 else r)
        os.fstat(r)   # still open
    finally:
        os.close(r)
        os.close(w)


@pytest.mark.parametrize("path", [5, None, b"/tmp/x.png", ["a.png"]])
def test_an_output_path_must_be_a_path(path, tmp_path) -> None:
    from pyjulia4d.app.output import OutputError, write_image

    with pytest.raises(OutputError, match=r"^output path: expected a str or an os.PathLike"):
        write_image(path, None)


def _path_calls():
    from pyjulia4d.app import animation, video
    from pyjulia4d.app.explore.notebook import Explorer
    from pyjulia4d.app.output import check_output_path
    from pyjulia4d.interop.povray import writer

    return [(check_output_path, "output path: expected"), (animation.check_pattern, "frame pattern: expected"),
            (lambda p: animation.strip([p], "sheet.png"), "frame path: expected"),
            (lambda p: animation.strip([], p), "contact sheet path: expected"),
            (video.check_video_path, "video path: expected"), (video.read_frame, "frame path: expected"),
            (writer.import_pov, "POV-Ray scene path: expected"),
            (lambda p: writer.check_toml_path(p, "a.pov"), "scene file path: expected"),
            (lambda p: Explorer(folder=p), "--folder: expected")]


@pytest.mark.parametrize("bad", [3, None, b"a.png", Hostile()], ids=["int", "None", "bytes", "hostile"])
def test_every_path_argument_takes_a_path(bad) -> None:
    """Each function of the package that takes a path refuses anything but a str or an
    os.PathLike in one line of its own error (a ValueError), before it opens anything."""
    for call, message in _path_calls():
        with pytest.raises(ValueError) as e:
            call(bad)
        assert str(e.value).startswith(message) and "a str or an os.PathLike" in str(e.value), call


def test_a_file_that_is_no_frame_is_named(tmp_path) -> None:
    from pyjulia4d.app.output import OutputError
    from pyjulia4d.app.video import read_frame

    fake = tmp_path / "frame.png"
    fake.write_text("not a picture")
    with pytest.raises(OutputError, match=r"frame.png: cannot read it as a frame \(UnidentifiedImageError"):
        read_frame(fake)
    with pytest.raises(OutputError, match=r"missing.png: cannot read it as a frame \(FileNotFoundError"):
        read_frame(tmp_path / "missing.png")


def test_device_and_workers_of_the_wrong_type() -> None:
    from pyjulia4d.app.cluster import check_workers, worker_device
    from pyjulia4d.opencl.devices import DeviceError, select_device

    for bad in (3, Hostile(), b"cpu"):
        with pytest.raises(DeviceError, match=r"^device: expected None or a text"):
            select_device(bad)
        with pytest.raises(DeviceError, match=r"^device: expected None or a text"):
            worker_device(bad)
    for bad in (Hostile(), 2.5, True, None):
        with pytest.raises(SceneError, match=r"^--workers: expected a whole number of workers"):
            check_workers(bad)
    assert check_workers(3) == 3 and check_workers(" 2 ") == 2


@pytest.mark.parametrize("header,message", [
    (5, "header: expected None or a dict of text entries, got int"),
    (Hostile(), "header: expected None or a dict of text entries, got Hostile"),
    ({"k" * 80: "v"}, "header: key 'kkk"),
    ({"": "v"}, "header: key '': expected 1 to 79 printable Latin-1 characters"),
    ({"ключ": "v"}, "header: key 'ключ': expected 1 to 79 printable Latin-1"),
    ({" a": "v"}, "header: key ' a'"),
    ({"a\x00b": "v"}, "header: key 'a\\x00b'"),
    ({"a": 1}, "header: a: expected text without NUL"),
    ({"a": "x\x00"}, "header: a: expected text without NUL"),
    ({"pyjulia4d.scene": "junk"}, "header: key 'pyjulia4d.scene': the pyjulia4d.* entries are the render's own"),
])
@pytest.mark.parametrize("ext", ["png", "exr", "tif"])
def test_a_saved_images_header_is_checked_before_anything_is_written(header, message, ext, tmp_path) -> None:
    from pyjulia4d import render
    from pyjulia4d.app.output import OutputError

    r = render(Scene.default().with_overrides(["image.width=8", "image.height=6"]))
    with pytest.raises(OutputError) as e:
        r.save(tmp_path / f"x.{ext}", header=header)
    assert str(e.value).startswith(message) and "\n" not in str(e.value)
    assert list(tmp_path.iterdir()) == []
    r.save(tmp_path / f"x.{ext}", header={"artist": "A. Person", "note": "ünïcode välue"})
    from pyjulia4d.app.output import read_header

    got = read_header(tmp_path / f"x.{ext}")
    assert got["artist"] == "A. Person" and got["note"] == "ünïcode välue" and "pyjulia4d.scene" in got


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), float("inf"), True, "1e-3", Hostile()])
def test_a_reports_stated_bound_is_checked(bad) -> None:
    from pyjulia4d import render

    r = render(Scene.default().with_overrides(["image.width=8", "image.height=6"]))
    with pytest.raises(SceneError, match=r"^stated_p99: expected None or a positive finite number"):
        r.report(bad)


def test_the_animation_interface_names_bad_arguments(tmp_path) -> None:
    """docs/animation.md's Python interface: keyframes.load, Animation.scene and with_camera."""
    from pyjulia4d.scene import keyframes

    src = tmp_path / "a.toml"
    src.write_text("[animation]\nframes = 3\n[[keyframe]]\nframe = 0\nfractal.c = [0, 0.5, 0, 0]\n"
                   "[[keyframe]]\nframe = 2\nfractal.c = [0, 0.7, 0, 0]\n")
    anim = keyframes.load(src)
    cases = [(lambda: keyframes.load(src, Hostile()), "overrides: expected a list of SECTION.KEY=VALUE texts"),
             (lambda: keyframes.load(src, 5), "overrides: expected a list of SECTION.KEY=VALUE texts, got 5"),
             (lambda: keyframes.from_table(5), "scene: expected a table, got 5"),
             (lambda: anim.scene("1"), "frame: expected a whole frame number, got '1'"),
             (lambda: anim.scene(Hostile()), "frame: expected a whole frame number, got <a Hostile>"),
             (lambda: anim.scene(3), "--frames: frame 3 is outside 0..2"),
             (lambda: anim.with_camera(Hostile(), [0, 0, 0]), "camera.position: expected a list of 3 or 4 numbers"),
             (lambda: anim.with_camera([1, 2, 3], None), "camera.target: expected a list of 3 or 4 numbers"),
             (lambda: keyframes.parse_frames(5, 3), "--frames: expected A:B")]
    for call, message in cases:
        with pytest.raises(SceneError) as e:
            call()
        assert str(e.value).startswith(message), str(e.value)
    assert anim.scene(1).fractal.c[1] == pytest.approx(0.6)


def test_animate_checks_its_arguments_before_any_frame(tmp_path) -> None:
    from pyjulia4d.app import animation
    from pyjulia4d.scene import keyframes

    src = tmp_path / "a.toml"
    src.write_text("[image]\nwidth = 8\nheight = 6\n[animation]\nframes = 2\n")
    anim = keyframes.load(src)
    pattern = str(tmp_path / "f" / "m_##.png")
    for kw, message in [(dict(frames=5), "frames: expected a list of frame numbers, got 5"),
                        (dict(frames=Hostile()), "frames: expected a list of frame numbers"),
                        (dict(frames=[0, "1"]), "frames: expected whole frame numbers, got '1'"),
                        (dict(frames=[0, 0]), "frames: a frame is named twice"),
                        (dict(force=Hostile()), "force: expected True or False"),
                        (dict(progress="yes"), "progress: expected True or False"),
                        (dict(on_written=5), "on_written: expected None or a callable")]:
        with pytest.raises(SceneError) as e:
            animation.animate(anim, pattern, workers=0, **kw)
        assert str(e.value).startswith(message), str(e.value)
    with pytest.raises(SceneError, match=r"^anim: expected an Animation"):
        animation.animate(Scene.default(), pattern, workers=0)
    assert list(tmp_path.iterdir()) == [src]


@pytest.mark.parametrize("bad", [5, b"/tmp", Hostile()], ids=["int", "bytes", "hostile"])
def test_an_image_stores_folder_is_a_path(bad) -> None:
    from pyjulia4d.pipeline.store import ImageStore

    with pytest.raises(SceneError, match=r"^store: expected None or a folder, a str or an os.PathLike"):
        ImageStore(bad)


def test_a_mesh_and_a_header_path_are_checked(tmp_path) -> None:
    from pyjulia4d.app.mesh import write_mesh
    from pyjulia4d.app.output import OutputError, read_header

    with pytest.raises(OutputError, match=r"^mesh path: expected a str or an os.PathLike, got int"):
        write_mesh(5, None)
    with pytest.raises(OutputError, match=r"m.stl: expected a MeshResult to write, got NoneType"):
        write_mesh(tmp_path / "m.stl", None)
    with pytest.raises(OutputError, match=r"^image path: expected a str or an os.PathLike, got Hostile"):
        read_header(Hostile())
    assert read_header(tmp_path / "missing.png") is None and list(tmp_path.iterdir()) == []


def test_mesh_executor_is_checked_before_it_is_compared() -> None:
    from pyjulia4d.app.mesh import build_mesh

    with pytest.raises(SceneError, match=r"^executor: expected 'opencl' or 'reference', got <a Hostile>"):
        build_mesh(Scene.default(), resolution=8, executor=Hostile())


def test_one_output_name_is_one_output() -> None:
    from pyjulia4d import render

    r = render(Scene.default().with_overrides(["image.width=16", "image.height=12"]), outputs="depth")
    assert r.depth is not None and r.color is None


@pytest.mark.parametrize("bad", [None, 3, "scene", {"fractal": {}}])
def test_reference_refuses_a_non_scene(bad) -> None:
    from pyjulia4d import reference

    with pytest.raises(SceneError, match=r"^scene: expected a pyjulia4d.Scene"):
        reference.render(bad)


@pytest.mark.parametrize("text,message", [
    ("[fractal\n", "src.png (its scene): invalid TOML"),
    ("[animation]\nframes = 3\n", "animation: a keyframed scene"),
    ("x" * (1 << 20 + 1), "src.png: its scene is larger than 1 MiB"),
])
def test_render_an_image_whose_scene_is_bad(tmp_path: Path, capsys, monkeypatch, text, message) -> None:
    from PIL import PngImagePlugin

    monkeypatch.chdir(tmp_path)
    info = PngImagePlugin.PngInfo()
    info.add_text("pyjulia4d.scene", text)
    Image.new("RGBA", (4, 4)).save("src.png", pnginfo=info)
    assert cli.main(["render", "src.png"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pyjulia4d: error: {message}") and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["src.png"]
