"""Loose-joint workbench: a 9-DOF Gibbs-Appell model of a cantilever beam
with a loose bolted lap joint (docs/model.md), compiled with numba.

The API a user calls (docs/usage.md)::

    import workbench as wb

    run = wb.simulate(wb.Parameters().replace(gap_mm=1.016), wb.sine(200.0, 20.0, ramp_s=1.0), 2.0)
    run.summary()

- the model: :class:`Parameters`, :func:`simulate` (a :class:`Run`),
  :func:`static_equilibrium`, :func:`natural_frequencies`, :func:`mode_shapes`,
  :func:`periodic_orbit`;
- the drives: :func:`sine`, :func:`chirp`, :func:`hammer_joint`,
  :func:`hammer_tip` (module :mod:`drives`, the registry of drives);
- studies: :func:`load_study`, :func:`sweep`, :func:`wear_measures`, :func:`advise`;
- lab files: :func:`read`, :func:`write`, :func:`convert`,
  :func:`record_from_run`, :func:`frf`, :func:`compare`.

Everything else stays reachable in the sub-packages (``workbench.core``
the kernels, ``workbench.model``, ``workbench.study``,
``workbench.lab``, ``workbench.identify``, ``workbench.present``).
The names are imported on first use, so ``import workbench`` stays light.
"""
from importlib import import_module

from .model.params import CORK_MODELS, ParameterError, Parameters

__version__ = "0.1.0"

#: Each name of the API and the module that defines it (the name there, if another).
_API = {
    "simulate": ("model.simulate", "simulate"), "Run": ("model.run_result", "Run"),
    "static_equilibrium": ("model.statics", "static_equilibrium"),
    "natural_frequencies": ("model.modes", "natural_frequencies"),
    "mode_shapes": ("model.modes", "mode_shapes"),
    "drives": ("model.drives", None),
    "sine": ("model.drives", "sine"), "chirp": ("model.drives", "chirp"),
    "hammer_joint": ("model.drives", "hammer_joint"),
    "hammer_tip": ("model.drives", "hammer_tip"),
    "load_study": ("study.definition", "load"), "sweep": ("study.sweep", "sweep"),
    "read": ("lab.files", "read"), "write": ("lab.files", "write"),
    "convert": ("lab.files", "convert"),
    "record_from_run": ("lab.files", "record_from_run"),
    "frf": ("lab.frf", "frf"), "compare": ("present.comparison", "compare"),
    "periodic_orbit": ("model.orbit", "periodic_orbit"),
    "wear_measures": ("study.wear", "wear_measures"), "advise": ("study.advice", "advise"),
}

__all__ = ["CORK_MODELS", "ParameterError", "Parameters", "__version__", *_API]


def __getattr__(name):
    if name not in _API:
        raise AttributeError(f"module 'workbench' has no attribute {name!r}")
    module, attr = _API[name]
    value = import_module(f".{module}", __name__)
    value = value if attr is None else getattr(value, attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_API))
