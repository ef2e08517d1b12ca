"""Every physical parameter of the model, with its source (docs/model.md §2, §6).

Units are CGS inside (g, cm, s; force in dyn, E in g/(cm s^2)).  At the user
boundary a parameter may also be given with a unit suffix, converted once
here: ``gap_mm=0.762``, ``l4_mm=116.7``, ``e_a_gpa=50.48``.

Numbers marked ASSUMPTION are inferences of docs/model.md (the paper's drawing was
lost); they are ordinary, overridable parameters, flagged in
:data:`FIELDS` and in ``workbench params``.

Example::

    >>> from workbench.model.params import Parameters
    >>> p = Parameters(cork="linear").replace(gap_mm=0.508)
    >>> round(p.gap, 4)
    0.0508
"""
from __future__ import annotations

import dataclasses
import difflib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

class CorkLaw(NamedTuple):
    """A cork law (docs/model.md §6): the spring's form (a name of
    :data:`workbench.core.cork.FORMS`) with its shape parameter n and stiffness
    k, and the damper c (g/s).  The power form is k sign(s)|s|^n, k in
    g/(s^2 cm^(n-1))."""

    n: float
    k: float
    c: float
    form: str = "power"


#: Cork models of docs/model.md §6 (seed §4.3, Tables 5-6).  c = 1.7e4 g/s is
#: the paper's average.  A law of a new form is an entry here and its form in
#: workbench/core/cork.py.
CORK_MODELS: dict[str, CorkLaw] = {
    "none": CorkLaw(1.0, 0.0, 0.0),
    "linear": CorkLaw(1.0, 2.70e5, 1.7e4),      # Table 6, DE-1/DE-2
    "quadratic": CorkLaw(2.0, 6.0e4, 1.7e4),    # Table 6, DE-K~x^2
    "cubic": CorkLaw(3.0, 1.0e4, 1.7e4),        # Table 6, DE-K~x^3: the paper's choice
    "static": CorkLaw(1.0, 4.52e7, 1.7e4),      # mean of Table 5's static compression
}

#: The paper's gaps (mm), seed §5.1.
PAPER_GAPS_MM = (0.508, 0.635, 0.762, 1.016)
#: The beam bar's width, 2 in (cm; §4.1): out of the model's plane, the length of a contact
#: line across the bar, and b of the sections' b h^3 / 12 (identify.paper).
BAR_WIDTH_CM = 5.08

#: Unit suffixes accepted at the user boundary: suffix -> (CGS unit it
#: converts to, factor to multiply by).
USER_UNITS = {
    "_mm": ("cm", 0.1),
    "_gpa": ("g/(cm s^2)", 1.0e10),
}


class ParameterError(ValueError):
    """A parameter is unknown, missing, or outside its allowed range."""


def _p(default, unit, source, lo=None, hi=None, lo_open=True, hi_open=False,
       assumption=False, doc="", allow_inf=False):
    """A parameter field with its metadata (unit, source, allowed range; +inf if allow_inf)."""
    return field(default=default, metadata=dict(
        unit=unit, source=source, lo=lo, hi=hi, lo_open=lo_open,
        hi_open=hi_open, assumption=assumption, doc=doc, allow_inf=allow_inf))


