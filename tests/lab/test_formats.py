"""Every file format: a simulated run written and read back (channels, units, time base,
settings), conversions between any two, what the UFF and TDMS files hold for other
software, and damaged files that end in a clear ExperimentFileError."""
import itertools

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from workbench import cli
from workbench.lab import files as F

from damaged import reads_cleanly_or_fails_clearly
from workbench.lab.formats import uff
from workbench.lab.matching import settings_of, setup_from
from workbench.model.params import Parameters

SUFFIXES = {"lvm": ".lvm", "text": ".txt", "tdms": ".tdms", "uff": ".uff", "parquet": ".parquet"}
#: Digits each format keeps: the text formats write 10 significant digits, UFF 12.
RTOL = {"lvm": 1e-9, "text": 1e-9, "tdms": 0.0, "uff": 1e-10, "parquet": 0.0}
DRIVE = {"drive": "sine", "force_n": 120.0, "freq_hz": 25.0, "ramp_s": 0.1}
PARAMS = Parameters().replace(gap_mm=0.635, tip_mass=False, cork="linear")


@pytest.fixture(scope="module")
def simulated():
    """A 0.4 s simulated shaker run's record and the settings it is written with."""
    t = pd.DataFrame(index=pd.Index(np.arange(401) / 1000.0, name="t"))
    meta = settings_of(DRIVE, PARAMS)
    run = setup_from(meta, t).simulate()
    assert run.ok
    return F.record_from_run(run), meta


def _same(back, rec, meta, fmt):
    assert list(back.columns) == list(rec.columns)
    scale = np.maximum(np.abs(rec.to_numpy()).max(axis=0), 1e-300)     # per channel
    np.testing.assert_allclose(back.to_numpy() / scale, rec.to_numpy() / scale,
                               rtol=RTOL[fmt], atol=1e-9)
    np.testing.assert_allclose(back.index.to_numpy(), rec.index.to_numpy(), rtol=1e-12, atol=1e-12)
    assert back.attrs["meta"] == meta and back.attrs["units_assumed"] == []


@pytest.mark.parametrize("fmt", list(SUFFIXES))
def test_a_simulated_run_comes_back_from_every_format(simulated, tmp_path, fmt):
    rec, meta = simulated
    path = F.write(tmp_path / f"run{SUFFIXES[fmt]}", rec, meta)
    back = F.read(path)
    _same(back, rec, meta, fmt)
    assert setup_from(back.attrs["meta"], back).params == PARAMS    # the settings re-make the run


def test_conversions_between_any_two_formats_keep_the_record(simulated, tmp_path):
    rec, meta = simulated
    for a, b in itertools.permutations(SUFFIXES, 2):
        source = F.write(tmp_path / f"a{SUFFIXES[a]}", rec, meta)
        back = F.convert(source, tmp_path / f"{a}_to_{b}{SUFFIXES[b]}")
        _same(F.read(tmp_path / f"{a}_to_{b}{SUFFIXES[b]}"), back, meta, b)
        _same(back, rec, meta, a)


def test_the_format_can_be_named_instead_of_the_suffix(simulated, tmp_path):
    rec, meta = simulated
    path = F.write(tmp_path / "run.dat", rec, meta, format="lvm")
    assert path.read_text().startswith("LabVIEW Measurement")
    _same(F.read(path, format="lvm"), rec, meta, "lvm")
    with pytest.raises(F.ExperimentFileError, match="unknown file type '.xyz'"):
        F.read(tmp_path / "run.xyz")
    with pytest.raises(F.ExperimentFileError, match="format 'csv': allowed lvm, text"):
        F.read(path, format="csv")


def test_uff_holds_header_units_sensor_nodes_and_time_histories(simulated, tmp_path):
    """Other modal software reads the nodes (dataset 2411, m) at Table 2's positions and
    one dataset 58 per sensor with its node, direction, data type and unit."""
    import pyuff

    rec, meta = simulated
    sets = pyuff.UFF(str(F.write(tmp_path / "run.uff", rec, meta))).read_sets()
    assert [s["type"] for s in sets] == [151, 164, 2411] + [58] * 10
    assert sets[1]["units_code"] == 1                            # SI
    nodes = sets[2]
    where = uff.sensor_positions(PARAMS)
    for c in F.CHANNELS:
        i = list(nodes["node_nums"]).index(uff.NODES[c])
        assert (nodes["x"][i], nodes["y"][i]) == pytest.approx(where[c][:2], abs=1e-12)
    # MODEL.md §9: force1 13.2 cm on beam A, accel3 28.4 cm on beam B from its root
    p = PARAMS
    assert where["force1"][0] == pytest.approx(0.132)
    assert where["accel3"][0] == pytest.approx((p.l_a + p.x_in + p.l4 + 28.4) / 100.0)
    for s, c in zip(sets[3:], F.CHANNELS):
        assert s["id1"] == F.TABLE2_NAMES[c] and s["func_type"] == 1
        assert (s["rsp_node"], s["rsp_dir"]) == (uff.NODES[c], uff.DIRECTIONS[F.kind(c)])
        assert (s["ref_node"], s["ref_dir"]) == (uff.NODES["force1"], 2)
        assert s["ordinate_spec_data_type"] == uff.ORDINATE[F.kind(c)]
        assert s["ordinate_axis_units_lab"] == F.DEFAULT_UNITS[F.kind(c)]
        assert s["abscissa_spec_data_type"] == 17 and s["abscissa_spacing"] == 1


