"""The explorer's latency, measured by driving its page in a real browser (headless Chromium
through selenium): how soon the first picture comes, how soon a new one follows a control's
change, and how many previews arrive per second while a slider is dragged.

    python benchmarks/speed/explore_latency.py [--changes 10] [--drag-seconds 3] [--set KEY=VALUE ...]

- ``command -> first picture``: from starting ``pyjulia4d explore`` to the first picture in a
  page opened as soon as the server listens, twice: with empty program caches (pyjulia4d's,
  PoCL's and pyopencl's: every kernel is built, the packet width probed) and then with the
  caches that run filled.  The server frames the scene and builds its kernels before it
  listens.
- ``page open -> first picture``: from the page's navigation start (the browser's own clock)
  to its first picture, in a second page opened on the same server.
- ``change -> next picture`` and ``change -> final picture``: a control's value set and its
  change event dispatched in the page, to the next picture and to the picture of the scene at
  its full size (the median over ``--changes`` changes of fractal.c[1]).
- ``previews per second``: the slider of fractal.c[1] moved every 16 ms (an input event per
  display frame, as a drag makes them) for ``--drag-seconds``; pictures that arrived, per second.
- ``change -> path-traced view of N paths`` (``--rest-batches K``, for a scene set to
  shading.integrator = "path"): after a change the explorer shows the direct-lit preview,
  then refines the picture at rest in batches of paths (4, then doubling: 4, 8, 16, ... paths
  per pixel in all), each shown denoised where Open Image Denoise is installed; the time from
  the change to each of the first K batches (median over ``--changes`` changes, at least 1).

Times are the browser's (performance.now()), so the WebSocket, the PNG decoding and the page's
own work are included.  Writes benchmarks/results/explore_latency.md (a section per run, with
commit, device and date).  The targets are those the explorer was built to: first picture at most
3 s after the page opens, a new picture at most 1 s after a change (0.3 s the aim), at least 5
previews per second on the default scene.
"""
from __future__ import annotations

import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.runlog import append_run, git_commit, utc_now  # noqa: E402
from benchmarks.lib.args import Parser  # noqa: E402

from pyjulia4d.app.explore.drive import headless_chromium, start_server, stop_server  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results" / "explore_latency.md"

# installed before each page's own scripts run: every picture's arrival on the browser's
# clock (performance.now(): milliseconds from the page's navigation start)
EARLY = """
window.__arrivals = [];
// each picture: its time, its stage, and the paths per pixel its facts state (a path-traced batch's; '' else)
const pathsOf = () => {
    const f = document.getElementById('facts');
    const m = f ? /paths per pixel\\s+([0-9-]+)/.exec(f.innerText) : null;
    return m ? m[1] : '';
};
new MutationObserver((records) => {
    for (const r of records) if (r.target.id === 'view') window.__arrivals.push([performance.now(), r.target.dataset.stage, pathsOf()]);
}).observe(document, {subtree: true, attributes: true, attributeFilter: ['data-count']});
"""

# a change of c[1]'s field, as a user types it: the start of CHANGE and REST (value: arguments[0])
SET_C = """
const done = arguments[arguments.length - 1];
const n0 = window.__arrivals.length;
const field = document.getElementsByName('fractal.c[1]')[0];
const t0 = performance.now();
field.value = arguments[0];
field.dispatchEvent(new Event('change', {bubbles: true}));
"""

CHANGE = SET_C + """
const poll = () => {
    const got = window.__arrivals.slice(n0);
    const fin = got.find(a => a[1] === 'final');
    if (fin) done([got[0][0] - t0, fin[0] - t0]);
    else if (performance.now() - t0 > 30000) done(null);
    else setTimeout(poll, 2);
};
poll();
"""

DRAG = """
const [seconds, done] = [arguments[0], arguments[arguments.length - 1]];
const slider = document.querySelector('input[type=range][data-for="fractal.c[1]"]');
const n0 = window.__arrivals.length;
const t0 = performance.now();
const tick = setInterval(() => {
    const t = (performance.now() - t0) / 1000;
    slider.value = (0.6 + 0.25 * Math.sin(2 * t)).toFixed(4);
    slider.dispatchEvent(new Event('input', {bubbles: true}));
    if (t >= seconds) {
        clearInterval(tick);
        const got = window.__arrivals.slice(n0).filter(a => a[0] - t0 <= seconds * 1000);
        slider.dispatchEvent(new Event('change', {bubbles: true}));
        done([got.length, got.map(a => a[1])]);
    }
}, 16);
"""


