"""One source, two variants (kernels/common/lanes.cl, "Lanes"): the march run one ray per
work-item and in packets of 4, 8 and 16 neighbouring rays (4 and 8 in double precision) must
give the same pixels.

Not bit for bit: the packet variant sums |q|^2 as four products where the one-ray variant
calls dot(), and ITP's interpolation amplifies that last-bit difference into a different
point inside the same certified bracket.  So: the same status on every pixel but a
handful, the same sample counts and guard flags there, and brackets that overlap."""
import json

import numpy as np
import pytest

from harness import packet_widths
from pyjulia4d.opencl import lanes as lanes_mod
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline.codes import STATUS_HIT
from pyjulia4d.scene.model import Scene

SCENES = [
    [],
    ["march.method=fixed", "march.post_steps=10", "fractal.c=0.4,0.5,0,0", "fractal.max_iter=20"],
    ["march.quality=final", "camera.position=-2,1,5,0.8", "camera.limbo=0,0.3,0,1"],
    ["march.method=de", "march.refine=bisect", "fractal.c=-0.75,0.15,0,0", "fractal.max_iter=20"],
    ["march.epsilon=1e-8", "march.post_steps=0", "fractal.max_iter=100"],   # ulp steps
    ["camera.position=0.05,0.1,-0.1,0", "camera.target=0,0,1,0"],           # eye inside
    ["fractal.function=cube", "fractal.c=0.3,0.4,0,0"],
    ["fractal.algebra=hypercomplex", "fractal.function=sqr", "fractal.max_iter=8"],
    ["fractal.algebra=hypercomplex", "fractal.function=sin", "fractal.c=0.5,0.3,0.2,0",
     "fractal.max_iter=6", "camera.position=3,2.5,-4,0"],
    ["fractal.algebra=hypercomplex", "fractal.function=pwr", "fractal.exponent=2.5,0.5",
     "fractal.max_iter=6"],
    ["fractal.algebra=cquat", "fractal.c=-0.7323,-0.2179,0.1,0", "fractal.max_iter=10"],
]


# every scene at the default width (16: its programs are built by other tests anyway), and
# the narrower widths on a sample: the default, the ulp-step scene and a transcendental one;
# the rest is marked slow (setup.cfg)
SAMPLED = (0, 4, 8)


def _cases():
    out = []
    for i, over in enumerate(SCENES):
        for lanes in packet_widths():
            slow = lanes != max(packet_widths()) and i not in SAMPLED
            out.append(pytest.param(over, lanes, id=f"over{i}-{lanes}",
                                    marks=[pytest.mark.slow] if slow else []))
    # double precision: its widest packet on the default's estimate; the rest, a transcendental
    # function's proven march among them, in the slow run (setup.cfg)
    for i, over in enumerate(SCENES):
        for lanes in packet_widths((8,), double=True):
            out.append(pytest.param(over + ["render.float=double"], lanes, id=f"over{i}-double-{lanes}",
                                    marks=[] if i == 0 else [pytest.mark.slow]))
    return out


