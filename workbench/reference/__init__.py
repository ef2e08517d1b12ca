"""The slow reference: the same equations in NumPy, the paper's solver with restarts.

:mod:`.equations` the free-flight equations on jets (docs/model.md §4-6);
:mod:`.events` the contact regimes, events and transitions (docs/model.md §7)
integrated regime by regime with scipy's solve_ivp (LSODA, the paper's
method, or another).  Used by the tests to check the kernels and by the
benchmarks as the baseline; never by the workbench's own runs.
"""
from .equations import Reference, shaker
from .events import HybridReference, Regime, ReferenceRun

__all__ = ["HybridReference", "Reference", "ReferenceRun", "Regime", "shaker"]
