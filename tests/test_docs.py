"""Every example of README.md and docs/*.md runs as written.

The examples are the fenced blocks tagged ``python`` and ``sh``, read from
the files themselves, so an example that goes stale fails here.  A file's
blocks run in order in one temporary folder (with ``studies/`` linked
into it): ``python`` blocks in one namespace per file; ``sh`` blocks line
by line, each ``workbench ...`` or ``python -m workbench ...`` command
through the command line's ``main``, which must return 0.  ``make
TARGET`` lines are checked by ``make -n TARGET`` in the repository (the
target exists and its recipe expands): running ``make test`` inside the
test suite would recurse.  Blocks tagged ``text`` (synopses, printed
output) and ``toml`` are not run.
"""
from __future__ import annotations

import re
import shlex
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from workbench import cli
from workbench.lab import files as F

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```(\w*)\n(.*?)^```$", re.S | re.M)
RUN = ("python", "sh")


def blocks(path: Path) -> list[tuple[str, int, str]]:
    """(language, line, code) of each fenced block of a Markdown file."""
    text = path.read_text()
    return [(m.group(1), text.count("\n", 0, m.start()) + 1, m.group(2))
            for m in FENCE.finditer(text)]


def run_shell(code: str, where: str) -> None:
    for line in code.splitlines():
        argv = shlex.split(line, comments=True)
        if not argv:
            continue
        if argv[0] == "make":
            done = subprocess.run(["make", "-n", *argv[1:]], cwd=ROOT, capture_output=True,
                                  text=True)
            assert done.returncode == 0, (where, line, done.stderr)
        elif argv[0] == "workbench" or argv[:3] == ["python", "-m", "workbench"]:
            args = argv[1:] if argv[0] == "workbench" else argv[3:]
            assert cli.main(args) == 0, (where, line)
        else:
            raise AssertionError(f"{where}: a sh example runs workbench or make, not {line!r}")


def check_lab_files() -> None:
    """What the README says its lab-files example makes."""
    tdms, uff = F.read("chirp.tdms"), F.read("chirp.uff")
    shaker = [c for c in F.CHANNELS if c != "hammer"]        # a chirp records no hammer
    assert list(tdms.columns) == shaker and tdms.attrs["meta"]["drive"] == "chirp"
    pd.testing.assert_frame_equal(tdms, uff, rtol=1e-9)
    modes = pd.read_csv("frf/modes.csv")
    assert modes.f_hz.between(5, 60).all() and (modes.band_hi_hz == 60).all()
    hit = pd.read_csv("frf-hit/modes.csv")                 # the locked joint's four modes
    assert np.allclose(hit.f_hz, [1.969, 13.91, 46.97, 159.75], rtol=3e-3), hit
    assert hit.zeta_resolved.tolist() == [False, True, True, True]
    assert Path("frf/frf.uff").stat().st_size > 0 and Path("compare/frf.png").exists()
    signals = pd.read_csv("compare/differences_signals.csv")
    assert signals.rms_error_rel.max() < 1e-6        # the file re-makes its run


#: Checks of what a file's examples made, run after them.
AFTER = {"README.md": check_lab_files}


@pytest.mark.parametrize("path", [p for p in DOCS if any(b[0] in RUN for b in blocks(p))],
                         ids=lambda p: p.name)
def test_the_examples_run_as_written(path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "studies").symlink_to(ROOT / "studies")
    namespace: dict = {"__name__": "__doc_example__"}
    for language, line, code in blocks(path):
        where = f"{path.name}:{line}"
        if language == "python":
            exec(compile(code, where, "exec"), namespace)
        elif language == "sh":
            run_shell(code, where)
    if path.name in AFTER:
        AFTER[path.name]()


def indented_blocks(path: Path) -> list[int]:
    """Lines that start a Markdown code block by indentation (outside fences and lists)."""
    starts, fenced, previous = [], False, ""
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if line.startswith("```"):
            fenced = not fenced
        elif (not fenced and line.startswith("    ") and not previous.strip()
              and not line.lstrip().startswith(("-", "*", "|"))):
            starts.append(number)
        previous = line
    return starts


def test_every_block_says_what_it_is():
    """An untagged or indented block would be skipped unseen: each is fenced and tagged
    python, sh, text or toml."""
    for path in DOCS:
        for language, line, _ in blocks(path):
            assert language in (*RUN, "text", "toml"), f"{path.name}:{line} is tagged {language!r}"
        assert not indented_blocks(path), (path.name, indented_blocks(path))
    assert sum(b[0] in RUN for p in DOCS for b in blocks(p)) >= 8


@pytest.mark.parametrize("path", DOCS, ids=lambda p: p.name)
def test_every_study_example_and_file_loads(path):
    """A ``toml`` block with a [study] table is a study that loads as written (and so is
    every study file under studies/)."""
    import tomllib
    from workbench.study import definition as S
    loaded = 0
    for language, line, code in blocks(path):
        if language == "toml" and code.lstrip().startswith("[study]"):
            S.from_dict(tomllib.loads(code), source=f"{path.name}:{line}")
            loaded += 1
    if path.name == "usage.md":
        assert loaded >= 1
    if path.name == "README.md":
        for study in sorted((ROOT / "studies").glob("*.toml")):
            S.load(study)