REST = SET_C + """
const batches = arguments[1];
const poll = () => {
    const got = window.__arrivals.slice(n0).filter(a => a[2] !== '');   // the path-traced batches
    if (got.length >= batches || got.some(a => a[1] === 'final'))
        done(got.slice(0, batches).map(a => [a[0] - t0, a[2]]));
    else if (performance.now() - t0 > 120000) done(got.map(a => [a[0] - t0, a[2]]));
    else setTimeout(poll, 2);
};
poll();
"""


def browser():
    try:
        d = headless_chromium()
    except RuntimeError as e:
        sys.exit(f"explore_latency: {e}")
    d.set_script_timeout(120)
    d.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": EARLY})
    return d


def launch(args: list[str], env: dict, d) -> tuple[subprocess.Popen, str, float, float]:
    """Start the server, open its page as soon as it listens: (process, url, seconds to
    listening, seconds to the first picture), both from the command's start."""
    from selenium.webdriver.support.ui import WebDriverWait

    t0 = time.perf_counter()
    try:
        proc, url = start_server(args, env, timeout=300)
    except RuntimeError as e:
        sys.exit(f"explore_latency: {e}")
    t_listen = time.perf_counter() - t0
    d.get(url)
    WebDriverWait(d, 120, poll_frequency=0.005).until(
        lambda d: d.find_element("id", "view").get_attribute("data-count"))
    return proc, url, t_listen, time.perf_counter() - t0


def run(changes: int, drag_seconds: float, overrides: list[str], device: str | None,
        screenshot: Path | None = None, cold: bool = True, rest_batches: int = 0) -> dict:
    from selenium.webdriver.support.ui import WebDriverWait

    tmp = Path(tempfile.mkdtemp(prefix="explore-latency-"))
    env = dict(os.environ, PYJULIA4D_CACHE=str(tmp / "cache"), POCL_CACHE_DIR=str(tmp / "pocl"),
               XDG_CACHE_HOME=str(tmp / "xdg"))
    d = browser()
    args = ["--folder", str(tmp)]
    args += [a for o in overrides for a in ("--set", o)] + (["--device", device] if device else [])
    proc = None
    try:
        cold_listen = cold_first = None
        if cold:
            proc, _, cold_listen, cold_first = launch(args, env, d)   # empty caches: every kernel built
            stop_server(proc)
        else:   # the caches as they are
            env = None
        proc, url, warm_listen, warm_first = launch(args, env, d)   # the caches the first run filled
        # a second page on the running server: its first picture on the browser's own clock
        d.get("about:blank")
        d.get(url)
        WebDriverWait(d, 120).until(lambda d: d.find_element("id", "view").get_attribute("data-stage") == "final")
        page_ms = d.execute_script("return window.__arrivals[0][0]")
        facts = d.find_element("id", "facts").text
        device_name = facts.split("device\n")[-1].strip()
        size = facts.split("size\n")[-1].split("\n")[0]
        nexts, finals, rests = [], [], []
        for k in range(changes if not rest_batches else 0):
            got = d.execute_async_script(CHANGE, f"{0.55 + 0.02 * (k % 10):.3f}")
            if got:
                nexts.append(got[0] / 1000)
                finals.append(got[1] / 1000)
        for k in range(max(changes, 1) if rest_batches else 0):   # a path-traced scene: its batches at rest
            rests.append([(t / 1000, paths) for t, paths in d.execute_async_script(
                REST, f"{0.55 + 0.02 * (k % 10):.3f}", rest_batches)])
        frames, stages = d.execute_async_script(DRAG, drag_seconds)
        if screenshot is not None:   # the page at rest after the drag
            WebDriverWait(d, 120).until(
                lambda d: d.find_element("id", "view").get_attribute("data-stage") == "final")
            d.save_screenshot(str(screenshot))
    finally:
        d.quit()
        if proc is not None:
            stop_server(proc)
        shutil.rmtree(tmp, ignore_errors=True)
    return {"cold_listen": cold_listen, "cold_first": cold_first, "warm_listen": warm_listen,
            "warm_first": warm_first, "page_ms": page_ms, "next": nexts, "final": finals,
            "previews": frames / drag_seconds, "stages": sorted(set(stages)), "device": device_name, "size": size,
            "rests": rests}


