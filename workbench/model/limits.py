"""The ranges of run settings accepted at the user boundary (command line, studies, API).

Physical parameters carry their ranges in :mod:`workbench.model.params`; these
are the settings of a run.  What a given step resolves (drive frequency,
pulse width) is checked against the step by
:func:`workbench.model.run_settings.check_settings`.
"""
#: The longest run (s) and the shortest step (s).
MAX_DURATION_S = 1e5
MIN_DT = 1e-7
#: The largest step (s): RK4 is unstable far below it for this model; the
#: model's own limit is :func:`workbench.model.step_policy.stability_limit`.
MAX_DT = 1e-3
#: The controlled method's relative tolerance: its default and allowed range
#: (docs/model.md "Integration").  The default is the largest of 1e-4, 5e-5,
#: 3e-5, 2e-5 and 1e-5 at which the default method (dop853) keeps all 22
#: converged windows of benchmarks/controlled_accuracy.py within the bounds
#: (tip 1e-3 of its range, shares 1e-3, events 5 %; at 1e-4 two windows' events
#: are 5.1 and 5.5 % off) and every event of the tests' 36 ms reference case
#: within 1e-6 s (7.9e-7 s; at 5e-5 it takes 32 of the 34 events);
#: docs/performance.md "Accuracy against cost".
DEFAULT_TOL = 3e-5
TOL_RANGE = (1e-9, 1e-1)
#: The largest sample rate of the stored signals (Hz).
MAX_OUTPUT_HZ = 1e6
#: The largest shaker amplitude or hammer peak (N): 50 times the 200 N of
#: the paper's validated range.
MAX_FORCE_N = 1e4
#: The largest static tip deflection of a free decay (cm, either way): the
#: tip of beam B has 8.4 cm of travel in the paper (seed §5.3).
FREE_DECAY_MAX_CM = 20.0
#: Steps per period of the highest drive frequency at least (sine, chirp ends).
STEPS_PER_PERIOD = 20
#: Steps per hammer pulse at least when the step is given, and in the default step.
MIN_PULSE_STEPS = 5
PULSE_STEPS = 20
#: Samples per hammer pulse at least, and in the default sample rate: a pulse is
#: never lost between samples, and its force channel keeps its shape.
MIN_PULSE_SAMPLES = 5
PULSE_SAMPLES = 10
#: The signals' sample rate (Hz) unless a drive needs more (a hammer: PULSE_SAMPLES a pulse).
DEFAULT_OUTPUT_HZ = 1000.0
#: The longest study name (it names a folder).
MAX_NAME_CHARS = 100

#: :func:`workbench.model.step_policy.default_dt` asks RK4 to be stable for every eigenvalue of the
#: linear model scaled by this factor: room for the stiffening of contact.
STABILITY_MARGIN = 1.25

# --- the range a run's response is validated for (study tables and maps flag points outside) ---
#: The tip's largest deflection from its static equilibrium (cm): the paper's deflection test,
#: "slightly higher than the deflections seen in shaker tests" (seed §5.3); beyond it the
#: beams' small-slope shapes (cubic Hermite, linear strain) were not compared with the rig.
VALID_TIP_CM = 8.4
#: The accelerometers' range (g): PCB Piezotronics 352A24 (seed Table 1), +-50 g peak by the
#: maker's datasheet (ASSUMPTION: the paper names the model, not its range).
ACCEL_RANGE_G = 50.0
#: The force transducer's range (N): PCB Piezotronics 208C03 (seed Table 1), 2224 N (500 lbf)
#: by the maker's datasheet (ASSUMPTION, as above).
FORCE_RANGE_N = 2224.0
#: How a periodic orbit's monodromy may be taken (:mod:`workbench.model.orbit`), the default
#: first.
MONODROMY_METHODS = ("variational", "finite-difference")
