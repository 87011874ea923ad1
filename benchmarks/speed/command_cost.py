"""What the whole command costs: CPU-seconds, wall time and peak memory of `python -m
pyjulia4d render`, from start-up to the file written.

Each case is the command in a child process, measured by os.wait4 (user + system CPU of the
process and its threads, peak resident memory ru_maxrss); cases alternate, --repeats each,
after one untimed run of each that fills the disk caches (programs, packet widths, the
remembered default device).  The cases: the start-up (an 8x6 PNG: importing, loading the
OpenCL runtime, framing, the tiny render and the write), 640x480 PNG, and 3840x2160 PNG and EXR
(every channel; --force: their work estimate asks for it).  Each is run twice side by side:

* as the command runs (one OpenCL runtime loaded once the default device is remembered,
  OpenBLAS at one thread: opencl/default_device.py, __main__.py);
* "every runtime": the same with OCL_ICD_VENDORS set to pyjulia4d's own vendors folder (a
  user's setting, which the command leaves alone, so every runtime is loaded as before) and
  OpenBLAS at one thread per core.

Reports medians and the ratio of each case to its "every runtime" twin.  Then the start-up's
floor: what the command cannot avoid before its first kernel, as children that stop at each
stage (OpenBLAS at one thread, as the command runs; cumulative CPU-s, medians of the same
repeats): Python alone; numpy and pyopencl imported; the render's own modules imported; the
default device's runtime loaded and its context made (the device remembered, so that
runtime alone, as the command loads it).  Writes benchmarks/results/command_cost.md (a
section per run: device, date, commit).

With ``--rev REV`` the second of each pair is the same command from commit REV's tree (a git
worktree made for the run and removed after) instead of every runtime loaded: this
checkout's command against an earlier one's, side by side, as ratios.

    python benchmarks/speed/command_cost.py [--repeats 5] [--big 3840x2160] [--no-big] [--rev REV]
"""
from __future__ import annotations

import contextlib
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, earlier_tree, git_commit, short_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402


# The start-up's floor, stage by stage: each a child that stops there (cumulative)
_MODULES = "import pyjulia4d.__main__\nfrom pyjulia4d.app import cli, output\nfrom pyjulia4d.opencl import executor\n"
FLOOR = [("Python alone", "pass"),
         ("numpy and pyopencl imported", "import numpy, pyopencl"),
         ("the render's own modules imported", _MODULES),
         ("the default device's runtime loaded, its context made",
          _MODULES + "from pyjulia4d.opencl import default_device\nfrom pyjulia4d.opencl.runner import queue_for\n"
                     "default_device.allow()\nqueue_for(cli.select_device(None))\n")]