@dataclass(frozen=True)
class Parameters:
    """The loose-joint beam's parameters (CGS).  Validated on construction."""

    # --- elastic beams (sections 2 and 5) ----------------------------------
    rho: float = _p(2.5065, "g/cm^3", "Table 3", 0.0, doc="density of the aluminium")
    mu_a: float = _p(4.0428, "g/cm", "Table 3", 0.0, doc="beam A mass per length")
    mu_b: float = _p(4.0428, "g/cm", "Table 3", 0.0, doc="beam B mass per length")
    rho_i_a: float = _p(0.03396, "g cm", "Table 4", 0.0, doc="beam A rotary inertia per length")
    rho_i_b: float = _p(0.03396, "g cm", "Table 4", 0.0, doc="beam B rotary inertia per length")
    e_a: float = _p(7.0e11, "g/(cm s^2)", "§4.4 'standard values' (identified: 5.048e11)", 0.0,
                    doc="beam A Young's modulus")
    e_b: float = _p(7.0e11, "g/(cm s^2)", "§4.4 'standard values' (identified: 4.612e11)", 0.0,
                    doc="beam B Young's modulus")
    l_a: float = _p(36.671, "cm", "Appendix B: L from EI = 11 mu wn^2 L^4 / 140", 0.0,
                    assumption=True, doc="beam A length")
    l_b: float = _p(33.099, "cm", "Appendix B, beam 2 rows, same derivation", 0.0,
                    assumption=True, doc="beam B length")
    zeta_a: float = _p(0.0074, "-", "Appendix B, mean of beam 1", 0.0, 1.0, lo_open=False,
                       hi_open=True, doc="beam A damping ratio of its first mode")
    zeta_b: float = _p(0.0066, "-", "Appendix B, mean of beam 2", 0.0, 1.0, lo_open=False,
                       hi_open=True, doc="beam B damping ratio of its first mode")
    c_strain: float = _p(0.15875, "cm", "h/2 of the 1/8 in bar", 0.0,
                         doc="distance from the neutral axis to the strain patch")
    # --- joint body (section 3) -------------------------------------------
    m3: float = _p(313.81, "g", "Table 3", 0.0, doc="joint body mass")
    i3: float = _p(6973.4, "g cm^2", "§4.2 (24904 about the origin, Table 4)", 0.0,
                   doc="joint body inertia about its CM")
    c3: float = _p(7.559, "cm", "§4.2", 0.0, lo_open=False,
                   doc="joint body CM along the joint axis")
    x_in: float = _p(8.3, "cm", "Table 2: contact1, contact2", 0.0,
                     doc="loose body's inner end (contacts 1, 2) along the joint axis")
    x_lip: float = _p(14.5, "cm", "Table 2: contact3, contact4", 0.0,
                      doc="plate lips (contacts 3, 4) along the joint axis")
    # --- loose body (section 4) -------------------------------------------
    m4: float = _p(123.33, "g", "Table 3", 0.0, doc="loose body mass")
    i4: float = _p(1398.6, "g cm^2", "Table 4", 0.0, doc="loose body inertia about its CM")
    l4: float = _p(11.67, "cm", "uniform rod: sqrt(12 I4 / m4)", 0.0, assumption=True,
                   doc="loose body length, inner end to beam B's root")
    c4: float | None = _p(None, "cm", "l4 / 2 (uniform rod)", 0.0, lo_open=False,
                          assumption=True, doc="loose body CM from its inner end (None: l4/2)")
    h4: float = _p(0.3175, "cm", "1/8 in bar", 0.0, assumption=True,
                   doc="loose body thickness at the contacts")
    gap: float = _p(0.1016, "cm", "§5.1: 0.508, 0.635, 0.762, 1.016 mm", 0.0, 0.5,
                    assumption=True, doc="total transverse clearance, centred at rest")
    # --- tip mass (section 6) ---------------------------------------------
    m6: float = _p(158.9, "g", "Table 3 (the text says 152 g)", 0.0, doc="tip mass")
    i6: float = _p(301.55, "g cm^2", "Table 4", 0.0, doc="tip mass inertia about its CM")
    tip_mass: bool = _p(True, "-", "§5.2-5.3: tests with and without", doc="tip mass attached")
    # --- contact ------------------------------------------------------------
    mu_s: float = _p(0.3, "-", "the paper gives none", 0.0, 5.0, lo_open=False,
                     assumption=True, doc="static friction coefficient")
    mu_k: float = _p(0.3, "-", "the paper gives none", 0.0, 5.0, lo_open=False,
                     assumption=True, doc="kinetic friction coefficient (<= mu_s)")
    # --- cork (docs/model.md §6) -------------------------------------------------
    cork: str = _p("cubic", "-", "§4.3: the cubic model gave the best agreement",
                   doc="cork model: " + ", ".join(CORK_MODELS))
    cork_n: float | None = _p(None, "-", "from the cork model", 1.0, 5.0, lo_open=False,
                              doc="override of the cork law's shape parameter (the power law's exponent)")
    cork_k: float | None = _p(None, "g/(s^2 cm^(n-1))", "from the cork model", 0.0,
                              lo_open=False, doc="override of the cork stiffness")
    cork_c: float | None = _p(None, "g/s", "from the cork model", 0.0, lo_open=False,
                              doc="override of the cork damping")
    s_travel: float = _p(0.705, "cm", "Table 5: mean pre-load gap (0.71, 0.77, 0.635 cm)", 0.0,
                         assumption=True, allow_inf=True,
                         doc="slide s before the cork bottoms out in the slot, each way "
                             "(inf: the paper's unbounded slide)")
    k_stop: float = _p(4.52e7, "g/s^2", "Table 5: static stiffness of the compressed cork", 0.0,
                       lo_open=False, assumption=True,
                       doc="stiffness of the slot's end stop beyond |s| > s_travel")
    # --- extensions of the workbench (not in the paper) ---------------------
    k_v: float = _p(0.0, "g/s^2", "workbench: 0 in the paper's model", 0.0, lo_open=False,
                    doc="optional spring holding the loose body across the gap")
    k_psi: float = _p(0.0, "g cm^2/s^2", "workbench: 0 in the paper's model", 0.0,
                      lo_open=False, doc="optional spring holding the loose body's rotation")
    g: float = _p(981.0, "cm/s^2", "standard gravity", 0.0, lo_open=False,
                  doc="gravitational acceleration")
    n_gauss: int = _p(6, "-", "6 points integrate the beams exactly", 5, 20, lo_open=False,
                      doc="Gauss-Legendre points per beam")
    # --- sensor positions (Table 2: from the start of each section) ---------
    x_force: float = _p(13.2, "cm", "Table 2: force1, section 2", 0.0, doc="shaker on beam A")
    x_strain1: float = _p(21.9, "cm", "Table 2: strain1, section 2", 0.0, lo_open=False,
                          doc="strain1 on beam A")
    x_accel1: float = _p(4.4, "cm", "Table 2: accel1, section 3", 0.0, lo_open=False,
                         doc="accel1 on the joint body")
    x_accel2: float = _p(10.5, "cm", "Table 2: accel2, section 4", 0.0, lo_open=False,
                         doc="accel2 on the loose body, from its inner end")
    x_strain2: float = _p(13.4, "cm", "Table 2: strain2, section 5", 0.0, lo_open=False,
                          doc="strain2 on beam B")
    x_accel3: float = _p(28.4, "cm", "Table 2: accel3, section 5", 0.0, lo_open=False,
                         doc="accel3 on beam B")

    def __post_init__(self):
        _validate(self)

    # --- derived quantities -------------------------------------------------
    @property
    def area_a(self) -> float:
        """Beam A cross-section A = mu / rho (cm^2)."""
        return self.mu_a / self.rho

    @property
    def area_b(self) -> float:
        """Beam B cross-section (cm^2)."""
        return self.mu_b / self.rho

    @property
    def inertia_a(self) -> float:
        """Beam A area moment I = rho I / rho (cm^4); b h^3/12 for 2 in x 1/8 in."""
        return self.rho_i_a / self.rho

    @property
    def inertia_b(self) -> float:
        """Beam B area moment (cm^4)."""
        return self.rho_i_b / self.rho

    @property
    def loose_cm(self) -> float:
        """Loose body CM from its inner end (cm): c4, or l4/2 when not given."""
        return self.l4 / 2.0 if self.c4 is None else self.c4

    @property
    def cork_law(self) -> CorkLaw:
        """The cork's law: the model's values with any override of n, k and c."""
        n, k, c, form = CorkLaw(*CORK_MODELS[self.cork])
        return CorkLaw(n if self.cork_n is None else self.cork_n,
                       k if self.cork_k is None else self.cork_k,
                       c if self.cork_c is None else self.cork_c, form)

    def first_frequency(self, beam: str) -> float:
        """A beam's own first clamped-free frequency (rad/s): 3.516/L^2 sqrt(EI/mu)."""
        L, e, inertia, mu = self.beam(beam)
        return 3.516 / L ** 2 * math.sqrt(e * inertia / mu)

    def damping_beta(self, beam: str) -> float:
        """Bending damping C_b = beta K_b: beta = 2 zeta / omega_1 (s), docs/model.md §5."""
        zeta = self.zeta_a if beam == "a" else self.zeta_b
        return 2.0 * zeta / self.first_frequency(beam)

    def axial_mass(self, beam: str) -> float:
        """Mass (g) on a beam's tip elongation u at rest: M(0)[u, u] of docs/model.md §5.

        The beam's own mu L / 3 (u(x) = xi u_tip) plus every body carried
        outboard along the axis: for beam A the joint body, the loose body,
        beam B and the tip mass; for beam B the tip mass.
        """
        tip = self.m6 if self.tip_mass else 0.0
        if beam == "a":
            return self.mu_a * self.l_a / 3.0 + self.m3 + self.m4 + self.mu_b * self.l_b + tip
        return self.mu_b * self.l_b / 3.0 + tip

    def axial_damping(self, beam: str) -> float:
        """Damping (g/s) on a beam's tip elongation u, docs/model.md §5 (ASSUMPTION).

        c = 2 zeta sqrt(k m): the axial coordinate's own mode (stiffness
        EA/L, mass :meth:`axial_mass`) gets the beam's bending zeta.  Its
        frequency is the coordinate's own, sqrt(EA/L / m): with the tip mass
        1.0 kHz (beam A) and 2.1 kHz (beam B), without it 1.1 and 4.4 kHz.
        """
        L, e, _, mu = self.beam(beam)
        zeta = self.zeta_a if beam == "a" else self.zeta_b
        k = e * (mu / self.rho) / L
        return 2.0 * zeta * math.sqrt(k * self.axial_mass(beam))

    def beam(self, beam: str) -> tuple[float, float, float, float]:
        """Beam "a" or "b": length (cm), E (g/(cm s^2)), area moment (cm^4), mass per length (g/cm)."""
        if beam == "a":
            return self.l_a, self.e_a, self.inertia_a, self.mu_a
        if beam == "b":
            return self.l_b, self.e_b, self.inertia_b, self.mu_b
        raise ParameterError(f"beam must be 'a' or 'b', got {beam!r}")

    # --- construction from user input ----------------------------------------
    def replace(self, **changes: Any) -> "Parameters":
        """A copy with some parameters changed (unit-suffixed names accepted)."""
        return dataclasses.replace(self, **_to_cgs(changes))

    @classmethod
    def from_user(cls, values: dict[str, Any]) -> "Parameters":
        """Parameters from a mapping of names (CGS or unit-suffixed) to values."""
        return cls(**_to_cgs(values))

    @classmethod
    def from_toml(cls, path: str | Path) -> "Parameters":
        """Parameters from a TOML file: top-level keys or a ``[model]`` table."""
        path = Path(path)
        data = read_toml(path)
        if "model" in data:
            extra = sorted(set(data) - {"model"})
            if extra:
                raise ParameterError(f"{path}: keys outside [model]: {extra}")
            data = data["model"]
            if not isinstance(data, dict):
                raise ParameterError(f"{path}: [model] must be a table of parameters, got "
                                     f"{str(data)[:40]!r}")
        try:
            return cls.from_user(data)
        except ParameterError as exc:
            raise ParameterError(f"{path}: {exc}") from None

    def changed(self) -> dict[str, Any]:
        """The parameters that differ from their defaults (CGS names and units)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if getattr(self, f.name) != f.default}

    def to_dict(self) -> dict[str, Any]:
        """All parameters as a plain dict (CGS), for provenance records."""
        return dataclasses.asdict(self)


#: Metadata of every parameter, by name.
FIELDS = {f.name: f for f in dataclasses.fields(Parameters)}


def read_toml(path: Path, error=None) -> dict[str, Any]:
    """The parsed TOML file; ``error`` (default ParameterError) names the file on failure."""
    error = error or ParameterError
    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not a UTF-8 text file (byte {exc.start}); TOML is UTF-8 text") \
            from None
    except RecursionError:
        raise error(f"{path}: not valid TOML: nested too deeply") from None
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror or exc}") from None
    _check_integers(data, path, error)
    return data


def _check_integers(value, path, error, where="") -> None:
    """Refuse integers too large for a float (TOML allows 64-bit; Python parses any)."""
    if isinstance(value, bool):
        return
    if isinstance(value, int) and abs(value) > 2 ** 63:
        raise error(f"{path}: {where or 'a value'} = {str(value)[:20]}... is too large a number")
    if isinstance(value, dict):
        for k, v in value.items():
            _check_integers(v, path, error, f"{where}.{k}" if where else str(k))
    elif isinstance(value, list):
        for v in value:
            _check_integers(v, path, error, where)


def check_positive(name: str, value, unit: str, allow_zero: bool = False) -> float:
    """``value`` as a float if it is a finite number > 0 (>= 0 with allow_zero), else
    a ParameterError naming the parameter and the allowed range."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and _finite(value)
    if not ok or value < 0 or (value == 0 and not allow_zero):
        allowed = "[0, inf)" if allow_zero else "(0, inf)"
        raise ParameterError(f"{name} = {value!r} {unit} is outside the allowed range {allowed} {unit}")
    return float(value)


