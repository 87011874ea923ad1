"""The package's shape holds: no import circles (late imports included), no private name
imported across modules, no module past 500 lines, every package in setup.cfg, the float64 reference importable
without OpenCL, and a registry whose every entry names a kernel piece and a twin that
exist (and every piece and twin has an entry)."""
from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import pyjulia4d
from pyjulia4d.fractal import registry
from pyjulia4d.resources import kernel_dir

PKG = Path(pyjulia4d.__file__).resolve().parent
MOST_LINES = 500   # a module past this is doing more than one thing


def _modules() -> dict[str, Path]:
    out = {}
    for p in PKG.rglob("*.py"):
        parts = list(p.relative_to(PKG.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


MODULES = _modules()


def _imports(name: str, path: Path) -> list[tuple[str, str]]:
    """(imported module, imported name or "") for every import in the file, late ones too."""
    tree = ast.parse(path.read_text())
    pkg = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for a in node.names:
                out.append((target, a.name))
        elif isinstance(node, ast.Import):
            out.extend((a.name, "") for a in node.names)
    return [(t, n) for t, n in out if t.split(".")[0] == "pyjulia4d"]


def _graph() -> dict[str, set[str]]:
    g: dict[str, set[str]] = {m: set() for m in MODULES}
    for m, p in MODULES.items():
        for target, name in _imports(m, p):
            dep = f"{target}.{name}" if f"{target}.{name}" in MODULES else target
            if dep in MODULES and dep != m:
                g[m].add(dep)
    return g


def test_no_import_circles() -> None:
    """Tarjan's strongly connected components of the import graph: all of size one.  The one
    edge left out is a module's import from a package that contains it (``from pyjulia4d
    import __version__`` in app/cli.py): Python has run that package's __init__ first anyway."""
    g = _graph()
    for m in g:
        g[m] = {d for d in g[m] if not m.startswith(d + ".")}
    index, low, stack, on, cycles = {}, {}, [], set(), []
    counter = [0]
    sys.setrecursionlimit(max(10000, sys.getrecursionlimit()))

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in g:
        if v not in index:
            visit(v)
    assert cycles == []


def test_no_private_names_across_modules() -> None:
    bad = [(m, t, n) for m, p in MODULES.items() for t, n in _imports(m, p)
           if n.startswith("_") and not n.startswith("__")]
    assert bad == []


def test_modules_stay_small() -> None:
    sizes = {m: len(p.read_text().splitlines()) for m, p in MODULES.items()}
    assert {m: n for m, n in sizes.items() if n > MOST_LINES} == {}


def test_setup_cfg_ships_every_package() -> None:
    """A non-editable install (what .ci/run and users get) holds only the packages setup.cfg
    lists: every folder of pyjulia4d/ with an __init__.py must be among them."""
    import configparser
    cfg = configparser.ConfigParser()
    cfg.read(PKG.parent / "setup.cfg")
    listed = set(cfg["options"]["packages"].split())
    on_disk = {".".join(p.parent.relative_to(PKG.parent).parts) for p in PKG.rglob("__init__.py")}
    assert on_disk - listed == set()
    assert "pyjulia4d.kernels" in listed


def test_reference_imports_without_opencl() -> None:
    """pyjulia4d.reference is a second executor of the same plan: no pyopencl anywhere in
    its imports (a blocked pyopencl fails any import of it)."""
    code = ("import sys; sys.modules['pyopencl'] = None\n"
            "import pyjulia4d.reference\n"
            "from pyjulia4d import Scene\n"
            "r = pyjulia4d.reference.render(Scene.default().with_overrides(['image.width=6', 'image.height=4']))\n"
            "print(r.hit_fraction > 0)")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(PKG.parent), os.environ.get("PYTHONPATH")])))
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "True"


def test_registry_names_pieces_and_twins_that_exist() -> None:
    import importlib

    kd = kernel_dir()
    for table in (registry.ALGEBRAS_TABLE, registry.FUNCTIONS_TABLE):
        for entry in table.values():
            assert (kd / f"{entry.piece}.cl").is_file(), entry
            importlib.import_module(entry.twin)
    for kind in registry.KINDS_TABLE.values():
        if kind.piece:
            assert (kd / f"{kind.piece}.cl").is_file(), kind
        # a kind plugs in as a function does: its host hooks and its twin's interface
        hooks = registry.kind_hooks(kind.name)
        assert all(callable(getattr(hooks, h, None)) for h in ("defines", "set_radius", "check")), kind
        if kind.twin:
            twin = importlib.import_module(kind.twin)
            assert all(callable(getattr(twin, h, None)) for h in ("inside", "level", "normal")), kind
    # every piece of algebra/ and function/ has its entry (power.cl and complex.cl are shared)
    assert {p.stem for p in (kd / "function").glob("*.cl")} == set(registry.FUNCTIONS_TABLE)
    assert {p.stem for p in (kd / "algebra").glob("*.cl")} - {"power", "complex"} == set(registry.ALGEBRAS_TABLE)


