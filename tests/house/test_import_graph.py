"""The pyins package's import graph, read from the source with ``ast``: no
cycle, and no pyins module imported inside a function (a function-level
import hides an edge that runs back up the house; third-party modules
imported late for speed or as optional extras, matplotlib, dask, tomli,
are not pyins's and are not counted).

Edges: ``import pyins.a.b``, ``from pyins.a import b`` (b a submodule or a
name of pyins.a), ``from . import x`` and ``from .a import b``, each to the
module imported and to every package on its way (importing pyins.a.b runs
pyins/a/__init__.py first), except the packages the importer itself lies
in (they are already being imported when it runs)."""
import ast
import pathlib

import pyins

ROOT = pathlib.Path(pyins.__file__).resolve().parent
PACKAGE = "pyins"


def _modules(root=ROOT):
    """{dotted name: path} of every module of the package."""
    out = {}
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _is_package(name, modules):
    return modules[name].name == "__init__.py"


def _resolve_from(node, name, modules):
    """The absolute module a ``from ... import`` names (its level resolved)."""
    if node.level == 0:
        return node.module
    base = name.split(".") if _is_package(name, modules) else name.split(".")[:-1]
    base = base[:len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _targets(node, name, modules):
    """The pyins modules an import node brings in (itself and its packages)."""
    found = []
    if isinstance(node, ast.Import):
        found = [a.name for a in node.names]
    elif isinstance(node, ast.ImportFrom):
        mod = _resolve_from(node, name, modules)
        found = [mod] + [f"{mod}.{a.name}" for a in node.names if f"{mod}.{a.name}" in modules]
    out = set()
    own = set()
    parts = name.split(".")
    for i in range(1, len(parts) + 1):
        prefix = ".".join(parts[:i])
        if prefix in modules and _is_package(prefix, modules):
            own.add(prefix)
    for mod in found:
        if mod != PACKAGE and not mod.startswith(PACKAGE + "."):
            continue
        bits = mod.split(".")
        for i in range(1, len(bits) + 1):
            prefix = ".".join(bits[:i])
            if prefix in modules and prefix not in own and prefix != name:
                out.add(prefix)
    return out


class _Walker(ast.NodeVisitor):
    """Every import node of a module, with whether it sits inside a function."""

    def __init__(self):
        self.found, self.depth = [], 0

    def _function(self, node):
        self.depth += 1
        self.generic_visit(node)
        self.depth -= 1

    visit_FunctionDef = visit_AsyncFunctionDef = visit_Lambda = _function

    def visit_Import(self, node):
        self.found.append((node, self.depth > 0))

    visit_ImportFrom = visit_Import


def import_graph(root=ROOT):
    """({module: {module it imports}}, [(module, line, text) of each
    function-level import of a pyins module])."""
    modules = _modules(root)
    graph, late = {}, []
    for name, path in modules.items():
        walker = _Walker()
        walker.visit(ast.parse(path.read_text(encoding="utf-8"), filename=str(path)))
        edges = set()
        for node, in_function in walker.found:
            targets = _targets(node, name, modules)
            edges |= targets
            if in_function and targets:
                late.append((name, node.lineno, ast.unparse(node)))
        graph[name] = edges
    return graph, late


def find_cycles(graph):
    """The strongly connected components of more than one module (or a
    module importing itself), sorted, each as (one shortest cycle through
    its first module, every module of the component)."""
    index, low, stack, on_stack, comps = {}, {}, [], set(), []
    counter = [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1 or v in graph.get(v, ()):
                comps.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return [(_one_cycle(graph, comp), comp) for comp in sorted(comps)]


def _one_cycle(graph, comp):
    """A shortest path start -> ... -> start inside the component ``comp``."""
    inside = set(comp)
    start = comp[0]
    prev, todo = {start: None}, [start]
    while todo:
        v = todo.pop(0)
        for w in sorted(graph[v] & inside):
            if w == start:
                path = [v]
                while prev[path[-1]] is not None:
                    path.append(prev[path[-1]])
                return path[::-1] + [start]
            if w not in prev:
                prev[w] = v
                todo.append(w)
    return comp


def test_the_graph_sees_the_package():
    graph, _ = import_graph()
    assert "pyins.fil" in graph and "pyins.scenario.build" in graph
    assert "pyins.records" in graph["pyins.fil"]
    assert "pyins.scenario" in graph["pyins.fil"]          # the package of pyins.scenario.build
    assert "pyins.scenario.build" in graph["pyins.scenario"]
    assert "pyins.scenario" not in graph["pyins.scenario.build"]  # its own package: already importing


def test_a_cycle_is_found_and_named(tmp_path):
    pkg = tmp_path / PACKAGE
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from pyins import b\n")
    (pkg / "b.py").write_text("def f():\n    from . import a\n")
    (pkg / "sub" / "__init__.py").write_text("from .c import X\n")
    (pkg / "sub" / "c.py").write_text("from pyins.sub import d\nX = 1\n")
    (pkg / "sub" / "d.py").write_text("import numpy\n")
    graph, late = import_graph(pkg)
    assert find_cycles(graph) == [([f"{PACKAGE}.a", f"{PACKAGE}.b", f"{PACKAGE}.a"], [f"{PACKAGE}.a", f"{PACKAGE}.b"])]
    assert late == [(f"{PACKAGE}.b", 2, "from . import a")]
    assert graph[f"{PACKAGE}.sub.c"] == {f"{PACKAGE}.sub.d"}


def test_no_import_cycle():
    graph, _ = import_graph()
    cycles = find_cycles(graph)
    assert not cycles, "import cycles in pyins:\n" + "\n".join(
        f"{' -> '.join(cycle)} (in a circle of {len(comp)}: {', '.join(comp)})" for cycle, comp in cycles)


def test_no_function_level_import_of_pyins():
    _, late = import_graph()
    assert not late, "pyins modules imported inside a function:\n" + "\n".join(
        f"{name}:{line}: {text}" for name, line, text in late)