@pytest.mark.filterwarnings("ignore:march.epsilon")   # the ulp-step scene: its warning is the point
@pytest.mark.parametrize("over,lanes", _cases())
def test_packets_give_the_same_pixels(over, lanes):
    # 61 x 37 = 2257 pixels: the last packet is partly past the image
    s = Scene.default().with_overrides(over + ["image.width=61", "image.height=37"])
    one, pk = render(s, lanes=1), render(s, lanes=lanes)
    assert pk.lanes == lanes and one.lanes == 1
    same = one.status == pk.status
    assert np.mean(same) >= 0.998
    if not one.proven:   # the proven march sizes its segments by margins, which rounding moves
        assert np.mean(one.samples[same] == pk.samples[same]) >= 0.99
    assert one.guards == pytest.approx(pk.guards, abs=max(2, 0.002 * s.image.width * s.image.height))
    hit = (one.status == STATUS_HIT) & (pk.status == STATUS_HIT)
    a, wa = one.depth[hit].astype(float), one.bracket[hit].astype(float)
    b, wb = pk.depth[hit].astype(float), pk.bracket[hit].astype(float)
    # each states the crossing near [depth - unresolved, depth + bracket] (kernels/march/proven.cl;
    # the fixed scan and the estimate are compared on their brackets)
    ua = one.unresolved[hit].astype(float) if one.proven else 0.0
    ub = pk.unresolved[hit].astype(float) if pk.proven else 0.0
    slack = 1e-6 * (1 + np.maximum(a, b))
    overlap = np.maximum(a - ua, b - ub) <= np.minimum(a + wa, b + wb) + slack
    assert np.mean(overlap) >= 0.995
    # the same depth gives the same normal up to the rounding of the Jacobian's sums, which
    # packets add as products where one ray calls dot() (where the depths differ by a few
    # ulp, so may the normals of a max_iter-20 surface)
    eq = a == b
    # measured 79-100 % for quaternions; 67 % for the hypercomplex square (its box-like faces
    # meet the rays at grazing angles, so an ulp in an iterate moves the depth), and the
    # functions' vector exp, log, atan2 (PoCL's libm) round differently from the scalar ones
    hyper = any(o.startswith("fractal.algebra=") and o != "fractal.algebra=quaternion" for o in over)
    assert np.mean(eq) >= (0.6 if hyper else 0.75)
    dn = np.abs(pk.normal[hit][eq] - one.normal[hit][eq]).max(axis=-1)
    assert np.mean(dn <= 1e-4) >= 0.99, np.percentile(dn, [50, 99, 100])


def test_variant_choice_and_its_cache(tmp_path, monkeypatch):
    from harness import device
    from pyjulia4d.opencl.devices import device_key, forget_remembered

    dev = device()
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    forget_remembered()
    assert lanes_mod.lanes_for(dev, "scalar", False) == 1
    probed = lanes_mod.lanes_for(dev, "packet", False)
    assert probed in (1,) + lanes_mod.WIDTHS
    known = json.loads((tmp_path / "lanes.json").read_text())
    assert known[device_key(dev)] == probed
    # double precision: a probe of its own, kept apart
    probed_double = lanes_mod.lanes_for(dev, "packet", True)
    assert probed_double in (1,) + lanes_mod.DOUBLE_WIDTHS
    assert json.loads((tmp_path / "lanes_double.json").read_text())[device_key(dev)] == probed_double
    # cached: no second probe, in this process or the next
    forget_remembered()
    monkeypatch.setattr(lanes_mod, "probe", lambda *a, **k: pytest.fail("probed twice"))
    assert lanes_mod.lanes_for(dev, "packet", False) == probed
    assert lanes_mod.lanes_for(dev, "packet", True) == probed_double
    # the compiler probe likewise: remembered in compiles.json, no second build
    from pyjulia4d.opencl import devices
    assert devices.compile_error(dev) == ""
    assert json.loads((tmp_path / "compiles.json").read_text())[device_key(dev)] == ""
    forget_remembered()
    monkeypatch.setattr(devices, "_probe_build", lambda *a: pytest.fail("built the probe twice"))
    assert devices.compile_error(dev) == ""
    forget_remembered()


@pytest.mark.parametrize("junk", ["", "{", "[1, 2]", '{"x": 1}', "null", "\u0000\u00ff"])
def test_a_damaged_cache_is_found_again(tmp_path, monkeypatch, junk):
    """compiles.json and lanes.json that do not hold the answer (empty, cut short, not a
    table, another device's, binary) are answered again and rewritten, never trusted."""
    from harness import device
    from pyjulia4d.opencl import devices
    dev = device()
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    for name in ("compiles", "lanes"):
        (tmp_path / f"{name}.json").write_text(junk)
    devices.forget_remembered()
    monkeypatch.setattr(lanes_mod, "probe", lambda d: 8)
    assert devices.compile_error(dev) == ""
    assert lanes_mod.lanes_for(dev, "packet", False) == 8
    assert json.loads((tmp_path / "lanes.json").read_text())[devices.device_key(dev)] == 8
    assert json.loads((tmp_path / "compiles.json").read_text())[devices.device_key(dev)] == ""
    devices.forget_remembered()


