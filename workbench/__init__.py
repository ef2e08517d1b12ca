"""Loose-joint workbench: a 9-DOF Gibbs-Appell model of a cantilever beam
with a loose bolted lap joint (docs/model.md), compiled with numba."""
from .model.params import CORK_MODELS, ParameterError, Parameters

__version__ = "0.1.0"
__all__ = ["CORK_MODELS", "ParameterError", "Parameters", "__version__"]
