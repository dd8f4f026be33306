"""The layout's rules, measured on the source (docs/design.md, "Layout"; issue 34).

Arrows only downward (no import cycle between modules, nor between the package's folders), each
room holding one idea (file, function and class sizes), no module reaching into another's
private names, and matplotlib only in the plotting package. Every figure is read from the
syntax tree of ``rrtpso_ompl/``, imports inside functions included.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from functools import cache
from pathlib import Path

import rrtpso_ompl

ROOT = Path(rrtpso_ompl.__file__).parent
PACKAGE = ROOT.name

#: The limits of issue 34: a file over 800 lines, a function over 60 (docstring included) and a
#: class over 400 hold more than one idea. A few public functions whose numpydoc parameter list
#: is most of their length (the swarm's ``minimize``, ``run_batch``, ``run_bench``) may pass 60.
MAX_FILE_LINES = 800
MAX_FUNCTION_LINES = 60
MAX_LONG_FUNCTIONS = 3
MAX_CLASS_LINES = 400
MAX_LONG_CLASSES = 1


@cache
def _modules() -> dict[str, Path]:
    """Dotted module name -> file, for every module of the package."""
    found = {}
    for path in ROOT.rglob("*.py"):
        parts = path.relative_to(ROOT.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        found[name] = path
    return found


@cache
def _tree(name: str) -> ast.Module:
    return ast.parse(_modules()[name].read_text(encoding="utf-8"))


def _imports(name: str) -> list[tuple[str, str | None]]:
    """``(module imported, name imported from it or None)`` for every import in ``name``."""
    mods = _modules()
    out = []
    for node in ast.walk(_tree(name)):
        if isinstance(node, ast.Import):
            out += [(a.name, None) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                here = name.split(".")
                if mods[name].name != "__init__.py":
                    here = here[:-1]
                here = here[: len(here) - (node.level - 1)]
                base = ".".join(here + ([node.module] if node.module else []))
            for a in node.names:
                sub = f"{base}.{a.name}"
                out.append((sub, None) if sub in mods else (base, a.name))
    return out


def _edges() -> dict[str, set[str]]:
    """Module -> the package's modules it imports (a package's ``__init__`` importing its own
    submodules is not an arrow: it is how a package exports)."""
    mods = _modules()
    edges = defaultdict(set)
    for name in mods:
        for target, _ in _imports(name):
            if target in mods and target != name:
                if mods[name].name == "__init__.py" and target.startswith(name + "."):
                    continue
                edges[name].add(target)
    return edges


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in list(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    component = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        component.append(w)
                        if w == v:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return found


def _folder(module: str) -> str:
    parts = module.split(".")
    return "(root)" if len(parts) == 1 else parts[1]


def _sized(kinds: tuple[type, ...], limit: int) -> list[tuple[int, str]]:
    out = []
    for name in _modules():
        for node in ast.walk(_tree(name)):
            if isinstance(node, kinds):
                lines = node.end_lineno - node.lineno + 1
                if lines > limit:
                    out.append((lines, f"{name}.{node.name}"))
    return sorted(out, reverse=True)


def test_the_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_module_imports_itself_back():
    assert _cycles(_edges()) == []


def test_no_folder_imports_itself_back():
    folders = defaultdict(set)
    for name, targets in _edges().items():
        for target in targets:
            if _folder(name) != _folder(target):
                folders[_folder(name)].add(_folder(target))
    assert _cycles(folders) == []


def test_no_module_imports_another_modules_private_name():
    private = [
        (name, target, imported)
        for name in _modules()
        for target, imported in _imports(name)
        if target.startswith(PACKAGE) and imported
        and imported.startswith("_") and not imported.startswith("__")
    ]  # fmt: skip
    assert private == []


def test_no_file_holds_more_than_one_room():
    big = [
        (len(path.read_text(encoding="utf-8").splitlines()), name)
        for name, path in _modules().items()
    ]
    assert [b for b in big if b[0] > MAX_FILE_LINES] == []


def test_functions_and_classes_stay_short():
    functions = _sized((ast.FunctionDef, ast.AsyncFunctionDef), MAX_FUNCTION_LINES)
    assert len(functions) <= MAX_LONG_FUNCTIONS, functions
    classes = _sized((ast.ClassDef,), MAX_CLASS_LINES)
    assert len(classes) <= MAX_LONG_CLASSES, classes


def test_only_the_plotting_package_imports_matplotlib():
    users = {
        name
        for name in _modules()
        for target, _ in _imports(name)
        if target.split(".")[0] == "matplotlib"
    }
    assert users and all(_folder(u) == "plotting" for u in users), sorted(users)
