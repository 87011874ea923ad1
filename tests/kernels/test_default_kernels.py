"""The default Julia scene compiles to exactly the kernels it compiled to before the other
kinds of set (fractal.kind, fractal.theta: kernels/kind/) existed: those reach the shared
pieces only through -D switches the default scene does not set (KIND_*, ROTATE_*, STACK_*,
KIND_NORMAL), so the default's preprocessed source must not change by a single token.

The reference, tests/data/default_kernels.i, is the C preprocessor's output (cpp -P -undef,
blank lines dropped) of the default scene's one-ray march program - the iteration
(real, algebra/complex, function/sqr, algebra/quaternion, iterate), march/refine.cl,
march/de.cl and normals/jacobian.cl - with the default scene's -D switches (REFINE_ITP and
the shading's), made from the kernels as they were before the kinds (the same tokens as
these pieces with the kind blocks compiled out, checked when the reference was written).  Comments and layout do not count;
every token does.  The ray generation (rays.cl), the march kernel's entry point
(march/march.cl) and the shading are left out: the kinds never touch them and they change
with features of their own.  If a change to these pieces is meant to change the default
scene (not a kind), rewrite the reference with
    .venv/bin/python tests/kernels/test_default_kernels.py --write
and say why in the change."""
import difflib
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from pyjulia4d.pipeline import kernel_config
from pyjulia4d.scene.model import Scene

REFERENCE = Path(__file__).resolve().parents[1] / "data" / "default_kernels.i"
PIECES = ("common/codes", "common/lanes", "algebra/complex", "function/sqr", "algebra/quaternion", "iterate", "march/refine",
          "march/de", "normals/jacobian")
HEADER = "// tests/kernels/test_default_kernels.py: the default scene's preprocessed kernels (see its docstring)\n"


def default_config() -> kernel_config.KernelConfig:
    cfg = kernel_config.march_config(Scene.default(), 1)
    return kernel_config.KernelConfig(tuple(p for p in cfg.pieces if p in PIECES), cfg.defines)


def preprocessed(config: kernel_config.KernelConfig) -> str:
    cpp = shutil.which("cpp")
    if cpp is None:
        pytest.skip("no C preprocessor (cpp) on this machine")
    src = kernel_config.source(config)
    out = subprocess.run([cpp, "-P", "-undef", "-x", "c", *[f"-D{d}" for d in config.defines], "-"],
                         input=src, capture_output=True, text=True, check=True).stdout
    return "".join(" ".join(line.split()) + "\n" for line in out.splitlines() if line.strip())


def test_default_scene_uses_the_pre_kinds_pieces_and_switches():
    cfg = kernel_config.march_config(Scene.default(), 1)
    # the iteration and the march as before the kinds (the shading pieces after them are its own),
    # after common/codes.cl, which holds the status and guard codes common/lanes.cl defined before (#defines only)
    # and march/cone.cl's start of the camera rays (-D CONE_START), which the kinds never touch
    assert cfg.pieces[:12] == ("common/codes", "common/lanes", "algebra/complex", "function/sqr", "algebra/quaternion", "iterate",
                               "march/refine", "march/de", "rays", "march/cone", "march/march", "normals/jacobian")
    assert not [p for p in cfg.pieces if p.startswith("kind/")]
    assert not [d for d in cfg.defines if d.startswith(("KIND_", "ROTATE_", "STACK_", "LOCUS_"))]


def test_default_kernels_are_token_for_token_the_pre_kinds_ones():
    got = preprocessed(default_config())
    want = REFERENCE.read_text()
    assert want.startswith(HEADER)
    want = want[len(HEADER):]
    if got != want:
        diff = "".join(list(difflib.unified_diff(want.splitlines(True), got.splitlines(True), "reference",
                                                 "now", n=1))[:60])
        pytest.fail("the default scene's preprocessed kernels changed:\n" + diff)


def test_the_check_sees_a_kind_switch():
    # the same pieces built for a stack (-D KIND_NORMAL ... with its piece) differ: the
    # comparison above is sensitive to what a kind compiles in
    s = Scene.default().with_overrides(["fractal.kind=julia_stack"])
    cfg = kernel_config.march_config(s, 1)
    assert preprocessed(kernel_config.KernelConfig(tuple(p for p in cfg.pieces if p in PIECES + ("kind/julia_stack",)),
                                           cfg.defines)) != preprocessed(default_config())


if __name__ == "__main__" and sys.argv[1:] == ["--write"]:
    REFERENCE.write_text(HEADER + preprocessed(default_config()))
    print(f"wrote {REFERENCE}")
