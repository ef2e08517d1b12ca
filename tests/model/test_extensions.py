"""A new force shape and a cork law of a new functional form, each in at most 3 files.

The test copies the package, adds a two-tone shaker force (a code and a
branch in ``core/excitation.py``, a drive with its own resolution check in
``model/drives.py``) and an exponential cork law (a form in ``core/cork.py``,
an entry of ``CORK_MODELS`` in ``model/params.py``), and runs the copy with
numba's JIT disabled (``NUMBA_DISABLE_JIT=1``: the kernels as plain Python,
no compile).  The copy's runs use the new force and the new law; the slow
reference equations refuse both with a clear error.
"""
from __future__ import annotations

import filecmp
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import workbench

PACKAGE = Path(workbench.__file__).parent

#: The anchor of a text added at the end of a file.
END = None
#: file: [(anchor, text put after the anchor)]: the whole of each extension.
EDITS = {
    "core/excitation.py": [
        ("EXC_HAMMER_TIP = 4    # half-sine pulse along beam B's axis at its tip (§4.3)\n",
         "EXC_TWO_TONE = 5      # F0/2 (sin 2 pi f0 t + sin 2 pi f1 t) at force1\n"),
        ('    """Vertical shaker force (dyn) at force1 at time t (s) for the excitation array ex."""\n'
         "    kind = int(ex[X_KIND])\n",
         "    if kind == EXC_TWO_TONE:\n"
         "        return 0.5 * ex[X_AMP] * (math.sin(2.0 * math.pi * ex[X_F0] * t)\n"
         "                                  + math.sin(2.0 * math.pi * ex[X_F1] * t))\n"),
    ],
    "model/drives.py": [
        (END, textwrap.dedent("""\


            def two_tone(force_n, f0_hz, f1_hz):
                ex = none()
                ex[cx.X_KIND] = cx.EXC_TWO_TONE
                ex[cx.X_AMP] = _amplitude(force_n)
                ex[cx.X_F0] = check_positive("f0_hz", f0_hz, "Hz")
                ex[cx.X_F1] = check_positive("f1_hz", f1_hz, "Hz")
                return ex


            def _check_two_tone(ex, step):
                _check_frequency(ex, step, "f0_hz", cx.X_F0)
                _check_frequency(ex, step, "f1_hz", cx.X_F1)


            register(Drive("two_tone", ("force_n", "f0_hz", "f1_hz"), lambda e: two_tone(**e),
                           code=cx.EXC_TWO_TONE, check=_check_two_tone))
            """)),
    ],
    "core/cork.py": [
        ('FORMS = ("power",)\nPOWER = 0\n',
         'FORMS += ("exponential",)\nEXPONENTIAL = 1   # F = k n (exp(|s|/n) - 1) sign(s), n in cm\n'),
        ("        return power_spring(s, n, k)\n",
         "    if int(form) == EXPONENTIAL:\n"
         "        return k * n * math.copysign(math.expm1(abs(s) / n), s)\n"),
        ("        return k * abs(s) ** (n + 1.0) / (n + 1.0)\n",
         "    if int(form) == EXPONENTIAL:\n"
         "        return k * n * (n * math.expm1(abs(s) / n) - abs(s))\n"),
        ("        return n * k * abs(s) ** (n - 1.0)\n",
         "    if int(form) == EXPONENTIAL:\n"
         "        return k * math.exp(abs(s) / n)\n"),
    ],
    "model/params.py": [
        ('    "static": CorkLaw(1.0, 4.52e7, 1.7e4),      # mean of Table 5\'s static compression\n',
         '    "exponential": CorkLaw(0.05, 2.7e5, 1.7e4, "exponential"),\n'),
    ],
}

