"""render.float = "auto", the default (scene/quality.py auto_precision, opencl/executor.py
resolve_float): double for the proven march of the sets whose float32 rounding stops proofs
short of the surface, on a CPU with fp64; single everywhere else; the result's scene (the
image's header) says which ran."""
import sys

import pytest

from pyjulia4d.fractal.registry import FUNCTIONS_OF
from pyjulia4d.opencl.executor import render
from pyjulia4d.scene.model import Scene

EXECUTOR = sys.modules["pyjulia4d.opencl.executor"]   # the package's name "render" is the function
DOUBLE = {("cquat", "sqr"), ("cquat", "cube"), ("commutative", "sqr"), ("commutative", "cube"),
          ("hypercomplex", "sin"), ("hypercomplex", "cos")}


@pytest.mark.parametrize("algebra", list(FUNCTIONS_OF))
def test_auto_takes_double_only_where_float32_stops_the_proofs(algebra):
    for function in FUNCTIONS_OF[algebra]:
        s = Scene.default().with_overrides([f"fractal.algebra={algebra}", f"fractal.function={function}"])
        assert s.render.float == "auto"
        want = "double" if (algebra, function) in DOUBLE and s.march.method == "proven" else "single"
        assert s.precision == want, (algebra, function)
        # a march that proves nothing keeps single; an explicit choice is kept as given
        assert s.with_overrides(["march.quality=custom", "march.method=fixed"]).precision == "single"
        assert s.with_overrides(["render.float=single"]).precision == "single"
        assert s.with_overrides(["render.float=double"]).precision == "double"


SMALL = ["fractal.algebra=commutative", "image.width=24", "image.height=18"]


def test_auto_is_resolved_for_the_device(monkeypatch):
    """On a CPU with fp64 the commutative square runs in double, and its statement tightens;
    a GPU, or a device without fp64, takes single (no refusal): the result's scene says which."""
    s = Scene.default().with_overrides(SMALL)
    cpu = render(s)
    assert cpu.scene.render.float == "double"
    single = render(s.with_overrides(["render.float=single"]))
    assert cpu.error_stats()["p99"] < 0.1 * single.error_stats()["p99"]
    monkeypatch.setattr(EXECUTOR, "device_type", lambda dev: "GPU")
    assert render(s).scene.render.float == "single"
    monkeypatch.undo()
    monkeypatch.setattr(EXECUTOR, "has_fp64", lambda dev: False)
    assert render(s).scene.render.float == "single"


def test_a_mesh_samples_in_single_under_auto():
    """"auto" serves the proven march's proofs; the mesh samples the set test (pipeline/mesh_plan.py)."""
    from pyjulia4d.pipeline.mesh_plan import make_mesh_plan
    s = Scene.default().with_overrides(["fractal.algebra=commutative"])
    assert s.precision == "double"
    assert not make_mesh_plan(s, 16).double and "REAL_DOUBLE" not in make_mesh_plan(s, 16).config.defines
    assert make_mesh_plan(s.with_overrides(["render.float=double"]), 16).double
