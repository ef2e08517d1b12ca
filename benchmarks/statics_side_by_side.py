"""The static start of two checkouts on the same models: equal results, and their cost.

    python benchmarks/statics_side_by_side.py save /tmp/statics.json      # in the old checkout
    python benchmarks/statics_side_by_side.py compare /tmp/statics.json   # in the new one

The models: the default study's 24 (4 gaps x tip mass on/off x 3 cork
models), the 1.016 mm cubic model with and without the tip mass under tip
loads of -20, -5, 5 and 20 N, two friction coefficients at 0.762 mm, and the
locked joint.  ``save`` writes each model's contact set, whether friction
holds, and q (or the error); ``compare`` counts the models whose results are
bitwise the same and names the others with their largest difference of q
(cm or rad).  Both print the wall time of the
static starts (one process: the first model also loads the kernels).
"""
import itertools
import json
import sys
import time

from workbench.model import packing as mdl
from workbench.model import statics
from workbench.model.params import Parameters


def models():
    """(parameter changes, tip load (N), fixed coordinates) of every model."""
    out = [(dict(gap_mm=gap, tip_mass=tip, cork=cork), 0.0, ())
           for gap, tip, cork in itertools.product((0.508, 0.635, 0.762, 1.016), (True, False),
                                                   ("linear", "quadratic", "cubic"))]
    out += [(dict(gap_mm=1.016, tip_mass=tip, cork="cubic"), load, ())
            for tip, load in itertools.product((True, False), (-20.0, -5.0, 5.0, 20.0))]
    out += [(dict(gap_mm=0.762, tip_mass=True, cork="linear", mu_s=mu, mu_k=0.8 * mu), 0.0, ())
            for mu in (0.1, 0.9)]
    out.append((dict(gap_mm=1.016, tip_mass=True, cork="cubic"), 0.0, tuple(mdl.JOINT)))
    return out


def solve_all():
    results, start = [], time.perf_counter()
    for changes, load, fixed in models():
        try:
            e = statics._solve_equilibrium(Parameters().replace(**changes), load, fixed, 0.0, None)
            results.append([int(e.contact_set), bool(e.friction_held), e.q.tolist()])
        except Exception as exc:            # no equilibrium: the message is the result
            results.append(["error", str(exc)])
    return results, time.perf_counter() - start


def main(argv):
    results, wall = solve_all()
    print(json.dumps({"models": len(results), "wall_s": wall}))
    if argv[0] == "save":
        with open(argv[1], "w") as f:
            json.dump(results, f)
        return
    with open(argv[1]) as f:
        saved = json.load(f)
    same = sum(a == b for a, b in zip(saved, results))
    print(json.dumps({"bitwise_same": same, "of": len(results)}))
    for (changes, load, fixed), a, b in zip(models(), saved, results):
        if a != b:
            dq = (max(abs(x - y) for x, y in zip(a[2], b[2]))
                  if a[0] != "error" and b[0] != "error" else None)
            print(json.dumps({"differs": changes, "tip_load_n": load, "fixed": list(fixed),
                              "saved": a[:2], "now": b[:2], "largest_dq": dq}))


if __name__ == "__main__":
    main(sys.argv[1:])
