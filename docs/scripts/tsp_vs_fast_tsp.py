"""Our --order tsp path against fast_tsp (PyPI; within about 0.1% of LKH-3)
through the same dots: `pixelpie stipple PHOTO --order tsp --points N -o
x.csv` writes the dots in drawing order; fast_tsp solves the open path
through them (a city at distance 0 from all closes it), on distances scaled to
fast_tsp's 16-bit range.

    pip install fast-tsp numpy
    python docs/scripts/tsp_vs_fast_tsp.py PIXELPIE PHOTO N [N ...]
"""
import csv
import subprocess
import sys
import tempfile

import fast_tsp
import numpy as np


def path_length(xy, order):
    d = np.diff(xy[order], axis=0)
    return float(np.sqrt((d * d).sum(axis=1)).sum())


def main():
    binary, photo, counts = sys.argv[1], sys.argv[2], [int(n) for n in sys.argv[3:]]
    for n in counts:
        with tempfile.TemporaryDirectory() as tmp:
            out = f"{tmp}/x.csv"
            subprocess.run([binary, "stipple", photo, "--order", "tsp", "--points", str(n),
                            "--backend", "cpu", "-q", "-o", out], check=True)
            with open(out) as f:
                rows = list(csv.DictReader(f))
        xy = np.array([[float(r["x"]), float(r["y"])] for r in rows])
        ours = path_length(xy, np.arange(len(xy)))
        m = len(xy)
        diff = xy[:, None, :] - xy[None, :, :]
        dist = np.sqrt((diff * diff).sum(axis=2))
        dist *= 65000.0 / dist.max()
        full = np.zeros((m + 1, m + 1), dtype=np.int64)
        full[:m, :m] = np.rint(dist).astype(np.int64)
        del diff, dist
        tour = fast_tsp.find_tour(full.tolist(), duration_seconds=min(60.0, 2.0 + m / 400))
        k = tour.index(m)
        order = np.array(tour[k + 1:] + tour[:k])
        theirs = path_length(xy, order)
        print(f"{photo} {m} dots: ours {ours:.0f} px, fast_tsp {theirs:.0f} px, "
              f"ours/theirs {ours / theirs:.4f}")


if __name__ == "__main__":
    main()
