"""Bad input at the command line: refused in one line naming what the user wrote, exit 2.

The CLI entry point (``workbench.cli.main``) runs in-process.  Wherever a
simulation would start, a stub stands in (:class:`WouldRun`): reaching it
means the input was accepted; what the tests check is that everything else
ends in exit code 2 with a one-line message that names the offending
option, key or file, and that no input ends in a traceback (exit 70) or an
uncaught exception.
"""
from __future__ import annotations

import json
import math
import string
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, example, given, settings, strategies as st

from workbench import cli
from workbench.lab import files as F


class WouldRun(BaseException):
    """Raised by the stubs where the real work would start (not an Exception: main lets it by)."""


def _stub(*args, **kwargs):
    raise WouldRun()


@pytest.fixture(autouse=True)
def no_work(monkeypatch, tmp_path):
    import workbench.present.comparison
    import workbench.lab.estimate
    import workbench.model.simulate
    import workbench.study.sweep
    monkeypatch.setattr(workbench.model.simulate, "simulate", _stub)
    monkeypatch.setattr(workbench.study.sweep, "run_study", _stub)
    monkeypatch.setattr(workbench.lab.estimate, "estimate", _stub)
    monkeypatch.setattr(workbench.lab.estimate, "fit", _stub)
    monkeypatch.setattr(workbench.present.comparison, "compare", _stub)
    monkeypatch.setenv("WORKBENCH_CRASH_DIR", str(tmp_path / "crash"))
    monkeypatch.chdir(tmp_path)


def outcome(argv, capsys):
    """('accepted' | exit code, stderr) of main(argv)."""
    try:
        code = cli.main([str(a) for a in argv])
    except WouldRun:
        code = "accepted"
    err = capsys.readouterr().err
    return code, err


