"""This checkout against an earlier commit, side by side: each kernel's time and a render's
CPU-seconds, as ratios.

The machine is shared and its speed drifts by a third within minutes, so two runs of a
benchmark an hour apart compare nothing.  Here the earlier commit (--rev, a git worktree made
for the run and removed after) and the checkout render the same scene in child processes that
alternate, --repeats pairs; each child renders once to build and warm, then --renders times,
(keeping every output, or with --png what a PNG keeps)
and reports the least time of each kernel (its OpenCL events, summed over the tiles) and the
least CPU-seconds of a whole render (getrusage: the host's work and the kernels' threads).
Each child starts with empty program caches (pyjulia4d's programs, pyopencl's and PoCL's
caches in a folder of its own; the remembered default device and probes copied in), so its
first render's wall time is the build of the scene's programs plus one render: what a new
scene costs a user, as in the explorer.
Reports the medians over the pairs and checkout / earlier; writes
benchmarks/results/commit_ratio.md (a section per run: both commits, device, date).

    python benchmarks/speed/commit_ratio.py --rev 6bff021 [--repeats 5] [--set KEY=VALUE ...] [--png]
"""
from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, earlier_tree, git_commit, short_commit, utc_now  # noqa: E402
from pyjulia4d.resources import cache_dir  # noqa: E402
from benchmarks.lib.args import Parser, size_of  # noqa: E402

CHILD = r"""
import collections, json, resource, sys, time, warnings
warnings.simplefilter("ignore")
from pyjulia4d import Scene, render
import pyjulia4d.opencl.executor as ex
renders, png, over = int(sys.argv[1]), sys.argv[2] == "png", sys.argv[3:]
scene = Scene.default().with_overrides(over)
outputs = None
if png:   # what a PNG keeps (colour and alpha), as peers.py's renders do
    from pyjulia4d.app.cli import CHANNEL_GROUPS
    outputs = CHANNEL_GROUPS["RGBA"]
events = []
home = sys.modules[ex.TileRunner.__module__]   # where the tile runner's launch lives, in either commit
launch = home.launch
def timed(queue, kernel, n, *args, **kw):
    e = launch(queue, kernel, n, *args, **kw)
    events.append((kernel.function_name, e))
    return e
home.launch = timed
t_first = time.perf_counter()
render(scene, outputs=outputs)
first = time.perf_counter() - t_first
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
best, best_cpu, device = {}, float("inf"), "?"
for _ in range(renders):
    events.clear()
    c0 = cpu()
    r = render(scene, outputs=outputs)
    best_cpu = min(best_cpu, cpu() - c0)
    device = r.device_name
    per = collections.Counter()
    for name, e in events:
        if e is not None:
            per[name] += (e.profile.end - e.profile.start) * 1e-9
    for name, s in per.items():
        best[name] = min(best.get(name, float("inf")), s)
print(json.dumps({"kernels": best, "cpu": best_cpu, "first": first, "device": device}))
"""


def child(tree: Path, renders: int, over: list[str], png: bool = False) -> dict:
    """One child process in ``tree``, its program caches empty (the module docstring)."""
    with tempfile.TemporaryDirectory() as cache:
        for item in cache_dir().iterdir() if cache_dir().is_dir() else ():
            if item.name != "programs":
                (shutil.copytree if item.is_dir() else shutil.copy2)(item, Path(cache) / item.name)
        env = dict(os.environ, PYTHONPATH=str(tree), PYJULIA4D_CACHE=cache, XDG_CACHE_HOME=str(Path(cache) / "xdg"),
                   POCL_CACHE_DIR=str(Path(cache) / "pocl"))
        p = subprocess.run([sys.executable, "-c", CHILD, str(renders), "png" if png else "all", *over], cwd=tree, env=env,
                           capture_output=True, text=True, timeout=3600)
    if p.returncode != 0:
        raise SystemExit(f"{tree}: {(p.stderr.strip().splitlines() or ['?'])[-1]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", required=True, help="the earlier commit")
    ap.add_argument("--repeats", type=int, default=5, help="alternating pairs of child processes")
    ap.add_argument("--renders", type=int, default=8, help="timed renders in each child (the least counts)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--png", action="store_true",
                    help="keep what a PNG keeps (colour and alpha), as peers.py's renders do; default: every output")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size, "--size")
    over = [f"image.width={w}", f"image.height={h}", *a.set]
    rev = short_commit(a.rev)
    if rev is None:
        ap.error(f"--rev: {a.rev!r} is no commit of this repository")
    runs: dict[str, list[dict]] = {"earlier": [], "checkout": []}
    with earlier_tree(rev) as tree:
        for k in range(a.repeats):
            order = [("earlier", tree), ("checkout", ROOT)]
            for name, path in order if k % 2 == 0 else order[::-1]:
                runs[name].append(child(path, a.renders, over, a.png))
    names = sorted({k for r in runs["checkout"] for k in r["kernels"]},
                   key=lambda k: -statistics.median(r["kernels"].get(k, 0) for r in runs["checkout"]))

    def med(name: str, key: str) -> float:
        vals = [r[key] for r in runs[name]] if key in ("cpu", "first") else [r["kernels"].get(key, 0.0) for r in runs[name]]
        return statistics.median(vals)
    rows = ["| measure | earlier s | checkout s | checkout / earlier |", "|---|---|---|---|"]
    labels = {"cpu": "CPU-s of a render", "first": "first render from empty program caches, wall s"}
    for key in names + ["cpu", "first"]:
        e, c = med("earlier", key), med("checkout", key)
        label = labels.get(key, f"kernel {key}")
        rows.append(f"| {label} | {e:.4f} | {c:.4f} | {c / e:.2f} |" if e > 0 else f"| {label} | - | {c:.4f} | - |")
    table = "\n".join(rows)
    print(table)
    scene = f", the default scene with {', '.join(a.set)}" if a.set else ", the default scene"
    scene += ", keeping a PNG's outputs" if a.png else ""
    section = (f"\n## {utc_now()}, {a.size}{scene}, {runs['checkout'][0]['device']}: commit {git_commit()} "
               f"against {rev}, medians of {a.repeats} alternating pairs (each the least of {a.renders} renders)\n\n"
               f"{table}\n")
    append_run(a.out / "commit_ratio.md", "# This checkout against an earlier commit\n\nWritten by "
               "`python benchmarks/speed/commit_ratio.py` (its docstring says what is measured).\n", section)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