def test_a_probe_that_ran_out_of_time_is_not_cached(tmp_path, monkeypatch):
    """A width whose probe only timed out (a busy machine) is not known to fail: this process
    marches one ray per work-item with a warning, and nothing is written, so the next process
    probes again; a width that ran and failed is an answer, cached as 1."""
    import subprocess
    from harness import device
    from pyjulia4d.opencl import devices
    dev = device()
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    devices.forget_remembered()
    calls = []

    def timed_out(cmd, **kw):
        calls.append(cmd[4])
        raise subprocess.TimeoutExpired(cmd, kw.get("timeout"))

    monkeypatch.setattr(lanes_mod.subprocess, "run", timed_out)
    with pytest.warns(RuntimeWarning, match="ran out of time"):
        assert lanes_mod.lanes_for(dev, "packet", False) == 1
    assert calls == [str(w) for w in lanes_mod.WIDTHS]
    assert not (tmp_path / "lanes.json").exists()
    devices.forget_remembered()
    monkeypatch.setattr(lanes_mod.subprocess, "run",
                        lambda cmd, **kw: subprocess.CompletedProcess(cmd, 1, "", "build failed"))
    assert lanes_mod.lanes_for(dev, "packet", False) == 1
    assert json.loads((tmp_path / "lanes.json").read_text())[devices.device_key(dev)] == 1
    devices.forget_remembered()


def test_scene_variant_key():
    s = Scene.default().with_overrides(["render.variant=scalar", "image.width=9", "image.height=7"])
    assert render(s).lanes == 1


def test_the_proven_march_takes_the_width_its_probe_picked(tmp_path, monkeypatch):
    """march_lanes: the estimate and the scan keep the device's width; the proven march takes
    it, or PROVEN_LANES, as the timed probe found faster on the device (remembered in
    lanes_proven.json: probed once); a probe that fails or answers neither width leaves
    PROVEN_LANES, uncached; a width no wider than PROVEN_LANES needs no probe."""
    from harness import device
    from pyjulia4d.opencl import devices
    dev = device()
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    devices.forget_remembered()
    calls = []

    def fake(d, widths, answer):
        calls.append(widths)
        return answer

    monkeypatch.setattr(lanes_mod, "probe_proven", lambda d, w: fake(d, w, 16))
    assert lanes_mod.march_lanes(16, "de", dev) == 16 and lanes_mod.march_lanes(16, "fixed", dev) == 16
    assert calls == []
    assert lanes_mod.march_lanes(16, "proven", dev) == 16
    assert lanes_mod.march_lanes(16, "proven", dev) == 16 and calls == [(8, 16)]   # remembered
    assert json.loads((tmp_path / "lanes_proven.json").read_text())[devices.device_key(dev)] == 16
    assert lanes_mod.march_lanes(8, "proven", dev) == 8 and lanes_mod.march_lanes(4, "proven", dev) == 4
    assert lanes_mod.march_lanes(16, "proven", None) == lanes_mod.PROVEN_LANES
    for answer in (None, 4):
        devices.forget_remembered()
        (tmp_path / "lanes_proven.json").unlink(missing_ok=True)
        monkeypatch.setattr(lanes_mod, "probe_proven", lambda d, w, a=answer: fake(d, w, a))
        assert lanes_mod.march_lanes(16, "proven", dev) == lanes_mod.PROVEN_LANES
    devices.forget_remembered()


@pytest.mark.slow   # two builds of the proven march and six timed renders in a child process
def test_the_proven_width_probe_answers_one_of_its_widths():
    from harness import device
    dev = device()
    assert lanes_mod.probe_proven(dev, (4, 8)) in (4, 8)
