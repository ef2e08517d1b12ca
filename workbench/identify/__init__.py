"""Parameter identification as in the paper (seed §3.5, §4, Appendices A-C).

Plain functions, one method per module:

* :mod:`.sections`: parallel-axis inertia, b h^3/12, per-length values (Tables 3-4);
* :mod:`.cork`: Hooke's-law stiffness (Table 5) and the hammer-test exhaustive
  search (Table 6);
* :mod:`.decrement`: logarithmic decrement -> Td, zeta, omega_n, EI, E
  (Eq. 2, Appendix B);
* :mod:`.strain`: strain-patch scale factors from double-integrated
  acceleration (Eq. 3);
* :mod:`.contacts`: contact codes from PVDF patch voltages (§3.5);
* :mod:`.tables`: the paper's tables reproduced (``workbench identify tables``).
"""
from .contacts import contact_code_series, detect_contacts
from .cork import CorkFit, fit_cork, hammer_record, hooke_stiffness, sliding_mass
from .decrement import Decrement, decrement_from_record, log_decrement
from .sections import area_moment, mass_per_length, parallel_axis, rotary_inertia_per_length
from .strain import calibrate_patch, cantilever_strain, euler_double_integral, scale_factor

__all__ = ["CorkFit", "Decrement", "area_moment", "calibrate_patch", "cantilever_strain",
           "contact_code_series", "decrement_from_record", "detect_contacts",
           "euler_double_integral", "fit_cork", "hammer_record", "hooke_stiffness",
           "log_decrement", "mass_per_length", "parallel_axis", "rotary_inertia_per_length",
           "scale_factor", "sliding_mass"]