@pytest.mark.parametrize("name", list(registry.FUNCTIONS_TABLE))
def test_degree_is_the_pieces_own(name: str) -> None:
    """A polynomial function's degree is stated twice by nature - in its piece, whose code is
    that polynomial (#define FUNC_POWER), and in the registry; they must agree."""
    text = (kernel_dir() / "function" / f"{name}.cl").read_text()
    m = re.search(r"^#define FUNC_POWER (\d+)", text, re.M)
    assert (int(m.group(1)) if m else None) == registry.FUNCTIONS_TABLE[name].degree


def _kernels() -> dict[str, tuple[str, str]]:
    """Every kernel in kernels/: name -> (its declaration's qualifier, its body)."""
    out = {}
    for path in sorted(kernel_dir().rglob("*.cl")):
        text = path.read_text()
        heads = list(re.finditer(r"^(__kernel|PACKET_KERNEL) void (\w+)\(", text, re.M))
        for i, m in enumerate(heads):
            end = heads[i + 1].start() if i + 1 < len(heads) else len(text)
            out[m.group(2)] = (m.group(1), text[m.end():end])
    return out


def test_packet_kernels_say_so() -> None:
    """A kernel whose work-items each take LANES rays or blocks (common/lanes.cl) is declared
    PACKET_KERNEL, whose vec_type_hint keeps Intel's compiler from vectorising it a second
    time (half its build); any other keeps __kernel, which the runtime vectorises."""
    kernels = _kernels()
    assert {"march", "light_terms", "normals_jacobian", "cone_starts", "shade"} <= set(kernels)
    for name, (qualifier, body) in kernels.items():
        packet = any(s in body for s in ("block_lanes(get_global_id(0)", "packet_lanes(get_global_id(0)",
                                         "get_global_id(0) * LANES"))
        assert qualifier == ("PACKET_KERNEL" if packet else "__kernel"), name


# The executors: after planning they read the plan alone (pipeline/plan.py).  Each entry is a
# module and the functions of it that execute ("*": all of it); ``plan.scene`` may only ride
# on to the result (RenderResult's scene=), as metadata.
EXECUTORS = {
    "pyjulia4d.opencl.passes": "*",
    "pyjulia4d.opencl.runner": "*",
    "pyjulia4d.pipeline.calibrate": "*",
    "pyjulia4d.reference.executor": {"execute"},
    "pyjulia4d.reference.march": "*",
    "pyjulia4d.reference.cone": "*",
    "pyjulia4d.reference.normals": "*",
    "pyjulia4d.reference.shade": "*",
    "pyjulia4d.reference.rays": "*",
}


def _scene_reads(tree: ast.AST) -> list[int]:
    """Lines where ``tree`` reads a scene: the name ``scene`` or an attribute ``.scene``, except
    as the value of a ``scene=`` keyword (the result's metadata)."""
    passed = {id(k.value) for k in ast.walk(tree) if isinstance(k, ast.keyword) and k.arg == "scene"}
    return [n.lineno for n in ast.walk(tree)
            if id(n) not in passed and ((isinstance(n, ast.Attribute) and n.attr == "scene")
                                        or (isinstance(n, ast.Name) and n.id == "scene"))]


def test_executors_read_no_scene() -> None:
    """The OpenCL executor's passes and runner, calibration and the float64 executor take every
    number from the plan's records; a scene read there would be a second source."""
    bad = {}
    for mod, funcs in EXECUTORS.items():
        tree = ast.parse(MODULES[mod].read_text())
        nodes = [tree] if funcs == "*" else [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name in funcs]
        assert funcs == "*" or len(nodes) == len(funcs), mod
        lines = [ln for node in nodes for ln in _scene_reads(node)]
        if lines:
            bad[mod] = lines
    assert bad == {}


def test_executors_see_a_scene_read() -> None:
    """The check above finds what it looks for."""
    assert _scene_reads(ast.parse("w = plan.scene.image.width\nr = RenderResult(scene=plan.scene)")) == [1]


