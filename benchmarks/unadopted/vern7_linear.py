"""Linear analysis (not in make bench): DOP853 against Verner 7(6) on y' = i omega y, the
right-hand sides per radian at which each pair's estimate reaches 1e-5, 1e-4, 1e-3.  Verner's
coefficients from /tmp/diag/vern7.py (transcribed from Verner's published 7(6) 'efficient'
table, https://www.sfu.ca/~jverner/); pass its path as argv[1]."""
import json, sys
import numpy as np
from scipy.optimize import brentq
exec(open(sys.argv[1]).read())           # c, A, b, bh of Verner 7(6)
d = json.load(open("workbench/model/dop853.json"))
s = len(d["b"]); AA = np.zeros((s, s))
for i, row in enumerate(d["a"]):
    AA[i, :len(row)] = row
bb = np.array(d["b"]); e5 = np.r_[d["e"], np.zeros(s - len(d["e"]))]; e3 = np.r_[d["e3"], np.zeros(s - len(d["e3"]))]
def dop(y):
    z = 1j * y; k = np.linalg.solve(np.eye(s) - z * AA, np.ones(s))
    E5, E3 = abs(z * e5 @ k), abs(z * e3 @ k)
    return E5 ** 2 / np.sqrt(E5 ** 2 + 0.01 * E3 ** 2)
def vern(y):
    z = 1j * y; k = np.linalg.solve(np.eye(10) - z * A, np.ones(10))
    return abs(z * (b - bh) @ k)
for thr in (1e-5, 1e-4, 1e-3):
    y1 = brentq(lambda y: dop(y) - thr, 0.1, 4); y2 = brentq(lambda y: vern(y) - thr, 0.1, 4)
    print(f"estimate {thr:g}: dop853 {15 / y1:.1f} RHS/rad (12+3), vern7 {15 / y2:.1f} (10+5)")
