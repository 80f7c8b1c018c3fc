"""pixelpie.sample against scipy.stats.qmc.PoissonDisk, the Python sampler
Python users have, at the same radius: points, maximality and seconds.

    python python/benches/scipy_poissondisk.py [RADIUS]

Maximality is checked the same way for both: every probe of a grid at
1/4 px within the radius of some point (scipy's k-d tree), edges included.
scipy's radius is the minimum distance in the unit square.
"""

import sys
import time

import numpy as np
from scipy.spatial import cKDTree
from scipy.stats import qmc

import pixelpie

R = float(sys.argv[1]) if len(sys.argv) > 1 else 8.5


def uncovered(xy, side, r):
    tree = cKDTree(xy)
    worst = 0
    step = 0.25
    # Row blocks keep the probe arrays small.
    for y0 in np.arange(0.0, side + 1e-9, 64.0):
        ys = np.arange(y0, min(y0 + 64.0, side + 1e-9), step)
        xs = np.arange(0.0, side + 1e-9, step)
        gx, gy = np.meshgrid(xs, ys)
        d, _ = tree.query(np.column_stack([gx.ravel(), gy.ravel()]))
        worst += int(np.count_nonzero(d >= r))
    return worst


def closest(xy):
    d, _ = cKDTree(xy).query(xy, k=2)
    return float(d[:, 1].min())


print(f"r = {R} px; seconds of one run each")
print("| sampler | domain | points | closest pair | uncovered probes | maximal | seconds | samples/s | vs scipy |")
print("|---|---|---|---|---|---|---|---|---|")
for side in (1024, 2048):
    rows = []
    for name, run in [
        ("pixelpie.sample (pixel mode)", lambda: pixelpie.sample(side, side, radius=R, seed=1)[0][:, :2]),
        ("pixelpie.sample(exact=True)", lambda: pixelpie.sample(side, side, radius=R, exact=True, seed=1)[0][:, :2]),
        ("scipy qmc.PoissonDisk", lambda: qmc.PoissonDisk(2, radius=R / side, seed=1).fill_space() * side),
    ]:
        t = time.perf_counter()
        xy = np.asarray(run(), dtype=np.float64)
        s = time.perf_counter() - t
        rows.append((name, xy, s))
    scipy_rate = len(rows[-1][1]) / rows[-1][2]
    for name, xy, s in rows:
        u = uncovered(xy, side, R)
        rate = len(xy) / s
        print(f"| {name} | {side}² | {len(xy)} | {closest(xy):.3f} | {u} | {'yes' if u == 0 else 'no'} | {s:.3f} | {rate / 1e3:.1f}K | {rate / scipy_rate:.0f}× |")
