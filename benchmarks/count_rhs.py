import sys, io, contextlib, json
from workbench.model import packing
from workbench.core import layout as ly
captured = []
orig = packing.make_work
def mk():
    w = orig(); captured.append(w); return w
packing.make_work = mk
from workbench import cli
args = ["run", "--gap-mm", "1.016", "--freq-hz", "20", "--force-n", "200", "--cork", "cubic", "--duration", "10", "--json", "--tip-mass", sys.argv[1]]
for i in range(2):
    captured.clear()
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        try: cli.main(args)
        except SystemExit: pass
s = json.loads(buf.getvalue().strip().splitlines()[-1])
c = captured[-1].rg[ly.RG_CNT:ly.RG_CNT+7]
names = ["rhs_regime", "pair_step try", "pair_step past", "prepare_dense", "_trial", "store", "step_error rhs"]
print("wall", s["wall_s"], "steps", s["steps"], "rej", s["rejected"], "events", s["n_events"])
for n, v in zip(names, c): print(f"{n:16s} {v:10.0f}")
r = captured[-1].rg[ly.RG_CNT+8:ly.RG_CNT+8+ly.N_EV+2]
print("rejections by event fn index (0..N_EV-1), event time (N_EV), state (N_EV+1):", r.astype(int).tolist())