def _to_cgs(values: dict[str, Any]) -> dict[str, Any]:
    """Map user names (possibly unit-suffixed) to CGS field names and values."""
    out: dict[str, Any] = {}
    for key, value in values.items():
        name, factor = resolve_name(key)
        if name in out:
            raise ParameterError(f"parameter {name!r} given twice (as {key!r})")
        if factor != 1.0:
            # check in the user's unit, so the message speaks it
            meta = dict(FIELDS[name].metadata)
            meta["unit"] = key[len(name) + 1:]
            for bound in ("lo", "hi"):
                if meta[bound] is not None:
                    meta[bound] = meta[bound] / factor
            _check_number(key, value, meta)
            value = value * factor
        out[name] = value
    return out


def resolve_name(key: str) -> tuple[str, float]:
    """(CGS field name, factor to CGS) of a user name such as 'gap_mm' or 'gap'.

    Raises ParameterError, with close matches, for an unknown name.
    """
    if key in FIELDS:
        return key, 1.0
    for suffix, (unit, f) in USER_UNITS.items():
        stem = key[: -len(suffix)]
        if key.endswith(suffix) and stem in FIELDS and FIELDS[stem].metadata["unit"] == unit:
            return stem, f
    close = difflib.get_close_matches(key, list(FIELDS) + _suffixed_names(), n=3)
    hint = f"; did you mean {', '.join(close)}?" if close else ""
    raise ParameterError(f"unknown parameter {key!r}{hint} (see `workbench params` for the list)")


