"""What the command line tells a researcher: a run that leaves the validated range says
so, the human-readable output is short and plain, an unknown option gets the nearest
ones, ``compare`` takes the model options as ``run`` does, ``frf`` refuses an empty band."""
from __future__ import annotations

import json

from workbench import cli

RUN = ["run", "--gap-mm", "1.016", "--freq-hz", "20"]


def test_a_run_beyond_the_validated_range_says_so_in_its_json_and_on_stderr(capsys):
    assert cli.main([*RUN, "--force-n", "5000", "--duration", "0.3", "--json"]) == 0
    out, err = capsys.readouterr()
    summary = json.loads(out.strip().splitlines()[-1])
    assert "tip" in summary["out_of_range"] and summary["tip_abs_max_cm"] > 8.4
    assert "left the range the model is validated for" in err and "84 mm" in err
    assert err.count("\n") == 1
    assert cli.main([*RUN, "--force-n", "5", "--duration", "0.3", "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out.strip().splitlines()[-1])["out_of_range"] == "" and "range" not in err


def test_the_human_readable_run_is_short_plain_and_names_the_file(tmp_path, capsys):
    path = tmp_path / "h.parquet"
    assert cli.main([*RUN, "--duration", "0.3", "--out", str(path)]) == 0
    out = capsys.readouterr().out
    assert path.is_file() and f"wrote: {path}" in out
    assert "np." not in out and len(out.strip().splitlines()) <= 30
    assert "simulated_s: 0.3 s" in out


def test_an_unknown_option_gets_the_nearest_and_one_prefix(capsys):
    assert cli.main(["run", "--gap-mn", "1.016"]) == 2
    err = capsys.readouterr().err
    assert "did you mean --gap-mm?" in err and err.count("workbench:") == 1
    assert cli.main(["run", "--gap-mm", "x"]) == 2
    assert capsys.readouterr().err.startswith("workbench: error: run: argument --gap-mm")
    # the command's own options only: frf's --response is not offered to run
    assert cli.main(["run", "--response", "accel9"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: error: run: unrecognized arguments: --response accel9")
    assert "did you mean" not in err
    assert cli.main(["frf", "x.uff", "--f-maxx", "3"]) == 2
    assert "frf: unrecognized arguments: --f-maxx 3 (did you mean --f-max" in capsys.readouterr().err


def test_compare_takes_the_model_options_over_the_records_settings(tmp_path, capsys):
    """The record carries its gap (WB_gap); --gap-mm replaces it, as in docs/usage.md."""
    record = tmp_path / "r.tdms"
    assert cli.main([*RUN, "--duration", "1", "--out", str(record), "--json"]) == 0
    capsys.readouterr()
    assert cli.main(["compare", str(record), "--gap-mm", "0.762", "--out",
                     str(tmp_path / "cmp")]) == 0
    assert json.loads(capsys.readouterr().out)["simulation_status"] == 0


def test_frf_refuses_a_band_whose_lowest_frequency_is_above_its_highest(tmp_path, capsys):
    record = tmp_path / "r.tdms"
    assert cli.main([*RUN, "--duration", "1", "--out", str(record), "--json"]) == 0
    capsys.readouterr()
    assert cli.main(["frf", str(record), "--f-min", "60", "--f-max", "5",
                     "--out", str(tmp_path / "f")]) == 2
    assert "--f-min 60 Hz must be below --f-max 5 Hz" in capsys.readouterr().err


def test_compare_leaves_out_a_channel_the_simulation_lacks_and_says_so(tmp_path, capsys):
    """A hammer record compared with a sine run: the hammer channel is left out, by name."""
    record = tmp_path / "hit.tdms"
    assert cli.main(["run", "--impulse", "joint", "--duration", "0.5", "--out", str(record),
                     "--json"]) == 0
    capsys.readouterr()
    assert cli.main(["compare", str(record), "--freq-hz", "20", "--out",
                     str(tmp_path / "cmp")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["notes"] == ["compared on the channels both have; the simulation has no hammer"]


def test_an_option_and_its_parameter_state_one_allowed_range(capsys):
    assert cli.main(["run", "--gap-mm", "9"]) == 2
    option = capsys.readouterr().err
    assert cli.main(["run", "--set", "gap_mm=9"]) == 2
    parameter = capsys.readouterr().err
    assert "allowed range (0, 5]" in option and "allowed range (0, 5] mm" in parameter



def test_run_help_states_each_default(capsys):
    """Every option of ``workbench run`` with a default says it in --help."""
    import contextlib
    import io
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert cli.main(["run", "--help"]) == 0
    text = " ".join(buffer.getvalue().split())
    for option in ("--tip-mass", "--cork", "--gap-mm", "--mu", "--duration", "--dt",
                   "--method", "--tol", "--output-hz", "--joint", "--initial", "--force-n",
                   "--ramp-s", "--pulse-s", "--hit-s"):
        after = text.split(f"{option} ", 2)[-1][:260]
        assert "default" in after, option
    assert "see docs/usage.md" not in text
