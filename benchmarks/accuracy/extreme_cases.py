"""The extreme-case catalogue in float32 against float64.

For every case of ``pyjulia4d.catalogue`` and both march methods it renders the
scene with the single- and the double-precision kernels and records: the fraction
of pixels whose status (miss / hit / capped) differs; the depth error of float32
against float64 over pixels both hit (median and max, scene units, and the max in
pixels' worth of depth: error / (depth * 2 tan(fov/2) / height)); the median normal
angle between them; the kernel time of each and their ratio (double / single; the
median of --repeats runs after a warm-up render, so no build is timed); the guard
counts of each render; and the NaN/inf leaks (must be 0: non-finite colour or
normal, NaN depth, non-finite depth or position on a hit).  A case is "ok" when it
is within its stated tolerance, "LIMIT" when it is a documented precision limit
(the measured error is the record), "FAIL" otherwise.

Writes benchmarks/results/extreme_cases.md and extreme_cases.csv.

    python benchmarks/accuracy/extreme_cases.py               # full run (catalogue sizes x --scale 2)
    python benchmarks/accuracy/extreme_cases.py --scale 1 --repeats 1
"""
from __future__ import annotations

import csv
import datetime as _dt
import math
import platform
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser  # noqa: E402
from pyjulia4d.measure import catalogue as cat  # noqa: E402
from pyjulia4d.opencl.executor import render  # noqa: E402
from pyjulia4d.pipeline.codes import STATUS_HIT  # noqa: E402

from benchmarks.accuracy.error_vs_time import git_head  # noqa: E402  (same folder: benchmarks/)

GUARDS = ("ulp_step", "normal_fallback", "jacobian_tiny", "eye_hit", "shell_miss")


def leaks(r) -> int:
    hit = r.status == STATUS_HIT
    return int((~np.isfinite(r.color)).sum() + (~np.isfinite(r.normal)).sum()
               + np.isnan(r.depth).sum() + (~np.isfinite(r.depth[hit])).sum()
               + (~np.isfinite(r.position[hit])).sum() + np.isneginf(r.depth).sum())


def scaled(case: cat.Case, method: str, precision: str, scale: int):
    w, h = case.size
    return cat.scene(case, method, precision).with_overrides(
        [f"image.width={w * scale}", f"image.height={h * scale}"])


def run(case, method, precision, scale, repeats):
    s = scaled(case, method, precision, scale)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        r = render(s)                       # warm-up: build and first launch
        times = []
        for _ in range(repeats):
            r = render(s)
            times.append(r.kernel_seconds)
    return s, r, float(np.median(times))


def measure(case, method, scale, repeats) -> dict:
    s, a, ta = run(case, method, "single", scale, repeats)
    _, b, tb = run(case, method, "double", scale, repeats)
    both = (a.status == STATUS_HIT) & (b.status == STATUS_HIT)
    err = np.abs(a.depth[both].astype(float) - b.depth[both].astype(float))
    mism = float(np.mean(a.status != b.status))
    pix = b.depth[both].astype(float) * 2 * math.tan(math.radians(s.camera.fov) / 2) / s.image.height
    ang = np.degrees(np.arccos(np.clip(np.sum(a.normal[both] * b.normal[both], -1), -1, 1)))
    tol, stol = case.depth_tol_for(method), case.status_tol_for(method)
    within = (mism <= stol and (err.size == 0 or (np.median(err) <= tol and np.mean(err > tol) <= stol))
              and both.sum() >= case.both_hit_min)
    verdict = "LIMIT" if case.limit else ("ok" if within else "FAIL")
    return {
        "case": case.name, "method": method,
        "size": f"{s.image.width}x{s.image.height}",
        "hits32": int((a.status == STATUS_HIT).sum()), "hits64": int((b.status == STATUS_HIT).sum()),
        "capped32": a.capped, "capped64": b.capped,
        "status_mismatch": mism,
        "depth_err_median": float(np.median(err)) if err.size else float("nan"),
        "depth_err_max": float(err.max()) if err.size else float("nan"),
        "depth_err_max_pixels": (float((err[pix > 0] / pix[pix > 0]).max())
                                 if (pix > 0).any() else float("nan")),
        "normal_deg_median": float(np.median(ang)) if ang.size else float("nan"),
        "t32_s": ta, "t64_s": tb, "ratio_64_32": tb / ta if ta > 0 else float("nan"),
        "guards32": " ".join(f"{k}={a.guards[k]}" for k in GUARDS if a.guards[k]) or "-",
        "guards64": " ".join(f"{k}={b.guards[k]}" for k in GUARDS if b.guards[k]) or "-",
        "nan_inf32": leaks(a), "nan_inf64": leaks(b),
        "status_tol": stol, "depth_tol": tol,
        "verdict": verdict, "limit": case.limit,
    }


