"""Experiment files: round trips, units, and damaged files that must fail
with an error naming the file and the line, never with a traceback or wrong data."""
import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, example, given, settings, strategies as st

from workbench.lab import files as F

from damaged import reads_cleanly_or_fails_clearly


def _record(n=50, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 1e-3
    data = {"force1": rng.normal(0, 2e6, n), "strain1": rng.normal(0, 1e-4, n),
            "accel1": rng.normal(0, 500, n), "contact1": (rng.random(n) > 0.5) * 1.0,
            "contact2": np.zeros(n), "contact3": np.ones(n), "contact4": np.zeros(n),
            "accel2": rng.normal(0, 500, n), "strain2": rng.normal(0, 1e-4, n),
            "accel3": rng.normal(0, 500, n)}
    return pd.DataFrame(data, index=pd.Index(t, name="t"))


@pytest.mark.parametrize("suffix", [".lvm", ".txt"])
def test_round_trip_keeps_values_units_and_settings(tmp_path, suffix):
    rec = _record()
    meta = {"drive": "sine", "freq_hz": 20.0, "gap_mm": 1.016, "tip_mass": True, "cork": "cubic"}
    back = F.read(F.write(tmp_path / f"r{suffix}", rec, meta))
    assert list(back.columns) == list(rec.columns)
    np.testing.assert_allclose(back.to_numpy(), rec.to_numpy(), rtol=1e-9, atol=1e-20)
    np.testing.assert_allclose(back.index.to_numpy(), rec.index.to_numpy(), rtol=1e-12)
    assert back.attrs["meta"] == meta
    assert back.attrs["units_assumed"] == []


def test_units_and_labels_of_a_hand_written_text_file(tmp_path):
    path = tmp_path / "rig.txt"
    path.write_text("Time\tForce 1 (N)\tstrain_1 [ue]\tAccel3 (g)\tStrain2 (V)\n"
                    "0\t1\t100\t1\t2\n0.001\t2\t200\t0.5\t4\n")
    rec = F.read(path, strain_scale={"strain2": 1.77e-5})
    np.testing.assert_allclose(rec.force1, [1e5, 2e5])
    np.testing.assert_allclose(rec.strain1, [1e-4, 2e-4])
    np.testing.assert_allclose(rec.accel3, [980.665, 490.3325])
    np.testing.assert_allclose(rec.strain2, [3.54e-5, 7.08e-5])
    with pytest.raises(F.ExperimentFileError, match=r"rig.txt, line 1: .*Strain2 is in V"):
        F.read(path)


def test_lvm_without_x_column_uses_x0_and_delta_x(tmp_path):
    """X_Columns No (NI's LVM specification): the rows leave the X column empty and the
    time is X0 + k Delta_X."""
    text = F.write(tmp_path / "a.lvm", _record(5)).read_text()
    lines = [l.replace("X_Columns\tOne", "X_Columns\tNo") for l in text.split("\n")]
    body = next(i for i, l in enumerate(lines) if l.startswith("X_Value"))
    lines[body + 1:] = ["\t" + l.split("\t", 1)[1] if l else l for l in lines[body + 1:]]
    (tmp_path / "b.lvm").write_text("\n".join(lines))
    rec = F.read(tmp_path / "b.lvm")
    np.testing.assert_allclose(rec.index.to_numpy(), np.arange(5) * 1e-3)
    np.testing.assert_allclose(rec.to_numpy(), _record(5).to_numpy(), rtol=1e-9, atol=1e-20)


@pytest.mark.parametrize("edit, line, problem", [
    (lambda L: ["Labview measurement"] + L[1:], 1, "not a LabVIEW measurement file"),
    # lines: 1-13 file header (line 12 the WB_ setting), 15 the segment, 22 the
    # column names, 23-72 the 50 rows
    (lambda L: L[:-3], 15, "declares 50 samples but has 48"),
    (lambda L: L[:-2] + [L[-2].rsplit("\t", 3)[0]] + L[-1:], 72, "too few values"),
    (lambda L: [l.replace("Strain2", "Strain9") for l in L], 22, "unknown channel 'Strain9'"),
    (lambda L: [l.replace("Accel2", "Accel1") if l.startswith("X_Value") else l for l in L], 22,
     "appears twice"),
    (lambda L: L[:30] + [L[30].replace("\t", "\tabc", 1)] + L[31:], 31, "column 'Force1': 'abc"),
    (lambda L: L[:12], 2, "header without"),
    (lambda L: L[:14], 14, "no data segment"),
    (lambda L: [l.replace("m/s^2", "furlong") for l in L], 15, "unit 'furlong'"),
    (lambda L: L[:40] + [L[40].replace(L[40].split("\t")[0], "0.001", 1)] + L[41:], 41,
     "does not increase"),
])
def test_damaged_lvm_names_file_line_and_problem(tmp_path, edit, line, problem):
    lines = F.write(tmp_path / "good.lvm", _record(), {"gap_mm": 1.016}).read_text().split("\n")
    bad = tmp_path / "bad.lvm"
    bad.write_text("\n".join(edit(lines)))
    with pytest.raises(F.ExperimentFileError) as err:
        F.read(bad)
    assert err.value.path == str(bad)
    assert err.value.line == line and problem in err.value.problem, str(err.value)


def test_unknown_suffix_and_missing_file(tmp_path):
    with pytest.raises(F.ExperimentFileError, match="unknown file type '.xls'"):
        F.read(tmp_path / "a.xls")
    with pytest.raises(F.ExperimentFileError, match="no such file"):
        F.read(tmp_path / "nothing.lvm")


_GOOD = {}


def _good_file(tmp_path_factory, suffix):
    if suffix not in _GOOD:
        path = tmp_path_factory.mktemp("good") / f"good{suffix}"
        F.write(path, _record(30), {"drive": "sine", "freq_hz": 20.0})
        _GOOD[suffix] = path.read_bytes()
    return _GOOD[suffix]


damage = st.one_of(
    st.tuples(st.just("truncate"), st.floats(0.0, 1.0)),
    st.tuples(st.just("flip"), st.floats(0.0, 1.0), st.integers(0, 255)),
    st.tuples(st.just("delete_line"), st.floats(0.0, 1.0)),
    st.tuples(st.just("insert"), st.floats(0.0, 1.0), st.text(min_size=1, max_size=12)),
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(suffix=st.sampled_from([".lvm", ".txt"]), hits=st.lists(damage, min_size=1, max_size=3))
@example(suffix=".lvm", hits=[("insert", 0.078125, ":")])     # "Samples 30:" (found by hypothesis)
def test_randomly_damaged_files_either_read_cleanly_or_fail_clearly(tmp_path_factory, suffix, hits):
    """Any damage gives an ExperimentFileError naming the file, or a record that is
    still well formed (finite values, increasing time, Table 2 channels)."""
    data = bytearray(_good_file(tmp_path_factory, suffix))
    for hit in hits:
        pos = int(hit[1] * len(data))
        if hit[0] == "truncate":
            data = data[:pos]
        elif hit[0] == "flip":
            data[min(pos, len(data) - 1):min(pos, len(data) - 1) + 1] = bytes([hit[2]])
        elif hit[0] == "delete_line":
            lines = bytes(data).split(b"\n")
            del lines[min(int(hit[1] * len(lines)), len(lines) - 1)]
            data = bytearray(b"\n".join(lines))
        else:
            data[pos:pos] = hit[2].encode()
    path = tmp_path_factory.mktemp("bad") / f"damaged{suffix}"
    path.write_bytes(bytes(data))
    reads_cleanly_or_fails_clearly(path)
