#!/bin/bash
cd /work/wt-pi
run() { PYTHONPATH=/work/wt-pi .venv/bin/python -m workbench run --gap-mm 1.016 --freq-hz 20 --force-n 200 --cork cubic --duration 10 --json --tip-mass $1 --tol 3e-5 2>/dev/null | tail -1 | python3 -c "import json,sys; d=json.loads(sys.stdin.read()); print(round(d['wall_s'],3), d['steps_all'], d['rejected'], d['n_events'])"; }
for v in "1.5 0.04" "2.0 0.04" "2.0 0.02" "2.0 0.0"; do
  set -- $v
  git checkout -q workbench/core/adaptive.py
  sed -i "s/^BETA = .*/BETA = $2/; s/    order = P\[ly.P_RK_ORDER\]/    order = P[ly.P_RK_ORDER] * $1/" workbench/core/adaptive.py
  run on >/dev/null
  for i in 1 2; do echo "$v on $(run on)"; echo "$v off $(run off)"; done
done
git checkout -q workbench/core/adaptive.py
