"""The model: parameters, drives, packing for the kernels, runs, statics, modes."""
