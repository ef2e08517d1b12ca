import sys
from workbench.model.params import Parameters
from workbench.model.drives import sine
from workbench.model.simulate import simulate
import workbench.model.run_result as rr
from workbench.core import layout as ly
tip = sys.argv[1] == "on"
r = simulate(Parameters().replace(gap_mm=1.016, tip_mass=tip), sine(200.0, 20.0, ramp_s=1.0), 10.0)
s = r.summary(); print(s["wall_s"], s["steps"], s["rejected"])
a = rr.LAST_ARGS
names = [f"y{i}" for i in range(18)] + [f"gap{k}" for k in range(4)] + [f"lam{k}" for k in range(4)] + ["stick", "slip", "evtime"]
print("accepted:", {names[i]: int(a[i]) for i in range(29) if a[i]})
print("rejected:", {names[i]: int(a[32+i]) for i in range(29) if a[32+i]})
