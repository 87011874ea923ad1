"""benchmarks/speed/gpu_check.sh, the run prepared for the day a GPU is lent, run at a tiny size on
Oclgrind (the GPU-shaped simulator) so that it cannot rot: its tests, the default frame's
time, the path tracer's paths per second and the throughput table, each written under OUT."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from pyjulia4d.opencl.devices import indexed_devices, is_simulator

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.skipif(not any(is_simulator(d) for _, _, d in indexed_devices()),
                    reason="Oclgrind is not installed (pip install '.[test]')")
def test_gpu_check_runs_whole_on_a_simulated_gpu(tmp_path):
    env = dict(os.environ, DEVICE="oclgrind", SIZES="16x12", PATH_SIZE="16x12", PATH_SAMPLES="2", REPEATS="1",
               THROUGHPUT_SIZE="12x9", THROUGHPUT_SCENES="1", PEAK_ITEMS="64", JOBS="1",
               TESTS="tests/kernels/test_rays.py", OUT=str(tmp_path), PY=sys.executable,
               PYJULIA4D_CACHE=str(tmp_path / "cache"))
    env.pop("PYJULIA4D_DEVICE", None)
    p = subprocess.run(["bash", str(ROOT / "benchmarks" / "speed" / "gpu_check.sh")], env=env, capture_output=True,
                       text=True, timeout=600)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    assert "passed" in (tmp_path / "tests.txt").read_text()
    times = (tmp_path / "render_time.md").read_text()
    assert times.count("| Oclgrind Simulator | 16x12 |") == 2 and "paths/s)" in times
    table = (tmp_path / "throughput.md").read_text()
    assert "Oclgrind Simulator" in table and "| default (de" in table
    assert "Oclgrind" in (tmp_path / "devices.txt").read_text()
