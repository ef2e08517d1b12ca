"""How fast the model's modes get along runs: the regime's Jacobian against the linear model.

    python benchmarks/regime_spectra.py            # the 32 cases below, about a minute warm

``default_dt`` asks RK4 to be stable for the linear model's eigenvalues
scaled by STABILITY_MARGIN (1.25), to leave room for contact and large
motion.  This measures how much room is used: along 2.5 s of each sine
(from the static equilibrium, 0.5 s ramp), every 4 ms, the Jacobian
df/dy of ``rhs_regime`` in the regime the run is in (central differences
of (q, q'); a slipping regime with both slip directions), its eigenvalues,
and the largest modulus over the run against the linear model's largest.
Prints one line per case: that ratio, the regime and eigenvalue where it
occurs, and the largest ratio in each regime met.
"""
import numpy as np

from workbench.core import layout as ly
from workbench.core.constrained import rhs_regime
from workbench.model import packing as mdl
from workbench.model.excitation import sine
from workbench.model.params import Parameters
from workbench.model.regimes import is_stick, set_of
from workbench.model.simulate import _eigenvalues, simulate, stepped_dt

DURATION_S = 2.5
EVERY = 4                  # samples (1 kHz) between Jacobians
REL_STEP = 1e-7            # central-difference step, relative (floors 1e-3 cm or rad, 1 per s)


def jacobian_eigenvalues(y18, t, regime, sign, model, ex, work):
    """Eigenvalues (1/s) of df/dy at the state y18 (q, q') in ``regime``."""
    P, tab, kc, free = model
    rec, mat, vec, stages, cg, cw, rg, ev = work
    rg[ly.RG_SET] = set_of(regime)
    rg[ly.RG_STICK] = 1.0 if is_stick(regime) else 0.0
    rg[ly.RG_SIGN] = sign
    y = np.zeros(ly.N_AUG)
    y[:ly.N_STATE] = y18
    f_plus = np.zeros(ly.N_AUG)
    f_minus = np.zeros(ly.N_AUG)
    J = np.zeros((ly.N_STATE, ly.N_STATE))
    for j in range(ly.N_STATE):
        d = REL_STEP * max(abs(y18[j]), 1e-3 if j < ly.N_DOF else 1.0)
        y_plus = y.copy()
        y_plus[j] += d
        y_minus = y.copy()
        y_minus[j] -= d
        for yy, ff in ((y_plus, f_plus), (y_minus, f_minus)):
            status = rhs_regime(t, yy, P, tab, kc, free, ex, rec, mat, vec, cg, cw, rg, ff)
            if status != ly.OK:
                raise RuntimeError(f"rhs_regime status {status} at t = {t}")
        J[:, j] = (f_plus[:ly.N_STATE] - f_minus[:ly.N_STATE]) / (2.0 * d)
    return np.linalg.eigvals(J)


def case(tip, force_n, freq_hz, gap_mm):
    p = Parameters().replace(gap_mm=gap_mm, cork="cubic", tip_mass=tip)
    ex = sine(force_n, freq_hz, ramp_s=0.5)
    linear = float(np.abs(_eigenvalues(p)).max())
    run = simulate(p, ex, DURATION_S)
    if not run.ok:
        raise RuntimeError(run.message)
    model = mdl.build(p)
    model.P[ly.P_STEPPED_DT] = stepped_dt(p)
    work = mdl.make_work()
    regimes = run.signals["regime"].to_numpy()
    worst, worst_regime, worst_lam = 0.0, -1, 0j
    by_regime = {}
    for i in range(0, len(run.t), EVERY):
        r = int(regimes[i])
        for sign in ((1.0, -1.0) if r > 0 and not is_stick(r) else (1.0,)):
            lam = jacobian_eigenvalues(run.states[i], run.t[i], r, sign, model, ex, work)
            k = int(np.argmax(np.abs(lam)))
            m = abs(lam[k])
            by_regime[r] = max(by_regime.get(r, 0.0), m / linear)
            if m > worst:
                worst, worst_regime, worst_lam = m, r, lam[k]
    regimes_text = ", ".join(f"{k}: {v:.3f}" for k, v in sorted(by_regime.items()))
    print(f"tip mass {'on' if tip else 'off'}, {force_n:g} N, {freq_hz:g} Hz, {gap_mm} mm: "
          f"linear {linear:.4g} 1/s; along the run {worst:.4g} 1/s = {worst / linear:.3f} x "
          f"(regime {worst_regime}, {worst_lam:.4g}); by regime {{{regimes_text}}}", flush=True)
    return worst / linear


def main():
    ratios = [case(tip, force, freq, gap)
              for tip in (True, False) for gap in (0.508, 1.016)
              for force in (50.0, 200.0) for freq in (10.0, 30.0, 45.0, 55.0)]
    print(f"largest ratio over the {len(ratios)} cases: {max(ratios):.3f}")


if __name__ == "__main__":
    main()
