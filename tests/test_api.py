"""``import workbench`` is the API a user calls, resolved on first use."""
import subprocess
import sys
from pathlib import Path

import pytest

import workbench as wb

ROOT = Path(__file__).resolve().parents[1]


def test_every_name_of_the_api_resolves():
    for name in wb.__all__:
        assert getattr(wb, name) is not None, name
    assert set(wb.__all__) <= set(dir(wb))
    assert wb.load_study(ROOT / "studies" / "example.toml").n_points == 2
    with pytest.raises(AttributeError, match="has no attribute 'simulator'"):
        wb.simulator


def test_importing_the_package_loads_no_kernels():
    """The names load on first use: ``import workbench`` does not import numba."""
    code = "import sys, workbench; print('numba' in sys.modules, 'pandas' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
