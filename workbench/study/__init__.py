"""Studies: definitions, grids, sweeps, stored results, metrics, provenance."""
