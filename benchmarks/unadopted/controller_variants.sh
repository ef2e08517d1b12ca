#!/bin/bash
cd /work/wt-pi
run() { PYTHONPATH=/work/wt-pi .venv/bin/python -m workbench run --gap-mm 1.016 --freq-hz 20 --force-n 200 --cork cubic --duration 10 --json --tip-mass $1 --tol 3e-5 2>/dev/null | tail -1 | python3 -c "import json,sys; d=json.loads(sys.stdin.read()); print(round(d['wall_s'],3), d['steps_all'], d['rejected'], d['n_events'])"; }
for v in "0.9 0.04 0.2 10.0" "0.9 0.0 0.333 6.0" "0.9 0.08 0.2 10.0" "0.85 0.06 0.2 10.0" "0.9 0.04 0.2 2.0"; do
  set -- $v
  git checkout -q workbench/core/adaptive.py
  sed -i "s/^SAFETY = .*/SAFETY = $1/; s/^BETA = .*/BETA = $2/; s/^FAC_MIN = .*/FAC_MIN = $3/; s/^FAC_MAX = .*/FAC_MAX = $4/" workbench/core/adaptive.py
  run on >/dev/null
  for i in 1 2; do echo "$v on $(run on)"; echo "$v off $(run off)"; done
done
git checkout -q workbench/core/adaptive.py
