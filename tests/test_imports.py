"""The packages import downwards only: core, model, then reference and study,
identify, lab, present; the command line on top.  Read from the sources' import statements
(those inside functions included), so a late import cannot hide a circle."""
import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "workbench"
#: Each package and the packages it may import (besides itself).
LAYERS = {
    "core": set(),
    "model": {"core"},
    "reference": {"core", "model"},
    "study": {"core", "model"},
    "identify": {"core", "model", "study"},
    "lab": {"core", "model", "study", "identify"},
    "present": {"core", "model", "study", "identify", "lab"},
    "cli": {"core", "model", "reference", "study", "identify", "lab", "present"},
}

def imported_packages(path: Path) -> set[str]:
    """The workbench sub-packages a module imports (relative or absolute imports)."""
    parts = ("workbench", *path.relative_to(PACKAGE).with_suffix("").parts)
    package = parts[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level == 0:
                names = (node.module or "").split(".")
            else:
                names = [*package[:len(package) - node.level + 1], *(node.module or "").split(".")]
            if names[0] == "workbench" and len(names) > 1 and names[1]:
                found.add(names[1])
        elif isinstance(node, ast.Import):
            found |= {a.name.split(".")[1] for a in node.names if a.name.startswith("workbench.")}
    return found - {parts[1]}


def test_every_package_imports_only_the_layers_below_it():
    wrong = []
    for package, allowed in LAYERS.items():
        for path in sorted((PACKAGE / package).rglob("*.py")):
            extra = imported_packages(path) - allowed
            if extra:
                wrong.append(f"{path.relative_to(PACKAGE)} imports {sorted(extra)}")
    assert not wrong, wrong


def imported_modules(path: Path, modules: set[str]) -> set[str]:
    """The workbench modules a module imports (a name imported from a package counts as its
    module when it is one, else as the package)."""
    parts = ("workbench", *path.relative_to(PACKAGE).with_suffix("").parts)
    package = parts if parts[-1] == "__init__" else parts[:-1]
    package = package[:-1] if package[-1] == "__init__" else package
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = ((node.module or "").split(".") if node.level == 0
                    else [*package[:len(package) - node.level + 1], *(node.module or "").split(".")])
            base = ".".join(b for b in base if b)
            for alias in node.names:
                target = f"{base}.{alias.name}"
                found.add(target if target in modules else base)
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
    return {m for m in found if m in modules}


def test_no_module_imports_itself_through_others():
    """No import circle between modules (Tarjan's strongly connected components; a package's
    ``__init__`` is its face and is left out)."""
    paths = {".".join(("workbench", *p.relative_to(PACKAGE).with_suffix("").parts)): p
             for p in PACKAGE.rglob("*.py") if p.name != "__init__.py"}
    graph = {m: imported_modules(p, set(paths)) - {m} for m, p in paths.items()}
    index, low, stack, circles = {}, {}, [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))
    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert not circles, circles