def seconds(x: float | None) -> str:
    return "-" if x is None else f"{x:.2f} s"


def table(r: dict, changes: int, drag_seconds: float) -> str:
    med = statistics.median
    rows = [
        ("command -> server listening, empty caches (every kernel built)", seconds(r["cold_listen"]), ""),
        ("command -> first picture in the page, empty caches", seconds(r["cold_first"]), ""),
        ("command -> server listening, caches filled", f"{r['warm_listen']:.2f} s", ""),
        ("command -> first picture in the page, caches filled", f"{r['warm_first']:.2f} s", ""),
        ("page open -> first picture (warm server)", f"{r['page_ms'] / 1000:.2f} s", "at most 3 s"),
        (f"change -> next picture (median of {len(r['next'])})", f"{med(r['next']):.3f} s" if r["next"] else "-",
         "at most 1 s (0.3 s the aim)"),
        ("change -> final picture (median)", f"{med(r['final']):.3f} s" if r["final"] else "-", ""),
        (f"previews per second while dragging ({drag_seconds:g} s)", f"{r['previews']:.1f}", "at least 5"),
    ]
    if r["rests"]:   # a path-traced scene: the change's own rows are its batches at rest
        rows = [x for x in rows if not x[0].startswith("change")]
        for k in range(max(len(x) for x in r["rests"])):
            got = [x[k][0] for x in r["rests"] if len(x) > k]
            paths = r["rests"][0][k][1]
            rows.append((f"change -> path-traced view of {paths} paths per pixel (median of {len(got)})",
                         f"{med(got):.2f} s", "a clean denoised view within 2 s at rest" if k == 0 else ""))
    lines = ["| measure | value | target |", "|---|---|---|"] + [f"| {a} | {b} | {c} |" for a, b, c in rows]
    return "\n".join(lines) + f"\n\nScene size {r['size']}, device {r['device']}; stages seen while dragging: " \
                              f"{', '.join(r['stages']) or 'none'}.\n"


def main(argv=None) -> int:
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--changes", type=int, default=10)
    ap.add_argument("--drag-seconds", type=float, default=3.0)
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--device", default=None)
    ap.add_argument("--out", type=Path, default=RESULTS)
    ap.add_argument("--screenshot", type=Path, default=None, metavar="PNG",
                    help="also save the page at rest after the drag (docs/explore.md's picture)")
    ap.add_argument("--rest-batches", type=int, default=0, metavar="K",
                    help="a path-traced scene (--set shading.integrator=path): time the first K batches of "
                         "paths after each change instead of its final picture")
    ap.add_argument("--keep-caches", action="store_true",
                    help="skip the start with empty caches: one start, with the caches as they are")
    a = ap.parse_args(argv)
    r = run(a.changes, a.drag_seconds, a.overrides, a.device, a.screenshot, cold=not a.keep_caches,
            rest_batches=a.rest_batches)
    text = table(r, a.changes, a.drag_seconds)
    print(text)
    scene = f" with {' '.join(a.overrides)}" if a.overrides else " (the default scene)"
    append_run(a.out, "# The explorer's latency in a real browser (benchmarks/speed/explore_latency.py)\n",
               f"\n## {utc_now()}, commit {git_commit()}{scene}\n\n"
               f"`python benchmarks/speed/explore_latency.py --changes {a.changes} --drag-seconds {a.drag_seconds:g}"
               f"{' --keep-caches' if a.keep_caches else ''}"
               f"{f' --rest-batches {a.rest_batches}' if a.rest_batches else ''}"
               f"{''.join(' --set ' + o for o in a.overrides)}`\n\n{text}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
