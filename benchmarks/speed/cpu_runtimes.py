"""The CPU OpenCL runtimes side by side on every algebra x function pair: kernel time and
first-build time, the measurement behind the default device rule (devices.select_device:
Intel's CPU runtime before PoCL).

    python benchmarks/speed/cpu_runtimes.py [--size 320x240] [--repeats 3] [--only NAME ...]

Every CPU device that compiles takes part (Intel's runtime from the intel-opencl-rt wheel,
PoCL from Debian's pocl-opencl-icd or PyPI where it compiles; a device that cannot compile
is listed and skipped).  Each pair's scene is the gallery's (benchmarks/galleries/gallery.py: fixed
scan of 250 samples with 10 post-steps where the pair has no distance estimate), plus the
cube of the CQuats and of the commutative rules.  Per pair and device a child process with
empty program caches (pyjulia4d's, PoCL's and pyopencl's) renders once - "first", which builds the
programs - then ``--repeats`` times: the median kernel time.  The devices alternate in order
from pair to pair, so drift on this shared machine falls on both.  Writes
benchmarks/results/cpu_runtimes.md (a section per run, with commit, devices and date).
"""
from __future__ import annotations

import json
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.galleries.gallery import COMMON, SCENES  # noqa: E402
from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

CHILD = r"""
import json, statistics, sys, time, warnings
warnings.simplefilter("ignore")
from pyjulia4d import Scene, render
from pyjulia4d.opencl.devices import select_device
spec, repeats, overrides = sys.argv[1], int(sys.argv[2]), json.loads(sys.argv[3])
scene = Scene.default().with_overrides(overrides)
dev = select_device(spec)
t0 = time.perf_counter()
first = render(scene, device=dev)
first_s = time.perf_counter() - t0
runs = [render(scene, device=dev) for _ in range(repeats)]
print(json.dumps({"first": first_s, "kernel": statistics.median(r.kernel_seconds for r in runs),
                  "render": statistics.median(r.seconds for r in runs), "hit": first.hit_fraction,
                  "lanes": first.lanes}))
"""


def pairs() -> dict[str, list[str]]:
    """Scene name -> overrides: the gallery's pairs and the CQuat and commutative cubes."""
    from pyjulia4d.fractal.registry import FUNCTIONS_OF

    out = {name: COMMON + keys for name, keys in SCENES.items()}
    for algebra, functions in FUNCTIONS_OF.items():
        for f in functions:
            name = f"{algebra}_{f}"
            if name not in out:   # the same view as the algebra's sqr
                base = out[f"{algebra}_sqr"]
                out[name] = base + [f"fractal.function={f}", "fractal.max_iter=8"]
    return out


def cpu_devices() -> list[tuple[str, str, str]]:
    """(P:D spec, short name, why skipped or "") for every CPU device."""
    from pyjulia4d.opencl.devices import compile_error, device_type, list_devices
    from pyjulia4d.opencl.lanes import device_spec

    return [(device_spec(d), f"{p.name.strip()} {d.driver_version.strip()}", compile_error(d))
            for p, d in list_devices() if device_type(d) == "CPU"]


def run_child(spec: str, overrides: list[str], repeats: int, lanes_file: Path | None) -> dict:
    """One pair on one device in a fresh process with empty program caches."""
    import os

    with tempfile.TemporaryDirectory(prefix="cpu-runtimes-") as tmp:
        # pyopencl keeps binaries of drivers that cache none of their own (Intel's) under
        # $XDG_CACHE_HOME/pyopencl: every cache is empty, so "first" is a cold build
        env = dict(os.environ, PYJULIA4D_CACHE=str(Path(tmp) / "pyjulia4d"), POCL_CACHE_DIR=str(Path(tmp) / "pocl"),
                   XDG_CACHE_HOME=str(Path(tmp) / "xdg"))
        env.pop("OCL_ICD_VENDORS", None)   # the child registers the runtimes as any process does
        if lanes_file is not None and lanes_file.exists():   # the packet width probe's answer, not re-probed
            (Path(tmp) / "pyjulia4d").mkdir()
            shutil.copy(lanes_file, Path(tmp) / "pyjulia4d" / "lanes.json")
        p = subprocess.run([sys.executable, "-c", CHILD, spec, str(repeats), json.dumps(overrides)],
                           capture_output=True, text=True, env=env, timeout=1800)
    if p.returncode != 0:
        return {"error": (p.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(p.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="320x240", help="image size WxH (default 320x240)")
    ap.add_argument("--repeats", type=int, default=3, help="renders after the first, per pair and device")
    ap.add_argument("--only", nargs="*", default=[], help="pair names, e.g. hypercomplex_sin")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")

    from pyjulia4d.opencl.devices import remembered_path, select_device
    from pyjulia4d.opencl.lanes import lanes_for

    devices = cpu_devices()
    usable = [(s, n) for s, n, err in devices if not err]
    for s, n, err in devices:
        if err:
            print(f"skipped {s} {n}: cannot compile: {err}")
    if not usable:
        raise SystemExit("cpu_runtimes.py: no CPU device compiles")
    for s, _ in usable:   # probe the packet widths once, in this process's cache
        lanes_for(select_device(s), "auto", False)
    todo = pairs()
    if a.only:
        todo = {k: v for k, v in todo.items() if k in a.only}
    rows = []
    names = [n for _, n in usable]
    head = ("| pair | " + " | ".join(f"kernel s: {n}" for n in names) + " | "
            + " | ".join(f"first s: {n}" for n in names) + " | kernel ratio (first / others) |\n"
            + "|---" * (2 * len(names) + 2) + "|\n")
    print(head, end="")
    ratios = []
    for i, (name, overrides) in enumerate(todo.items()):
        order = usable if i % 2 == 0 else usable[::-1]
        got = {n: run_child(s, overrides + [f"image.width={w}", f"image.height={h}"], a.repeats, remembered_path("lanes"))
               for s, n in order}
        res = [got[n] for n in names]
        cells = [f"{r['kernel']:.3f}" if "kernel" in r else f"error: {r['error'][:60]}" for r in res]
        firsts = [f"{r['first']:.2f}" if "first" in r else "-" for r in res]
        ratio = ""
        if len(res) > 1 and all("kernel" in r for r in res):
            q = [res[0]["kernel"] / r["kernel"] for r in res[1:]]
            ratios.append(q[0])
            ratio = ", ".join(f"{x:.2f}" for x in q)
        row = f"| {name} | " + " | ".join(cells) + " | " + " | ".join(firsts) + f" | {ratio} |"
        rows.append(row)
        print(row, flush=True)
    summary = ""
    if ratios:
        summary = (f"\nKernel time of {names[0]} over {names[1]}: median {statistics.median(ratios):.2f}, "
                   f"range {min(ratios):.2f}-{max(ratios):.2f}, faster on {sum(r < 1 for r in ratios)} of "
                   f"{len(ratios)} pairs.\n")
        print(summary)
    section = (f"\n## {utc_now()}, commit {git_commit()}, {w}x{h}, median of {a.repeats} after a first render "
               f"with empty program caches\n\nDevices: " + "; ".join(f"{s} {n}" for s, n in usable) + "\n\n"
               + head + "\n".join(rows) + "\n" + summary)
    append_run(a.out / "cpu_runtimes.md", "# CPU OpenCL runtimes: kernel and first-build time per pair\n", section)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