def fmt(x, spec=".2e"):
    if isinstance(x, float):
        return "-" if math.isnan(x) else format(x, spec)
    return str(x)


def markdown(rows, args) -> str:
    head = ["case", "method", "size", "hits 32/64", "capped 32/64", "status mismatch",
            "depth err median", "depth err max", "max err (px)", "normal deg (median)",
            "t64/t32", "guards float32", "guards float64", "NaN/inf 32/64", "tolerance", "verdict"]
    out = [
        "# Extreme cases: float32 against float64",
        "",
        f"Generated by `benchmarks/accuracy/extreme_cases.py --scale {args.scale} --repeats {args.repeats}` "
        f"on {_dt.datetime.now(_dt.timezone.utc):%Y-%m-%d %H:%M} UTC, {rows[0]['device']} "
        f"({platform.machine()}), commit `{git_head()}`.  Catalogue: `pyjulia4d/measure/catalogue.py`; the float64 render is the "
        "double-precision kernels (held to the numpy reference by tests/accuracy/test_extreme.py).",
        "",
        "Status mismatch: fraction of pixels whose miss/hit/capped status differs.  Depth error: "
        "|t32 - t64| over pixels both hit (scene units); max err (px): in pixels' worth of depth.  "
        "t64/t32: kernel-time ratio double/single (median of repeats, after a warm-up render; "
        "tiny images, so the ratio is noisy).  Tolerance: status mismatch / depth (median; at most "
        "the status fraction of pixels above).  LIMIT: a documented float32 precision limit.",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    for r in rows:
        out.append("| " + " | ".join([
            r["case"], r["method"], r["size"], f"{r['hits32']}/{r['hits64']}",
            f"{r['capped32']}/{r['capped64']}", f"{r['status_mismatch']:.3f}",
            fmt(r["depth_err_median"]), fmt(r["depth_err_max"]), fmt(r["depth_err_max_pixels"], ".2g"),
            fmt(r["normal_deg_median"], ".3g"), fmt(r["ratio_64_32"], ".2f"),
            r["guards32"], r["guards64"], f"{r['nan_inf32']}/{r['nan_inf64']}",
            f"{r['status_tol']:g} / {r['depth_tol']:g}", r["verdict"]]) + " |")
    lim = [c for c in cat.catalogue() if c.limit]
    out += ["", "## Documented precision limits", ""]
    for c in lim:
        rs = [r for r in rows if r["case"] == c.name]
        meas = "; ".join(f"{r['method']}: status mismatch {r['status_mismatch']:.3f}, depth error "
                         f"median {fmt(r['depth_err_median'])} max {fmt(r['depth_err_max'])}"
                         for r in rs)
        out.append(f"- **{c.name}**: {c.limit}.  Measured: {meas}.")
    out += ["", "## Cases", ""]
    for c in cat.catalogue():
        out.append(f"- **{c.name}** (`{' '.join(c.overrides)[:160]}`): stresses {c.stresses}. "
                   f"Expected: {c.expected}.")
    return "\n".join(out) + "\n"


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", type=int, default=2, help="multiply the catalogue's image sizes")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", nargs="*", help="case names")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args(argv)
    rows = []
    for case in cat.catalogue():
        if args.only and case.name not in args.only:
            continue
        for method in case.methods:
            r = measure(case, method, args.scale, args.repeats)
            from pyjulia4d.opencl.devices import select_device
            r["device"] = select_device(None).name.strip()
            rows.append(r)
            print(f"{r['case']:20s} {method:5s} mism={r['status_mismatch']:.3f} "
                  f"dz med={fmt(r['depth_err_median'])} max={fmt(r['depth_err_max'])} "
                  f"t64/t32={fmt(r['ratio_64_32'], '.2f')} g32=[{r['guards32']}] "
                  f"nan/inf={r['nan_inf32']}/{r['nan_inf64']} {r['verdict']}", flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "extreme_cases.csv", "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(rows[0]))
        wr.writeheader()
        wr.writerows(rows)
    (args.out / "extreme_cases.md").write_text(markdown(rows, args))
    bad = [r for r in rows if r["nan_inf32"] or r["nan_inf64"] or r["verdict"] == "FAIL"]
    print(f"wrote {args.out / 'extreme_cases.md'}; {len(bad)} failing rows")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
