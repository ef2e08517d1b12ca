"""The unit a user reads for each CGS unit the model computes in, and the factor to it.

The model, its kernels and a run's signals are in CGS (cm, g, s, dyn; strain
as a ratio: docs/model.md); what a user reads is in SI as the field writes it
(N, m/s², µε, mm).  ``workbench.present.units`` applies this table to
figures, tables and reports; the model's own messages use it too.
"""
from __future__ import annotations

#: A CGS unit -> (the unit shown, the factor: shown = factor x CGS).
SI = {"cm": ("mm", 10.0), "cm/s²": ("m/s²", 0.01), "dyn": ("N", 1e-5),
      "strain": ("µε", 1e6), "": ("", 1.0), "g": ("g", 1.0), "N": ("N", 1.0),
      "erg": ("mJ", 1e-4), "cm³": ("mm³", 1e3), "dyn/cm": ("N/mm", 1e-6)}