def assert_refused(argv, capsys, *names):
    code, err = outcome(argv, capsys)
    assert code == cli.EXIT_BAD_INPUT, (argv, code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("workbench"), err
    for name in names:
        assert name in lines[0], (name, err)
    return lines[0]


def _study(tmp_path, text, name="s.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


GOOD_STUDY = """
[study]
name = "tiny"
duration_s = 0.1
window_s = 0.05
[excitation]
drive = "sine"
force_n = 20.0
[axes]
freq_hz = [20.0, 30.0]
"""

# Hand-picked cases: one per cause the issue lists (argv, names the message must contain).
CASES = [
    (["run", "--set", "cork=[1]"], ["--set cork=[1]", "cork"]),
    (["run", "--set", "gap_mm=1" + "0" * 400], ["--set gap_mm=1000", "too large"]),
    (["run", "--duration", "1e308"], ["--duration", "1e308"]),
    (["frf", "R", "--segment-s", "1e308"], ["--segment-s", "1e+308", "allowed"]),
    (["run", "--out", "1" + "0" * 400], ["--out 1000"]),           # a name too long to stat
    (["run", "--dt", "1e-300"], ["--dt", "1e-300"]),
    (["run", "--dt", "1e-3"], ["--dt", "stability limit"]),
    (["run", "--dt", "abc"], ["--dt", "'abc'"]),
    (["run", "--set", "m6=1e300"], ["--set m6=1e+300" if False else "m6", "mass matrix"]),
    (["run", "--mu", "7"], ["--mu", "7"]),
    (["run", "--mu", "nan"], ["--mu", "nan"]),
    (["run", "--gap-mm", "-1"], ["--gap-mm", "-1"]),
    (["run", "--freq-hz", "1e6"], ["--freq-hz", "1e+06", "resolves"]),
    (["run", "--chirp", "5:1e6:10", "--duration", "1"], ["--chirp F1", "resolves"]),
    (["run", "--chirp", "5:65"], ["--chirp", "F0:F1:T"]),
    (["run", "--impulse", "joint", "--pulse-s", "1e-6"], ["--pulse-s", "resolve"]),
    (["run", "--impulse", "joint", "--hit-s", "5", "--duration", "1"], ["--hit-s", "after the run"]),
    (["run", "--freq-hz", "20", "--ramp-s", "5", "--duration", "1"], ["--ramp-s", "after the run"]),
    (["run", "--freq-hz", "20", "--force-n", "-5"], ["--force-n", ">= 0"]),
    (["run", "--freq-hz", "20", "--chirp", "5:65:10"], ["--freq-hz", "--chirp"]),
    (["run", "--set", "cork=linear", "--cork", "none"], ["--cork none", "--set cork=linear"]),
    (["run", "--set", "nonsense=1"], ["--set nonsense=1", "unknown parameter"]),
    (["run", "--set", "gap_mm"], ["--set", "NAME=VALUE"]),
    (["run", "--output-hz", "333"], ["--output-hz", "333"]),
    (["run", "--free-decay", "1e9"], ["--free-decay = 1000000000.0 cm", "allowed range"]),
    (["run", "--out", "missing/dir/run.parquet"], ["--out", "missing/dir"]),
    (["run", "--out", "."], ["--out", "folder"]),
    (["run", "--out", "run.csv"], ["--out", ".parquet"]),
    (["run", "--tip-mass", "maybe"], ["--tip-mass", "maybe"]),
    (["run", "--params", "nowhere.toml"], ["nowhere.toml", "cannot read"]),
    (["identify", "decrement", "1", "0.5", "0", "1e-7", "2"], ["tn - t1", "too close"]),
    (["identify", "decrement", "1", "0.5", "0", "1", "x"], ["argument n", "'x'"]),
    (["sweep", "nowhere.toml"], ["nowhere.toml"]),
    (["sweep", "S", "--jobs", "0"], ["--jobs", "0"]),
    (["sweep", "S", "--scheduler", "not-an-address"], ["--scheduler", "not-an-address"]),
    (["sweep", "S", "--scheduler", "tcp://127.0.0.1:1"], ["--scheduler", "no scheduler"]),
    (["sweep", "S", "--scheduler", "tcp://[::1:8786"], ["--scheduler", "tcp://HOST:PORT"]),
    (["sweep", "S", "--scheduler", "tcp://host:port"], ["--scheduler", "tcp://HOST:PORT"]),
    (["sweep", "S", "--results", "F/sub"], ["--results", "a file"]),
    (["report", "S"], ["report", "sweep"]),
    (["estimate", "R", "--fit", "e_b=abc"], ["--fit e_b=abc", "'abc'"]),
    (["estimate", "R", "--fit", "e_b=1", "--max-nfev", "0"], ["--max-nfev", "0"]),
    (["estimate", "R", "--fit", "e_b=1", "--jobs", "0"], ["--jobs", "0"]),
    (["estimate", "R", "--fit", "nothing=1"], ["nothing"]),
    (["estimate", "--fit", "e_b=6e11"], ["estimate", "FILE", "--paper"]),
    (["estimate", "R", "--fit", "e_b=6e11", "--paper", "175:11"], ["--paper", "r.lvm"]),
    (["estimate", "--fit", "e_b=6e11", "--paper", "175"], ["--paper", "SINE_N:CHIRP_N"]),
    (["estimate", "--fit", "e_b=6e11", "--paper", "0:11"], ["--paper", "(0, "]),
    (["estimate", "--fit", "e_b=6e11", "--paper", "175:11", "--freq-hz", "20"],
     ["--paper", "drive options"]),
    (["estimate", "--fit", "e_b=6e11", "--bounds", "e_a=1:2"], ["--bounds e_a", "--fit"]),
    (["estimate", "--fit", "e_b=6e11", "--bounds", "e_b=2:1"], ["--bounds e_b=2:1", "LO < HI"]),
    (["estimate", "--fit", "e_b=6e11", "--bounds", "e_b=1"], ["--bounds e_b=1", "LO:HI"]),
    (["estimate", "--fit", "e_b=6e11", "--bounds", "e_b=7e11:8e11"], ["start e_b", "(7"]),
    (["estimate", "R", "--fit", "e_b=6e11", "--initial", "paper"], ["--initial paper", "--paper"]),
    (["compare", "R", "--skip-s", "1e9"], ["--skip-s", "lasts"]),
    (["compare", "R", "--skip-s", "nan"], ["--skip-s", "nan"]),
    (["compare", "R", "--strain-scale", "strain1=abc"], ["--strain-scale strain1=abc"]),
    (["compare", "NOSIG"], ["no signal channel"]),
    (["compare", "BADWB"], ["freq_hz", "'abc'"]),
    (["frobnicate"], ["frobnicate"]),
    (["identify", "tables", "--out", "F/x"], ["--out", "a file"]),
]


@pytest.fixture
def files(tmp_path):
    """Stand-ins the cases refer to: a study S, a record R, a file F, damaged records."""
    rec = pd.DataFrame({"force1": np.sin(np.arange(200) * 0.1) * 1e6,
                        "accel1": np.cos(np.arange(200) * 0.1) * 100.0},
                       index=pd.Index(np.arange(200) * 1e-3, name="t"))
    F.write(tmp_path / "r.lvm", rec, {"drive": "sine", "freq_hz": 20.0})
    F.write(tmp_path / "nosig.lvm", rec[[]].assign(contact1=0.0), {"drive": "sine", "freq_hz": 20.0})
    F.write(tmp_path / "badwb.lvm", rec, {"drive": "sine", "freq_hz": "abc"})
    (tmp_path / "afile").write_text("x")
    return {"S": _study(tmp_path, GOOD_STUDY), "R": tmp_path / "r.lvm",
            "F": tmp_path / "afile", "NOSIG": tmp_path / "nosig.lvm",
            "BADWB": tmp_path / "badwb.lvm", "OUT": tmp_path / "converted.tdms"}


def _fill(argv, files):
    out = []
    for a in argv:
        for key, path in files.items():
            if a == key:
                a = str(path)
            elif a.startswith(f"{key}/"):
                a = str(path) + a[len(key):]
        out.append(a)
    return out


@pytest.mark.parametrize("argv, names", CASES, ids=[" ".join(c[0])[:50] for c in CASES])
def test_hand_picked_bad_input_is_refused_in_one_line(argv, names, files, capsys):
    assert_refused(_fill(argv, files), capsys, *names)


def test_good_input_reaches_the_work(files, capsys):
    for argv in (["run", "--freq-hz", "20", "--duration", "0.5"],
                 ["run", "--impulse", "tip", "--duration", "0.1"],
                 ["run", "--chirp", "5:65:10", "--dt", "5e-5"],
                 ["run", "--out", "ok.parquet"],
                 ["sweep", files["S"], "--jobs", "1"],
                 ["compare", files["R"], "--skip-s", "0.05"],
                 ["estimate", files["R"], "--fit", "e_b=6e11"],
                 ["estimate", "--paper", "175:11", "--fit", "e_b=6e11", "--fit", "force_gain=1",
                  "--bounds", "e_b=4.6e11:7e11"]):
        code, err = outcome(argv, capsys)
        assert code == "accepted", (argv, code, err)


def test_dry_run_shows_grid_and_cost(files, capsys):
    code = cli.main(["sweep", str(files["S"]), "--dry-run"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert out["points"] == 2 and out["to_run"] == 2 and out["steps"] == 2000
    assert out["expected_wall_s"] > 0


def test_internal_error_is_one_line_with_a_traceback_file(monkeypatch, tmp_path, capsys):
    def broken(args):
        raise ZeroDivisionError("boom")
    from workbench.cli import simulation
    monkeypatch.setattr(simulation, "_cmd_params", broken)
    code, err = outcome(["params"], capsys)
    assert code == cli.EXIT_INTERNAL
    line = err.strip()
    assert "\n" not in line and "ZeroDivisionError: boom" in line
    crash = Path(line.split("traceback in ")[1].split(")")[0])
    assert "Traceback" in crash.read_text() and "boom" in crash.read_text()


def test_json_never_holds_nan():
    text = cli.json_text({"a": math.nan, "b": [1.0, math.inf], "c": np.float64(2.0)})
    obj = json.loads(text)
    assert obj["a"] is None and obj["b"] == [1.0, None] and obj["c"] == 2.0
    assert set(obj["nulls"]) == {"a", "b[1]"}


# --- fuzzing -----------------------------------------------------------------

OPTIONS = ["--duration", "--dt", "--output-hz", "--freq-hz", "--force-n", "--ramp-s", "--mu",
           "--gap-mm", "--pulse-s", "--hit-s", "--free-decay", "--chirp", "--tip-mass", "--cork",
           "--set", "--initial", "--out"]
texts = st.one_of(
    st.sampled_from(["0", "-1", "1e308", "-1e308", "1e-300", "nan", "inf", "-inf", "", " ",
                     "1" + "0" * 400, "0x10", "1_000", "abc", "on", "off", "linear", "[1]",
                     "{a=1}", "gap_mm=abc", "cork=[1]", "m6=1e300", "mu_s=-1", "5:65:10",
                     "5:65", "::", "1:2:3:4", "tip_mass=2", "\x00", "é", "a=b=c"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.text(string.printable, max_size=12))


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(pairs=st.lists(st.tuples(st.sampled_from(OPTIONS), texts), min_size=1, max_size=4))
def test_fuzzed_run_options_never_crash(pairs, capsys):
    argv = ["run"] + [x for pair in pairs for x in pair]
    code, err = outcome(argv, capsys)
    assert code in ("accepted", cli.EXIT_BAD_INPUT), (argv, code, err)
    if code == cli.EXIT_BAD_INPUT:
        assert len(err.strip().splitlines()) == 1, err


toml_values = st.recursive(
    st.one_of(st.integers(min_value=-10 ** 30, max_value=10 ** 30), st.floats(), st.booleans(),
              st.text(max_size=8), st.sampled_from(["linear", "cubic", "sine", "chirp", "up"])),
    lambda inner: st.one_of(st.lists(inner, max_size=3),
                            st.dictionaries(st.sampled_from(["n", "gap_mm", "x"]), inner,
                                            max_size=2)),
    max_leaves=6)
STUDY_KEYS = {"study": ["name", "duration_s", "window_s", "sweep", "dt", "output_hz",
                        "save_series", "initial", "description", "bogus"],
              "excitation": ["drive", "force_n", "freq_hz", "ramp_s", "deflection_cm", "f0_hz"],
              "fixed": ["cork", "mu_s", "gap_mm", "tip_mass", "m6", "bogus"],
              "axes": ["freq_hz", "gap_mm", "cork", "tip_mass", "force_n"]}


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value == math.inf else
                                                 "-inf" if value == -math.inf else repr(value))
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"


@st.composite
def study_texts(draw):
    lines = []
    for table, keys in STUDY_KEYS.items():
        if draw(st.booleans()):
            lines.append(f"[{table}]")
            for key in draw(st.lists(st.sampled_from(keys), unique=True, max_size=4)):
                lines.append(f"{key} = {_toml(draw(toml_values))}")
    base = GOOD_STUDY if draw(st.booleans()) else ""
    return base + "\n" + "\n".join(lines) if not base else _merge(base, lines)


def _merge(base, lines):
    """Replace or add keys of the good study (a duplicate TOML key is a decode error: kept)."""
    return base + "\n" + "\n".join(lines)


#: A list where a word belongs, in every section: (section, key = value, what the line names).
LIST_WORDS = [("study", 'name = ["tiny"]', "name"), ("study", 'description = ["d"]', "description"),
              ("study", 'sweep = ["up"]', "sweep"), ("study", 'initial = ["paper"]', "initial"),
              ("study", 'method = ["rk4"]', "method"), ("excitation", 'drive = ["sine"]', "drive"),
              ("fixed", 'cork = ["cubic"]', "cork"), ("axes", 'cork = [["cubic"]]', "cork")]


@pytest.mark.parametrize("section, line, names", LIST_WORDS, ids=lambda c: str(c)[:14])
def test_a_list_where_a_word_belongs_is_refused_in_one_line(section, line, names, tmp_path,
                                                            capsys):
    key = line.split(" = ")[0]
    text = "\n".join(row for row in GOOD_STUDY.splitlines()
                      if not (row.startswith(f"{key} = ") and section in ("study", "excitation")))
    if f"[{section}]" in text:
        text = text.replace(f"[{section}]", f"[{section}]\n{line}", 1)
    else:
        text += f"\n[{section}]\n{line}\n"
    path = _study(tmp_path, text)
    assert_refused(["sweep", str(path), "--dry-run"], capsys, names, "s.toml")


@settings(max_examples=200, deadline=None, suppress_health_check=list(HealthCheck))
@given(text=study_texts())
def test_fuzzed_study_files_never_crash(text, tmp_path_factory, capsys):
    path = tmp_path_factory.mktemp("fuzz") / "study.toml"
    path.write_text(text)
    code, err = outcome(["sweep", str(path), "--dry-run"], capsys)
    assert code in (0, cli.EXIT_BAD_INPUT), (text, code, err)
    if code == cli.EXIT_BAD_INPUT:
        assert len(err.strip().splitlines()) == 1 and "study.toml" in err, err


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=st.one_of(st.binary(max_size=64),
                      st.builds(lambda k, v: f"[model]\n{k} = {_toml(v)}\n".encode(),
                                st.sampled_from(["cork", "gap_mm", "m6", "tip_mass", "mu_s",
                                                 "model", "nonsense"]), toml_values),
                      st.builds(lambda v: f"model = {_toml(v)}\n".encode(), toml_values)))
def test_fuzzed_parameter_files_never_crash(data, tmp_path_factory, capsys):
    path = tmp_path_factory.mktemp("fuzz") / "p.toml"
    path.write_bytes(data)
    code, err = outcome(["params", "--params", str(path)], capsys)
    assert code in (0, cli.EXIT_BAD_INPUT), (data, code, err)
    if code == cli.EXIT_BAD_INPUT:
        assert len(err.strip().splitlines()) == 1 and "p.toml" in err, err


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(cut=st.integers(0, 2000), junk=st.binary(max_size=16))
@example(cut=64, junk=b"\n")                  # a header key left without its value
def test_fuzzed_experiment_files_never_crash(cut, junk, files, capsys):
    text = Path(files["R"]).read_bytes()
    path = Path(files["R"]).with_name("damaged.lvm")
    path.write_bytes(text[:cut] + junk + text[cut + len(junk):])
    code, err = outcome(["compare", str(path)], capsys)
    assert code in ("accepted", cli.EXIT_BAD_INPUT), (code, err)
    if code == cli.EXIT_BAD_INPUT:
        assert len(err.strip().splitlines()) == 1, err


COMMANDS = [["sweep", "S", "--dry-run"], ["compare", "R"], ["estimate", "R", "--fit", "e_b=6e11"],
            ["modes"], ["params"], ["identify", "decrement", "1", "0.5", "0", "1", "5"],
            ["identify", "tables", "--no-table6"], ["frf", "R"], ["convert", "R", "OUT"]]
MORE_OPTIONS = OPTIONS + ["--jobs", "--scheduler", "--results", "--fresh", "--skip-s",
                          "--strain-scale", "--threshold", "--fit", "--max-nfev", "--beam",
                          "--joint", "--params", "--json", "--force", "--response", "--segment-s",
                          "--f-min", "--f-max", "--format", "--from", "--to"]


@settings(max_examples=200, deadline=None, suppress_health_check=list(HealthCheck))
@given(command=st.sampled_from(COMMANDS),
       pairs=st.lists(st.tuples(st.sampled_from(MORE_OPTIONS), texts), min_size=1, max_size=3))
@example(command=["frf", "R"], pairs=[("--segment-s", "1e308")])   # longer than the record
def test_fuzzed_options_of_every_command_never_crash(command, pairs, files, capsys):
    argv = _fill(command, files) + [x for pair in pairs for x in pair
                                    if not (pair[0] == "--scheduler" and ":" in x)]
    code, err = outcome(argv, capsys)
    assert code in ("accepted", 0, cli.EXIT_BAD_INPUT), (argv, code, err)
    if code == cli.EXIT_BAD_INPUT:
        assert len(err.strip().splitlines()) == 1, err
