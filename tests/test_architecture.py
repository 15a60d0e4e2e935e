"""The shape of the code base: no import cycles, one time loop, no global
matplotlib backend switch inside the library."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("lagice", "forcing", "thermo")


def _modules():
    """{module name: path} of every module of the installed packages."""
    out = {}
    for pkg in PACKAGES:
        for p in (ROOT / pkg).rglob("*.py"):
            rel = p.relative_to(ROOT).with_suffix("")
            parts = list(rel.parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = p
    return out


def _imports(name: str, path: Path, modules: dict) -> set:
    """Modules of ours that ``name`` imports anywhere (module level or inside functions)."""
    tree = ast.parse(path.read_text())
    is_pkg = path.name == "__init__.py"
    base = name.split(".") if is_pkg else name.split(".")[:-1]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                root = base[: len(base) - (node.level - 1)]
                mod = ".".join(root + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            targets = [mod] + [f"{mod}.{a.name}" for a in node.names]
        else:
            continue
        for t in targets:
            # the deepest module of ours that the target names (a.b.c -> a.b.c or a.b or a)
            parts = t.split(".")
            for k in range(len(parts), 0, -1):
                cand = ".".join(parts[:k])
                if cand in modules:
                    if cand != name:
                        found.add(cand)
                    break
    return found


def test_no_import_cycles():
    modules = _modules()
    graph = {m: _imports(m, p, modules) for m, p in modules.items()}
    # a package's __init__ re-exporting its submodules is not a cycle with them; a
    # submodule importing its own package __init__ (``from . import x``) is
    for m in graph:
        graph[m] = {d for d in graph[m] if not (d.startswith(m + ".") and modules[m].name == "__init__.py")}
    index, low, stack, on, cycles = {}, {}, [], set(), []
    counter = [0]

    def strongconnect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                strongconnect(w)
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

    import sys

    sys.setrecursionlimit(10000)
    for v in graph:
        if v not in index:
            strongconnect(v)
    assert not cycles, f"import cycles: {cycles}"


def _step_calls_in_loops(path: Path):
    """(line, function) of every ``x.step(...)`` call inside a for/while loop."""
    tree = ast.parse(path.read_text())
    hits = []

    def visit(node, func, in_loop):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            func, in_loop = node.name, False
        if isinstance(node, (ast.For, ast.While)):
            in_loop = True
        if (in_loop and isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                and node.func.attr == "step"):
            hits.append((node.lineno, func))
        for child in ast.iter_child_nodes(node):
            visit(child, func, in_loop)

    visit(tree, None, False)
    return hits


def test_one_time_loop():
    """No ``.step(...)`` in a loop anywhere in the library or the benchmarks except
    Simulation.run: every run goes through Model/Simulation."""
    offenders = []
    for folder in ("lagice", "forcing", "thermo", "benchmarks"):
        for p in (ROOT / folder).rglob("*.py"):
            for line, func in _step_calls_in_loops(p):
                if p.name == "simulation.py" and func == "run":
                    continue
                offenders.append(f"{p.relative_to(ROOT)}:{line} in {func}()")
    assert not offenders, "time loops outside Simulation.run: " + ", ".join(offenders)


def test_library_never_switches_the_matplotlib_backend():
    for pkg in PACKAGES:
        for p in (ROOT / pkg).rglob("*.py"):
            assert "matplotlib.use(" not in p.read_text(), p


def test_tree_passes_ruff():
    """The lint rules of pyproject.toml ([tool.ruff]) hold on the whole tree."""
    import shutil
    import subprocess
    import sys

    exe = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    r = subprocess.run([exe, "check", "--output-format", "concise", str(ROOT)], capture_output=True, text=True,
                       cwd=ROOT)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-1000:]
