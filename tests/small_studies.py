"""Small study definitions (TOML text) that several test modules sweep."""

#: A sine grid: 2 gaps x 2 frequencies, 0.5 s a point, one point's series kept.
SMALL = """
[study]
name = "small"
duration_s = 0.5
window_s = 0.2
save_series = [{gap_mm = 1.016, freq_hz = 20.0}]

[excitation]
drive = "sine"
force_n = 20.0
ramp_s = 0.1

[axes]
gap_mm = [0.508, 1.016]
freq_hz = [20.0, 30.0]
"""

#: A 5-65 Hz chirp of 1 s at one gap, its series kept.
CHIRP = """
[study]
name = "chirp"
duration_s = 1.0
window_s = 0.5
save_series = [{gap_mm = 1.016}]

[excitation]
drive = "chirp"
f0_hz = 5.0
f1_hz = 65.0
sweep_s = 1.0

[axes]
gap_mm = [1.016]
"""

#: A damage map in miniature: 2 gaps x 3 frequencies x 2 levels, 1.2 s a point.
DAMAGE = """
[study]
name = "damage"
duration_s = 1.2
window_s = 0.5

[excitation]
drive = "sine"
ramp_s = 0.3

[wear]
threshold_mm3 = 1e-7

[axes]
gap_mm = [0.508, 1.016]
freq_hz = [15.0, 30.0, 45.0]
force_n = [20.0, 100.0]
"""