def test_uff_frfs_are_function_type_4_in_si(tmp_path):
    import pyuff

    f = np.arange(0, 51) * 0.5
    h = (1.0 + 0.5j) * np.ones_like(f)                # (cm/s^2) / dyn
    table = pd.DataFrame({"accel3_H1": h, "accel3_H2": h, "accel3_coherence": np.ones_like(f)},
                         index=pd.Index(f, name="f_hz"))
    path = uff.write_frf(tmp_path / "frf.uff", table, ["accel3"], meta={"drive": "chirp"})
    frf = pyuff.UFF(str(path)).read_sets()[-1]
    assert frf["func_type"] == 4 and frf["abscissa_spec_data_type"] == 18
    assert (frf["rsp_node"], frf["ref_node"]) == (uff.NODES["accel3"], uff.NODES["force1"])
    np.testing.assert_allclose(frf["x"], f)
    np.testing.assert_allclose(frf["data"], h * 1e5 / 100.0)   # (m/s^2) / N


def test_tdms_as_a_daq_writes_it(tmp_path):
    """A DAQmx-style file: units in NI_UnitDescription (lbf, g), a second group without
    Table 2 channels, a Time channel instead of waveform timing."""
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    t = np.arange(100) * 2e-4
    path = tmp_path / "daq.tdms"
    with TdmsWriter(str(path)) as w:
        w.write_segment([RootObject({"WB_drive": "sine", "WB_freq_hz": 20.0, "operator": "x"}),
                         GroupObject("Notes"), ChannelObject("Notes", "Temperature", np.ones(3)),
                         ChannelObject("Shaker test", "Time", t, {"unit_string": "s"}),
                         ChannelObject("Shaker test", "Force 1", np.sin(t),
                                       {"NI_UnitDescription": "lbf"}),
                         ChannelObject("Shaker test", "accel_3", np.cos(t),
                                       {"NI_UnitDescription": "g"})])
    rec = F.read(path)
    assert list(rec.columns) == ["force1", "accel3"]
    np.testing.assert_allclose(rec.index.to_numpy(), t)
    np.testing.assert_allclose(rec.force1, np.sin(t) * 4.4482216e5)
    np.testing.assert_allclose(rec.accel3, np.cos(t) * 980.665)
    assert rec.attrs["meta"] == {"drive": "sine", "freq_hz": 20.0}


@pytest.mark.parametrize("objects, problem", [
    (lambda C: [C("G", "Force1", np.ones(5), {"wf_increment": 1e-3}),
                C("G", "Accel9", np.ones(5), {"wf_increment": 1e-3})], "unknown channel 'Accel9'"),
    (lambda C: [C("G", "Force1", np.ones(5), {"wf_increment": 1e-3}),
                C("G", "Accel1", np.ones(4), {"wf_increment": 1e-3})], "differ in length"),
    (lambda C: [C("G", "Force1", np.ones(5))], "no time base"),
    (lambda C: [C("G", "Force1", np.ones(5), {"wf_increment": 1e-3, "unit_string": "furlong"})],
     "unit 'furlong'"),
    (lambda C: [C("G", "Force1", np.array([1.0, np.nan]), {"wf_increment": 1e-3})], "not finite"),
    (lambda C: [C("A", "Force1", np.ones(5), {"wf_increment": 1e-3}),
                C("B", "Accel1", np.ones(5), {"wf_increment": 1e-3})], "2 groups hold"),
])
def test_a_tdms_file_it_cannot_use_is_refused_clearly(tmp_path, objects, problem):
    from nptdms import ChannelObject, TdmsWriter

    path = tmp_path / "bad.tdms"
    with TdmsWriter(str(path)) as w:
        w.write_segment(objects(ChannelObject))
    with pytest.raises(F.ExperimentFileError, match=problem) as err:
        F.read(path)
    assert err.value.path == str(path)