def _suffixed_names() -> list[str]:
    return [name + suffix for name, f in FIELDS.items()
            for suffix, (unit, _) in USER_UNITS.items() if f.metadata["unit"] == unit]


def _range_text(meta) -> str:
    lo, hi = meta["lo"], meta["hi"]
    left = "(" if meta["lo_open"] or lo is None else "["
    right = ")" if meta["hi_open"] or hi is None else "]"
    lo_text = "-inf" if lo is None else f"{lo:g}"
    hi_text = "inf" if hi is None else f"{hi:g}"
    return f"{left}{lo_text}, {hi_text}{right}"


def _finite(value) -> bool:
    """math.isfinite that also refuses integers too large for a float."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _check_number(name, value, meta):
    unit = meta["unit"]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(f"{name} must be a number ({unit}), got {value!r}")
    if isinstance(value, int) and not _finite(value):
        raise ParameterError(f"{name} = {str(value)[:20]}... is too large a number ({unit})")
    if math.isnan(value) or (math.isinf(value) and not (meta["allow_inf"] and value > 0)):
        allowed = "finite or inf" if meta["allow_inf"] else "finite"
        raise ParameterError(f"{name} must be {allowed}, got {value!r} ({unit})")
    lo, hi = meta["lo"], meta["hi"]
    below = lo is not None and (value <= lo if meta["lo_open"] else value < lo)
    above = hi is not None and (value >= hi if meta["hi_open"] else value > hi)
    if below or above:
        raise ParameterError(
            f"{name} = {value!r} {unit} is outside the allowed range {_range_text(meta)} {unit}")


def _validate(p: Parameters) -> None:
    for f in dataclasses.fields(p):
        value = getattr(p, f.name)
        if f.name == "cork":
            if not isinstance(value, str) or value not in CORK_MODELS:
                raise ParameterError(
                    f"cork = {value!r} is not a cork model; valid: {', '.join(CORK_MODELS)}")
        elif f.name == "tip_mass":
            if not isinstance(value, bool):
                raise ParameterError(f"tip_mass must be true or false, got {value!r}")
        elif f.name == "n_gauss":
            if isinstance(value, bool) or not isinstance(value, int):
                raise ParameterError(f"n_gauss must be an integer, got {value!r}")
            _check_number(f.name, value, f.metadata)
        elif value is None and f.default is None:
            continue
        else:
            _check_number(f.name, value, f.metadata)
    _require(p.x_lip > p.x_in, "x_lip", p.x_lip, f"greater than x_in = {p.x_in} cm")
    _require(p.mu_k <= p.mu_s, "mu_k", p.mu_k, f"at most mu_s = {p.mu_s}")
    _require(p.x_force <= p.l_a, "x_force", p.x_force, f"on beam A: (0, l_a = {p.l_a}] cm")
    _require(p.x_strain1 <= p.l_a, "x_strain1", p.x_strain1, f"on beam A: [0, l_a = {p.l_a}] cm")
    _require(p.x_strain2 <= p.l_b, "x_strain2", p.x_strain2, f"on beam B: [0, l_b = {p.l_b}] cm")
    _require(p.x_accel3 <= p.l_b, "x_accel3", p.x_accel3, f"on beam B: [0, l_b = {p.l_b}] cm")
    _require(p.x_accel2 <= p.l4, "x_accel2", p.x_accel2, f"on the loose body: [0, l4 = {p.l4}] cm")
    _require(p.loose_cm <= p.l4, "c4", p.loose_cm, f"on the loose body: [0, l4 = {p.l4}] cm")
    _require(p.x_in + p.l4 > p.x_lip, "l4", p.l4,
             f"long enough to reach the lips: l4 > x_lip - x_in = {p.x_lip - p.x_in:g} cm")


def _require(ok: bool, name: str, value: float, allowed: str) -> None:
    if not ok:
        raise ParameterError(f"{name} = {value!r} is not allowed: it must be {allowed}")


def describe() -> list[dict[str, Any]]:
    """One row per parameter: name, default, unit, allowed range, source, assumption."""
    rows = []
    for name, f in FIELDS.items():
        m = f.metadata
        rows.append(dict(name=name, default=f.default, unit=m["unit"],
                         allowed=_range_text(m) if (m["lo"] is not None or m["hi"] is not None) else "",
                         source=m["source"], assumption=m["assumption"], doc=m["doc"]))
    return rows
