"""Mass and inertia of the sections (seed §4.1-4.2, Tables 3-4).

    >>> round(parallel_axis(6973.4, 313.81, 7.559))        # Table 4, section 3
    24904
    >>> round(rotary_inertia_per_length(2.5065, 5.08, 0.3175), 5)   # Table 4, sections 2, 5
    0.03396
"""
from __future__ import annotations

from ..model.params import check_positive


def parallel_axis(i_cm: float, mass: float, distance: float) -> float:
    """Inertia about a parallel axis, I_o = I_cm + m d^2 (g cm^2; §4.2).

    ``i_cm`` (g cm^2) about the centre of mass, ``mass`` (g), ``distance``
    (cm) from the centre of mass to the new axis.
    """
    check_positive("i_cm", i_cm, "g cm^2", allow_zero=True)
    check_positive("mass", mass, "g")
    check_positive("distance", abs(distance), "cm", allow_zero=True)
    return i_cm + mass * distance ** 2


def area_moment(width: float, height: float) -> float:
    """Second moment of a rectangle about its neutral axis, I = b h^3 / 12 (cm^4; Eq. 1).

    ``height`` (cm) is the dimension across the bending plane (the 1/8 in
    thickness of the bar), ``width`` (cm) the other one.
    """
    return check_positive("width", width, "cm") * check_positive("height", height, "cm") ** 3 / 12.0


def rotary_inertia_per_length(density: float, width: float, height: float) -> float:
    """rho I, the beam's rotary inertia per length (g cm; Table 4 from Eq. 1)."""
    return check_positive("density", density, "g/cm^3") * area_moment(width, height)


def mass_per_length(density: float, width: float, height: float) -> float:
    """rho b h (g/cm): Table 3's mass per length as density times cross-section.

    The paper weighed the beams instead (§4.1); this is the cross-check.
    """
    return check_positive("density", density, "g/cm^3") * check_positive("width", width, "cm") \
        * check_positive("height", height, "cm")
