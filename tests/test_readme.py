"""The README's example of lab files runs as written, and makes what it says."""
import shlex
from pathlib import Path

import pandas as pd

from workbench import cli
from workbench.experiments import files as F

README = Path(__file__).resolve().parents[1] / "README.md"


def _example(name: str) -> list[list[str]]:
    text = README.read_text()
    block = text.split(f"<!-- example: {name}")[1].split("-->", 1)[1].split("<!-- end of example -->")[0]
    return [shlex.split(line)[1:] for line in block.strip().splitlines()]


def test_the_lab_files_example_of_the_readme(tmp_path, monkeypatch, capsys):
    commands = _example("lab files")
    assert [c[0] for c in commands] == ["run", "convert", "frf", "compare"]
    monkeypatch.chdir(tmp_path)
    for argv in commands:
        assert cli.main(argv) == 0, (argv, capsys.readouterr().err)
    tdms, uff = F.read("chirp.tdms"), F.read("chirp.uff")
    assert list(tdms.columns) == list(F.CHANNELS) and tdms.attrs["meta"]["drive"] == "chirp"
    pd.testing.assert_frame_equal(tdms, uff, rtol=1e-9)
    peaks = pd.read_csv("frf/peaks.csv")
    assert len(peaks) and peaks.f_hz.between(5, 60).all()
    assert Path("frf/frf.uff").stat().st_size > 0 and Path("compare/frf.png").exists()
    signals = pd.read_csv("compare/differences_signals.csv")
    assert signals.rms_error_rel.max() < 1e-6        # the file re-makes its run
