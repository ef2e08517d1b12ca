"""Experiments: record files, matching, comparison, parameter estimation."""
