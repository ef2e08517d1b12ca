"""The packages import downwards only: core, model, then reference and study,
identify, experiments, present; the command line on top.  Read from the sources' import statements
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
    "experiments": {"core", "model", "study", "identify"},
    "present": {"core", "model", "study", "identify", "experiments"},
    "cli": {"core", "model", "reference", "study", "identify", "experiments", "present"},
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
