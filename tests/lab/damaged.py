"""The check of a damaged file shared by the format tests."""
import numpy as np

from workbench.lab import files as F


def reads_cleanly_or_fails_clearly(path) -> None:
    """An ExperimentFileError naming the file, or a well-formed record (finite values,
    increasing time, Table 2 channels)."""
    try:
        rec = F.read(path)
    except F.ExperimentFileError as err:
        assert str(path) in str(err) and err.problem
        return
    assert len(rec) >= 2 and set(rec.columns) <= set(F.CHANNELS)
    assert np.all(np.isfinite(rec.to_numpy())) and np.all(np.diff(rec.index.to_numpy()) > 0)