# Where the march is resolved from a scene: planning (the registry, the plan and what it
# calls: kernel configurations, the work bound, the bounding ball) and the render's entry,
# which picks the packet width before the plan.  Everything after reads plan.march.method.
PLANNING = {"pyjulia4d.fractal.registry", "pyjulia4d.pipeline.plan", "pyjulia4d.pipeline.records", "pyjulia4d.pipeline.kernel_config",
            "pyjulia4d.pipeline.workload", "pyjulia4d.geometry.camera", "pyjulia4d.opencl.executor"}


def test_march_method_is_resolved_in_planning_only() -> None:
    calls = {m for m, p in MODULES.items() if re.search(r"\bmarch_method\(", p.read_text())}
    assert calls - PLANNING == set()


def test_code_cites_papers_not_source_files() -> None:
    """Code names a paper by its authors, year and section (docs/bibliography.md keys the
    source files' names to them), never by a file name a reader cannot follow; and comments
    say why, not when (no issue numbers)."""
    roots = [PKG, kernel_dir(), PKG.parent / "tests", PKG.parent / "benchmarks"]
    bad = []
    for root in roots:
        for p in list(root.rglob("*.py")) + list(root.rglob("*.cl")) + list(root.rglob("*.sh")):
            if "results" in p.parts:
                continue
            text = p.read_text(encoding="utf-8")
            if re.search(r"\b[Ss]eeds? 00\d|\b00\d_[0-9a-f]{16}\.txt|\b[Ii]ssue #?\d+", text):
                bad.append(p.name)
    assert bad == []


PATH_CITED = re.compile(r"\b((?:pyjulia4d|kernels|benchmarks|tests|docs)/[\w./-]+\.(?:py|cl|md|sh))")
PACKAGE_PATH = re.compile(r"(?<![\w/])((?:app|fractal|geometry|interop|measure|opencl|pipeline|reference|scene)/[\w/]+\.py)")
PIECE_PATH = re.compile(r"(?<![\w/])((?:algebra|common|enclose|function|kind|march|mesh|normals|shade)/[\w/]+\.cl)")


def test_cited_paths_exist() -> None:
    """Every file a comment, docstring or page names by its path is there: from the top
    (pyjulia4d/..., kernels/..., docs/...), within the package (opencl/runner.py) or within
    kernels/ (march/march.cl)."""
    top = PKG.parent
    texts = [p for p in list(PKG.rglob("*.py")) + list(kernel_dir().rglob("*.cl")) + list((top / "tests").rglob("*.py"))
             + list((top / "benchmarks").rglob("*.py")) + list((top / "docs").glob("*.md")) + [top / "README.md"]]
    dead = set()
    for p in texts:
        text = p.read_text(encoding="utf-8")
        dead |= {(p.name, m) for m in PATH_CITED.findall(text) if not (top / m).exists()}
        dead |= {(p.name, m) for m in PACKAGE_PATH.findall(text) if not (PKG / m).exists() and not (top / m).exists()}
        dead |= {(p.name, m) for m in PIECE_PATH.findall(text) if not (kernel_dir() / m).exists()}
    assert dead == set()


def test_no_branch_on_a_kinds_name() -> None:
    """A kind is an entry, its piece, its host hooks (fractal/kinds/) and its twin
    (reference/kind/): nothing else compares the scene's kind with another kind's name."""
    other = "|".join(k for k in registry.KINDS_TABLE if k != "julia")
    pattern = re.compile(rf"""kind\s*(?:==|!=)\s*["'](?:{other})["']|["'](?:{other})["']\s*(?:==|!=)\s*\w*kind""")
    bad = [m for m, p in MODULES.items() if not m.startswith(("pyjulia4d.fractal.kinds", "pyjulia4d.reference.kind"))
           and pattern.search(p.read_text())]
    assert bad == []
    # the kernels likewise: a shared piece takes a kind's hooks (KIND_ORBIT_START, KIND_JVP_START,
    # KIND_NORMAL, defined by kernels/kind/<kind>.cl), never the kind's own switch
    switch = re.compile(r"#\s*if.*\bKIND_(?:" + "|".join(k.upper() for k in registry.KINDS_TABLE) + r")\b")
    own = {f"kind/{k}" for k in registry.KINDS_TABLE} | {f"enclose/{k}" for k in registry.KINDS_TABLE}
    bad = [str(p.relative_to(kernel_dir())) for p in kernel_dir().rglob("*.cl")
           if p.relative_to(kernel_dir()).with_suffix("").as_posix() not in own and switch.search(p.read_text())]
    assert bad == []