def run(args: list[str], env: dict[str, str], cwd: str) -> dict:
    """One command (``python -m pyjulia4d ARGS``, or ``python -c CODE`` where args is ["-c",
    CODE]): CPU-s (user + system), wall s, peak MiB; raises if it fails."""
    t = time.perf_counter()
    head = [] if args[:1] == ["-c"] else ["-m", "pyjulia4d"]
    p = subprocess.Popen([sys.executable, *head, *args], cwd=cwd, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    out, err = p.stdout.read().decode(), p.stderr.read().decode()
    p.stdout.close()
    p.stderr.close()
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed ({p.returncode}): {err.strip().splitlines()[-1:]}")
    return {"cpu": ru.ru_utime + ru.ru_stime, "wall": wall, "mib": ru.ru_maxrss / 1024, "line": out.strip()}


def measure(cases, modes, floor_env: dict[str, str], repeats: int) -> tuple[dict, str]:
    """Each case in each mode (name, environment), alternating, ``repeats`` times after one
    untimed run of each, and the floor's stages; {(case or stage, mode or "floor"): runs}."""
    got: dict[tuple[str, str], list[dict]] = {}
    device = "?"
    with tempfile.TemporaryDirectory() as tmp:
        for _, args in cases:                     # fill the caches, remember the device
            for _, env in modes:
                run(["render", *args], env, tmp)
        for k in range(repeats):
            for name, args in cases:
                order = modes if k % 2 == 0 else modes[::-1]
                for mode, env in order:
                    r = run(["render", *args], env, tmp)
                    got.setdefault((name, mode), []).append(r)
                    device = r["line"].split(" on ", 1)[-1].split(" (", 1)[0]
            for name, code in FLOOR:
                got.setdefault((name, "floor"), []).append(run(["-c", code], floor_env, tmp))
    return got, device


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--big", default="3840x2160", help="the large size (WxH)")
    ap.add_argument("--no-big", action="store_true", help="leave out the large renders")
    ap.add_argument("--rev", help="beside an earlier commit's command (its tree) instead of every runtime loaded")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    bw, bh = (str(v) for v in size_of(a.big, "--big"))
    rev = None if a.rev is None else short_commit(a.rev)
    if a.rev is not None and rev is None:
        ap.error(f"--rev: {a.rev!r} is no commit of this repository")
    cases = [("start-up, 8x6 PNG", ["--width", "8", "--height", "6", "-o", "s.png"]),
             ("640x480 PNG", ["--width", "640", "--height", "480", "-o", "m.png"])]
    if not a.no_big:
        cases += [(f"{a.big} PNG", ["--width", bw, "--height", bh, "--force", "-o", "b.png"]),
                  (f"{a.big} EXR, every channel", ["--width", bw, "--height", bh, "--force", "-o", "b.exr"])]
    import pyjulia4d.opencl.runtimes as runtimes

    runtimes.register()
    base = {k: v for k, v in os.environ.items() if k not in ("OCL_ICD_VENDORS", "OPENBLAS_NUM_THREADS")}
    base["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), base.get("PYTHONPATH")]))
    every = dict(base, OCL_ICD_VENDORS=runtimes.registered["folder"] or runtimes.SYSTEM_VENDORS,
                 OPENBLAS_NUM_THREADS=str(os.cpu_count() or 1))
    floor_env = dict(base, OPENBLAS_NUM_THREADS="1")   # as __main__.py sets it for the command
    with contextlib.ExitStack() as stack:
        if rev is None:
            modes = [("as run", base), ("every runtime", every)]
        else:   # the same command from the earlier commit's tree, in the same environment
            tree = stack.enter_context(earlier_tree(rev))
            modes = [("as run", base), (f"at {rev}", dict(base, PYTHONPATH=os.pathsep.join(
                filter(None, [str(tree), os.environ.get("PYTHONPATH")]))))]
        got, device = measure(cases, modes, floor_env, a.repeats)
    other = modes[1][0]
    rows = [f"| case | CPU-s | wall s | peak MiB | CPU-s, {other} | wall s, {other} | peak MiB, {other} | CPU ratio | "
            "wall ratio | memory ratio |", "|---|---|---|---|---|---|---|---|---|---|"]
    for name, _ in cases:
        m = {mode: {q: statistics.median(r[q] for r in got[name, mode]) for q in ("cpu", "wall", "mib")}
             for mode, _ in modes}
        s, e = m["as run"], m[other]
        rows.append(f"| {name} | {s['cpu']:.3f} | {s['wall']:.3f} | {s['mib']:.0f} | {e['cpu']:.3f} | {e['wall']:.3f} | "
                    f"{e['mib']:.0f} | {s['cpu'] / e['cpu']:.2f} | {s['wall'] / e['wall']:.2f} | {s['mib'] / e['mib']:.2f} |")
    start = statistics.median(r["cpu"] for r in got[cases[0][0], "as run"])
    rows += ["", f"The start-up's floor (cumulative, against the start-up's {start:.3f} CPU-s):", "",
             "| stage | CPU-s | this stage | share of the start-up |", "|---|---|---|---|"]
    before = 0.0
    for name, _ in FLOOR:
        cpu = statistics.median(r["cpu"] for r in got[name, "floor"])
        rows.append(f"| {name} | {cpu:.3f} | {cpu - before:+.3f} | {cpu / start:.0%} |")
        before = cpu
    rows.append(f"| the rest: programs from the disk cache, framing, the render, the PNG | {start:.3f} | "
                f"{start - before:+.3f} | 100% |")
    table = "\n".join(rows)
    print(table)
    section = (f"\n## {utc_now()}, {device}, commit {git_commit()}{'' if rev is None else ' beside ' + rev}, "
               f"median of {a.repeats} alternating runs\n\n"
               f"{table}\n")
    append_run(a.out / "command_cost.md",
               "# What the whole command costs\n\nWritten by `python benchmarks/speed/command_cost.py` (its docstring "
               "says what is measured).\n", section)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
