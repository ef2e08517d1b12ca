"""The paper's raw identification inputs and its printed results (seed §4, Tables 3-6, Appendix B).

Printed values are kept as the strings the paper prints, so a reproduction
can be compared to the printed digits (:func:`same_digits`).
"""
from __future__ import annotations

import math

from ..model.params import BAR_WIDTH_CM  # noqa: F401  (b of Eq. 1, kept with the model)

#: The beam bar, 2 in x 1/8 in (cm): height h of Eq. 1 (its width b is BAR_WIDTH_CM).
BAR_HEIGHT_CM = 0.3175

#: Table 3 (§4.1): density (g/cm^3), rigid masses (g), mass per length (g/cm).
TABLE3 = {"density": "2.5065", "mass_3": "313.81", "mass_4": "123.33", "mass_6": "158.9",
          "mu_2": "4.0428", "mu_5": "4.0428"}

#: §4.2: section 3's inertia about its centre of mass (g cm^2) and the distance
#: from the centre of mass to the section's origin (cm).
SECTION3_I_CM = 6973.4
SECTION3_CM_DISTANCE = 7.559
#: Table 4: inertia about the origin (g cm^2) and inertia per length (g cm).
TABLE4 = {"inertia_3": "24904", "inertia_4": "1398.60", "inertia_6": "301.55",
          "rho_i_2": "0.03396", "rho_i_5": "0.03396"}

#: Table 5: applied load (g cm/s^2), pre-load gap (cm), load gap (cm), and the
#: printed stiffness (g/s^2).
TABLE5 = [(3.14e6, 0.71, 0.635, "4.19e7"),
          (4.12e6, 0.77, 0.585, "2.23e7"),
          (3.92e6, 0.635, 0.58, "7.13e7")]
#: docs/model.md §6's static cork: the mean of Table 5 (g/s^2).
TABLE5_MEAN = "4.52e7"

#: Table 6: test, law, stiffness (g/(s^2 cm^(n-1))), damping (g/s).
TABLE6 = [("DE-1", "linear", "2.70e5", "1.10e4"),
          ("DE-2", "linear", "2.70e5", "9.50e3"),
          ("DE-3", "linear", "4.83e5", "1.75e4"),
          ("DE-K~x^2", "quadratic", "6.00e4", "2.00e4"),
          ("DE-K~x^3", "cubic", "1.00e4", "2.20e4")]
#: The damping the paper uses, "an average of the different values found" (g/s).
TABLE6_DAMPING_USED = "1.7e4"

#: Appendix B: beam, trial, (x1 V, xn V, t1 s, tn s, n) and the printed
#: (Td s, zeta, omega_n rad/s, EI g cm^3/s^2, E GPa).
APPENDIX_B = [
    (1, 1, (0.4499, 0.03836, 0.536, 3.238, 47), ("0.057489", "0.0085", "109.298", "6.862e9", "50.65")),
    (1, 2, (0.284, 0.03186, 0.885, 3.821, 51), ("0.057569", "0.006963", "109.144", "6.843e9", "50.51")),
    (1, 3, (0.2653, 0.02939, 0.935, 3.935, 52), ("0.057692", "0.006866", "108.912", "6.814e9", "50.29")),
    (2, 1, (0.3773, 0.02629, 0.901, 3.939, 62), ("0.049", "0.00695", "128.231", "6.269e9", "46.27")),
    (2, 2, (0.325, 0.01605, 1.826, 5.855, 82), ("0.049134", "0.00591", "127.881", "6.235e9", "46.02")),
    (2, 3, (0.4444, 0.02866, 0.864, 3.958, 63), ("0.049111", "0.007037", "127.942", "6.241e9", "46.06")),
]
#: §4.4: "The computed average moduli of elasticity for the first and second
#: are 50.48 GPa and 46.12 GPa".
APPENDIX_B_MEAN_E_GPA = {1: "50.48", 2: "46.12"}
#: The beams' lengths are not printed; docs/model.md §2 infers them from
#: Appendix B (ASSUMPTION): cm, by beam.
BEAM_LENGTH_CM = {1: 36.671, 2: 33.099}

#: §4.4 strain-patch scale factors (strain per volt); the calibration records
#: are not published, so these are quoted, not reproduced.
PATCH_SCALE = {"strain1": "9e-5", "strain2": "1.77e-5"}


def format_like(value: float, printed: str) -> str:
    """``value`` written with the digits of ``printed``: as many decimals, or for
    "6.862e9" as many significant digits in the same exponent form."""
    if not math.isfinite(value):
        return str(value)
    text = printed.lower()
    if "e" in text:
        mantissa, exponent = text.split("e")
        decimals = len(mantissa.partition(".")[2])
        scaled = value / 10.0 ** int(exponent)
        return f"{scaled:.{decimals}f}e{int(exponent)}"
    return f"{value:.{len(text.partition('.')[2])}f}"


def same_digits(value: float, printed: str) -> bool:
    """Whether ``value`` rounds to the digits the paper printed."""
    return format_like(value, printed) == format_like(float(printed), printed)
