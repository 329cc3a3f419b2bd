"""How the modules of ``src/robodyn`` may import each other (ARCHITECTURE.md): no import cycle,
no private name from another file, private modules only inside their own package; and no
module that defines a top-level function or class twice (the second silently replaces the
first for every caller in the file)."""

import ast
import pathlib

import pytest

SRC = pathlib.Path(__file__).resolve().parent.parent / "src"
PACKAGE = SRC / "robodyn"


def module_name(path: pathlib.Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: pathlib.Path):
    """``(line, module, names)`` of every import in the file, anywhere (function bodies too),
    relative imports resolved."""
    tree = ast.parse(path.read_text(), str(path))
    here = module_name(path)
    package = here if path.name == "__init__.py" else here.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name, []
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module
            yield node.lineno, module, [a.name for a in node.names]


def private(segment: str) -> bool:
    return segment.startswith("_") and not segment.startswith("__")


def is_module(name: str) -> bool:
    path = SRC.joinpath(*name.split("."))
    return path.with_suffix(".py").exists() or (path / "__init__.py").exists()


FILES = sorted(PACKAGE.rglob("*.py"))


def violations(path):
    here = module_name(path)
    found = []
    for line, module, names in imports(path):
        if not module or not module.startswith("robodyn"):
            continue
        targets = [module] + [f"{module}.{n}" for n in names if is_module(f"{module}.{n}")]
        for target in targets:
            parts = target.split(".")
            for k, segment in enumerate(parts):
                if private(segment):
                    owner = ".".join(parts[:k])  # the package the private module belongs to
                    if not (here == owner or here.startswith(owner + ".")):
                        found.append(f"{here}:{line}: imports {target}, private to {owner}")
                    break
        for n in names:
            if private(n) and not is_module(f"{module}.{n}"):
                found.append(f"{here}:{line}: imports the private name {n} from {module}")
    return found


def test_rules_catch_what_they_should(tmp_path, monkeypatch):
    """The checker itself: a private name and a private module of another package are caught."""
    pkg = tmp_path / "robodyn"
    (pkg / "a").mkdir(parents=True)
    (pkg / "b").mkdir()
    for f in ("__init__.py", "a/__init__.py", "b/__init__.py", "a/_hidden.py", "a/one.py"):
        (pkg / f).write_text("")
    (pkg / "a" / "two.py").write_text("from ._hidden import x\nfrom .one import _secret\n")
    (pkg / "b" / "three.py").write_text("def f():\n    from ..a import _hidden\n")
    monkeypatch.setattr(__import__(__name__), "SRC", tmp_path)
    assert violations(pkg / "a" / "two.py") == ["robodyn.a.two:2: imports the private name _secret from robodyn.a.one"]
    assert violations(pkg / "b" / "three.py") == ["robodyn.b.three:2: imports robodyn.a._hidden, private to robodyn.a"]


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_private_import_across_packages(path):
    assert violations(path) == []


def redefinitions(path: pathlib.Path) -> list[str]:
    """``name: lines`` of every top-level function or class defined more than once in the file."""
    lines = {}
    for node in ast.parse(path.read_text(), str(path)).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            lines.setdefault(node.name, []).append(node.lineno)
    return [f"{name}: lines {where}" for name, where in lines.items() if len(where) > 1]


def test_redefinition_finder_finds_one(tmp_path):
    path = tmp_path / "m.py"
    path.write_text("def _zero(x):\n    pass\n\n\nclass A:\n    pass\n\n\ndef _zero(y):\n    pass\n")
    assert redefinitions(path) == ["_zero: lines [1, 9]"]


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_top_level_name_defined_twice(path):
    assert redefinitions(path) == []


def import_graph(files):
    """``module -> set of modules it imports`` within ``robodyn``: every ``import`` statement,
    function bodies included; ``from pkg import name`` is an edge to ``pkg.name`` when that is a
    module, else to ``pkg``. The packages above an imported module are not counted (Python runs
    their ``__init__`` first, but a package's own ``__init__`` imports are its edges)."""
    graph = {}
    for path in files:
        here = module_name(path)
        edges = graph.setdefault(here, set())
        for _, module, names in imports(path):
            if not module or not (module == "robodyn" or module.startswith("robodyn.")):
                continue
            targets = [f"{module}.{n}" for n in names if is_module(f"{module}.{n}")]
            if not targets or len(targets) < len(names):
                targets.append(module)
            edges.update(t for t in targets if t != here)
    return graph


def find_cycle(graph):
    """One cycle of ``graph`` as a list of modules (first == last), or None."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        state[node] = "done"
        stack.pop()
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def test_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None


def test_no_import_cycle():
    cycle = find_cycle(import_graph(FILES))
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


# Packages that a module of the key may not import (ARCHITECTURE.md, "Layers").
FORBIDDEN = {
    "robodyn.algorithms": ("robodyn.simulation", "robodyn.control", "robodyn.identification", "robodyn.symbolic",
                           "robodyn.cli", "robodyn.interop", "robodyn.contact", "robodyn.distributed"),
    "robodyn.contact": ("robodyn.simulation", "robodyn.control", "robodyn.identification", "robodyn.cli",
                        "robodyn.distributed"),
    "robodyn.control": ("robodyn.simulation", "robodyn.identification", "robodyn.cli", "robodyn.distributed"),
    "robodyn.simulation": ("robodyn.identification", "robodyn.cli", "robodyn.distributed"),
    "robodyn.identification": ("robodyn.cli", "robodyn.distributed"),
    "robodyn.distributed": ("robodyn.cli",),
    "robodyn.io": ("robodyn.algorithms", "robodyn.simulation", "robodyn.control", "robodyn.cli"),
    "robodyn.interop": ("robodyn.algorithms", "robodyn.simulation", "robodyn.control", "robodyn.cli"),
    "robodyn": ("robodyn.cli",),  # nothing outside the command line imports it
}


def test_layers_import_downward_only():
    graph = import_graph(FILES)
    found = []
    for module, targets in graph.items():
        owner = max((k for k in FORBIDDEN if module == k or module.startswith(k + ".")), key=len, default=None)
        if owner is None or module.startswith("robodyn.cli"):
            continue
        found += [f"{module} imports {t}" for t in sorted(targets)
                  if any(t == f or t.startswith(f + ".") for f in FORBIDDEN[owner])]
    assert found == []
