"""Right-hand sides by what they were spent on, per event and per step (not adopted).

    PYTHONPATH=. python benchmarks/unadopted/count_event_costs.py sine-tip|sine-notip|chirp

Needs the counters of this branch (rg[RG_CNT + k], workbench/core/adaptive.py); prints the
right-hand sides of the tries (the pair's stages, the embedded solution's event functions,
the dense output's stages, the location on the dense output), of the rejected tries, of the
samples, and of each event (the pair's steps to it, an earlier event on the way, the event
applied with the regime chosen and the impacts it sets off).
"""
import sys

from workbench.core import layout as ly
from workbench.model import packing
from workbench.model.drives import chirp, sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

captured = []
make_work = packing.make_work


def capture():
    w = make_work()
    captured.append(w)
    return w


packing.make_work = capture
case = sys.argv[1]
p = Parameters().replace(gap_mm=1.016, tip_mass=case != "sine-notip", cork="cubic")
ex, duration = (chirp(200.0, 5.0, 65.0, 240.0), 240.0) if case == "chirp" else \
    (sine(200.0, 20.0, ramp_s=1.0), 10.0)
simulate(p, ex, 0.01)
captured.clear()
run = simulate(p, ex, duration)
c = captured[-1].rg[ly.RG_CNT:]
s = run.summary()
events, tries, steps = s["n_events"], s["steps_all"], s["steps"]
total = c[0]
rows = [("the pair's stages (tries)", c[15]), ("the embedded solution's events (tries)", c[16]),
        ("the dense output's stages (accepted)", c[17]), ("location on the dense output", c[14]),
        ("of these, in rejected tries", c[19]), ("samples", c[18]),
        ("steps of the pair to the event", c[11]), ("an earlier event on the way", c[12]),
        ("events applied, regime chosen, impacts", c[13])]
print(f"{case}: wall {run.wall_s:.2f} s, {events} events, {tries} tries, {steps} accepted, "
      f"{total:.0f} right-hand sides ({total / tries:.1f} a try); pair steps to events "
      f"{c[4]:.0f}, short steps {c[3]:.0f}, largest move from the dense output's event "
      f"{c[5]:.2e} s; rejections right after an event {c[21]:.0f}")
for name, v in rows:
    print(f"  {name:42s} {v:10.0f} {100 * v / total:5.1f} %  {v / events:6.1f} an event")