def test_a_truncated_tdms_file_is_refused_not_read_short(simulated, tmp_path, capsys):
    """npTDMS reads on past a truncated segment with a warning: the reader refuses it,
    and the warning is not printed."""
    rec, meta = simulated
    data = F.write(tmp_path / "run.tdms", rec, meta).read_bytes()
    (tmp_path / "cut.tdms").write_bytes(data[:-1000])
    with pytest.raises(F.ExperimentFileError, match="damaged or truncated TDMS file"):
        F.read(tmp_path / "cut.tdms")
    assert "nptdms" not in capsys.readouterr().err


def test_values_out_of_range_in_cgs_are_refused(tmp_path):
    path = tmp_path / "huge.txt"
    path.write_text("Time\tForce1 (kN)\n0\t1e300\n0.001\t2e300\n")
    with pytest.raises(F.ExperimentFileError, match="Force1: values that are not finite, or out of range"):
        F.read(path)


def test_a_uff_file_without_time_histories_or_with_ragged_ones_is_refused(simulated, tmp_path):
    rec, meta = simulated
    uff.write_frf(tmp_path / "frf_only.uff", pd.DataFrame(
        {"accel3_H1": np.ones(4, complex)}, index=pd.Index(np.arange(4.0))), ["accel3"])
    with pytest.raises(F.ExperimentFileError, match="no time history"):
        F.read(tmp_path / "frf_only.uff")
    text = F.write(tmp_path / "run.uff", rec, meta).read_text()
    cut = text.rindex("    -1\n    -1\n")          # the last record loses its data lines
    damaged = text[:cut].rsplit("\n", 40)[0] + "\n    -1\n"
    (tmp_path / "cut.uff").write_text(damaged)
    with pytest.raises(F.ExperimentFileError):
        F.read(tmp_path / "cut.uff")


def test_settings_too_long_for_uff_are_refused_before_writing(simulated, tmp_path):
    rec, _ = simulated
    with pytest.raises(F.ExperimentFileError, match="one word"):
        F.write(tmp_path / "x.uff", rec, {"note": "two words"})
    with pytest.raises(F.ExperimentFileError, match="the settings need"):
        F.check_settings(tmp_path / "x.uff", {f"k{i}": "v" * 70 for i in range(30)})
    assert not (tmp_path / "x.uff").exists()


_GOOD = {}


def _good_bytes(tmp_path_factory, fmt):
    if fmt not in _GOOD:
        t = np.arange(40) * 1e-3
        rec = pd.DataFrame({"force1": np.sin(t * 50) * 1e6, "accel3": np.cos(t * 50) * 100.0},
                           index=pd.Index(t, name="t"))
        path = tmp_path_factory.mktemp("good") / f"good{SUFFIXES[fmt]}"
        F.write(path, rec, {"drive": "sine", "freq_hz": 20.0})
        _GOOD[fmt] = path.read_bytes()
    return _GOOD[fmt]


@settings(max_examples=120, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(fmt=st.sampled_from(["tdms", "uff", "parquet"]), cut=st.floats(0.0, 1.0),
       flips=st.lists(st.tuples(st.floats(0.0, 1.0), st.integers(0, 255)), max_size=3))
def test_damaged_binary_and_uff_files_read_cleanly_or_fail_clearly(tmp_path_factory, fmt, cut,
                                                                  flips):
    data = bytearray(_good_bytes(tmp_path_factory, fmt))
    for where, byte in flips:
        data[min(int(where * len(data)), len(data) - 1)] = byte
    data = data[:max(1, int(cut * len(data)))] if cut < 0.999 else data
    path = tmp_path_factory.mktemp("bad") / f"damaged{SUFFIXES[fmt]}"
    path.write_bytes(bytes(data))
    reads_cleanly_or_fails_clearly(path)


def test_run_out_writes_by_suffix_and_convert_and_compare_read_it(tmp_path, capsys):
    out = tmp_path / "run.uff"
    assert cli.main(["run", "--duration", "0.3", "--freq-hz", "25", "--gap-mm", "0.635",
                     "--tip-mass", "off", "--out", str(out), "--json"]) == 0
    rec = F.read(out)
    assert rec.attrs["meta"]["drive"] == "sine" and rec.attrs["meta"]["tip_mass"] is False
    assert cli.main(["convert", str(out), str(tmp_path / "run.tdms")]) == 0
    assert cli.main(["compare", str(tmp_path / "run.tdms"), "--out", str(tmp_path / "cmp")]) == 0
    signals = pd.read_csv(tmp_path / "cmp" / "differences_signals.csv")
    assert signals.rms_error_rel.max() < 1e-6        # the file re-makes the same run
    capsys.readouterr()
    code = cli.main(["run", "--duration", "0.3", "--out", str(tmp_path / "run.xyz")])
    assert code == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "--out" in err and "run.xyz: the suffix must be one of .lvm" in err
    assert not (tmp_path / "run.xyz").exists()
    assert cli.main(["convert", str(out), str(out)]) == cli.EXIT_BAD_INPUT
    assert "is the SOURCE" in capsys.readouterr().err