#: What the copy runs (NUMBA_DISABLE_JIT=1); prints one JSON line.
SCRIPT = textwrap.dedent("""\
    import json, math
    import numpy as np
    from workbench.model import drives
    from workbench.model.modes import natural_frequencies
    from workbench.model.params import ParameterError, Parameters
    from workbench.model.step_policy import default_dt
    from workbench.model.simulate import simulate
    from workbench.reference.equations import Reference, shaker

    out = {}
    p = Parameters().replace(gap_mm=1.016)
    ex = drives.excitation_array({"drive": "two_tone", "force_n": 10.0, "f0_hz": 20.0, "f1_hz": 30.0})
    run = simulate(p, ex, 0.005, output_hz=1.0 / default_dt(p, ex))   # unfiltered: every step
    t = run.signals.index.to_numpy()
    want = 0.5 * 10.0e5 * (np.sin(2 * np.pi * 20.0 * t) + np.sin(2 * np.pi * 30.0 * t))
    out["force_status"] = run.status
    out["force_error"] = float(np.max(np.abs(run.signals["force1"].to_numpy() - want)))
    try:
        simulate(p, drives.two_tone(10.0, 20.0, 9000.0), 0.005)
    except ParameterError as e:
        out["too_fast"] = str(e)
    try:
        shaker(ex)
    except NotImplementedError as e:
        out["reference_force"] = str(e)

    cork = Parameters().replace(gap_mm=1.016, cork="exponential")
    run = simulate(cork, drives.sine(200.0, 20.0), 0.005)
    out["cork_status"] = run.status
    out["cork_energy_balance"] = run.energy_balance_rel()
    out["cork_s_range"] = float(np.ptp(run.signals["s"]))
    free = natural_frequencies(cork, "free")
    out["cork_rigid_modes"] = int(np.sum(free == 0.0))
    out["cubic_rigid_modes"] = int(np.sum(natural_frequencies(Parameters(), "free") == 0.0))
    try:
        Reference(cork)
    except NotImplementedError as e:
        out["reference_cork"] = str(e)
    print(json.dumps(out))
    """)


def _extend(root: Path) -> Path:
    """A copy of the package under root with EDITS applied; returns the copy."""
    copy = root / "workbench"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    for name, edits in EDITS.items():
        path = copy / name
        text = path.read_text()
        for anchor, added in edits:
            if anchor is END:
                text += added
                continue
            assert text.count(anchor) == 1, f"{name}: the anchor {anchor!r} moved"
            text = text.replace(anchor, anchor + added)
        path.write_text(text)
    return copy


def _changed_files(a: Path, b: Path) -> list[str]:
    cmp = filecmp.dircmp(a, b, ignore=["__pycache__"])
    changed, stack = [], [(cmp, "")]
    while stack:
        c, prefix = stack.pop()
        changed += [prefix + n for n in c.diff_files + c.left_only + c.right_only]
        stack += [(sub, f"{prefix}{name}/") for name, sub in c.subdirs.items()]
    return sorted(changed)


def test_a_force_shape_and_a_cork_form_each_touch_at_most_three_files(tmp_path):
    copy = _extend(tmp_path)
    changed = _changed_files(PACKAGE, copy)
    assert changed == sorted(EDITS)
    force_files = [f for f in changed if "excitation" in f or "drives" in f]
    cork_files = [f for f in changed if "cork" in f or "params" in f]
    assert len(force_files) <= 3 and len(cork_files) <= 3
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=str(tmp_path),
               WORKBENCH_CACHE_ROOT=str(tmp_path / "cache"))
    done = subprocess.run([sys.executable, "-c", SCRIPT], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    # the new force drives the model, sampled exactly (at the internal rate: no filter)
    assert out["force_status"] == 0
    assert out["force_error"] < 1e-6 * 10.0e5
    assert "f1_hz = 9000 Hz is above what the step" in out["too_fast"]
    assert "not the force shape 5" in out["reference_force"]
    # the new cork law: a run that balances its energy, and a stiff s in the linear modes
    assert out["cork_status"] == 0
    assert out["cork_energy_balance"] < 1e-6
    assert out["cork_s_range"] > 0.0
    assert out["cork_rigid_modes"] == out["cubic_rigid_modes"] - 1
    assert "not the 'exponential' form" in out["reference_cork"]
