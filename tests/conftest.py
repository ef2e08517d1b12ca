"""Shared fixtures: parameter sets and random states within physical ranges."""
import os
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

sys.path.insert(0, str(Path(__file__).parent))   # tests/fe_reference.py, small_studies.py

from workbench.model.params import Parameters  # noqa: E402

#: The property tests draw the same examples on every run ("repeatable"), so that the suite
#: that gates a change passes or fails by the code, not by the draw.
#: ``HYPOTHESIS_PROFILE=explore make test`` draws new examples to look for new failures.
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))

#: Typical magnitudes of (w_A, phi_A, u_A, s, v, psi, w_B, phi_B, u_B) for
#: random states: centimetres of deflection, tenths of a radian.
Q_SCALE = np.array([3.0, 0.12, 0.01, 0.1, 0.05, 0.02, 3.0, 0.12, 0.01])
QD_SCALE = np.array([50.0, 2.0, 0.5, 5.0, 5.0, 1.0, 50.0, 2.0, 0.5])


def random_state(rng):
    return np.concatenate([rng.normal(size=9) * Q_SCALE, rng.normal(size=9) * QD_SCALE])


#: The test modules that take 25 s or more (``pytest --durations=0``), longest first.
#: ``make test`` hands each worker process one module at a time in collection order
#: (``--dist loadscope --no-loadscope-reorder``); these go first, so that no long module
#: starts when the other worker is nearly done.
LONG_MODULES = ("test_docs.py", "reference/test_reference_events.py", "study/test_sweep.py",
                "present/test_figure_quality.py", "study/test_sensitivity.py",
                "study/test_wear.py", "lab/test_compare_estimate.py", "lab/test_frf.py")


def pytest_collection_modifyitems(session, config, items):
    """The modules of LONG_MODULES first, in its order; the others as collected."""
    here = Path(__file__).parent

    def rank(item):
        module = Path(str(item.fspath)).relative_to(here).as_posix()
        return LONG_MODULES.index(module) if module in LONG_MODULES else len(LONG_MODULES)
    items.sort(key=rank)


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)


@pytest.fixture(params=[True, False], ids=["tip", "notip"])
def params(request):
    return Parameters(tip_mass=request.param)


def pytest_sessionfinish(session, exitstatus):
    """Fail the run if a kernel was compiled in more than one version
    (a literal or omitted argument, or a test passing other types;
    tests/core/test_compile.py): in this process, and when the suite ran in
    worker processes (``pytest -n``), in the cache they all wrote."""
    from workbench.core.compiler.cache import index_entries, kernel_versions
    extra = {k: n for k, n in kernel_versions().items() if n > 1}
    if not hasattr(session.config, "workerinput"):          # not a worker: the whole run
        extra.update({k: n for k, n in index_entries().items() if n > 1})
    if extra:
        print(f"\nkernels compiled in more than one version: {extra}", file=sys.stderr)
        session.exitstatus = 1
