"""benchmarks/summarise.py: which saved run each table's entries come from."""
import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("summarise", ROOT / "benchmarks" / "summarise.py")
summarise = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(summarise)


def _run(path, names):
    path.write_text(json.dumps({"benchmarks": [{"name": n, "stats": {"median": 1.0}}
                                               for n in names]}))
    return path


def test_a_test_function_s_entries_come_from_the_newest_run_that_has_it(tmp_path):
    old = _run(tmp_path / "0001.json", ["test_acc[tip-2e-05]", "test_acc[tip-1e-06]",
                                        "test_core[free]"])
    new = _run(tmp_path / "0002.json", ["test_acc[tip-3e-05]", "test_acc[tip-1e-06]"])
    entries, _ = summarise.newest_by_name([old, new])
    assert sorted(entries) == ["test_acc[tip-1e-06]", "test_acc[tip-3e-05]", "test_core[free]"]
    assert entries["test_acc[tip-1e-06]"]["source"] == "0002.json"
    assert entries["test_core[free]"]["source"] == "0001.json"   # a partial run keeps the rest
