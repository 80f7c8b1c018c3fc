#!/usr/bin/env python3
"""How far a better pen choice could go (docs/colour.md): from `--choose K`'s
set, every swap of one chosen pen for one of the box's others is drawn and
measured (blurred ΔE00 at σ), the best taken, at most ROUNDS times (the
search stops where no swap helps), at the default seed 0. Then the choice
and the set found are drawn again at other seeds, so that the search's pick
of its luckiest drawing does not count.

    python3 docs/scripts/pen_search.py PHOTO [--pixelpie target/release/pixelpie]
        [--box assets/pens-24.toml] [--k 5] [--points 20000] [--rounds 2]
        [--seeds 2,3] [--dump sets.json]
"""
import argparse
import json
import os
import re
import subprocess
import tempfile
import tomllib


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("photo")
    ap.add_argument("--pixelpie", default="target/release/pixelpie")
    ap.add_argument("--box", default="assets/pens-24.toml")
    ap.add_argument("--k", type=int, default=5)
    ap.add_argument("--points", default="20000")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--seeds", default="2,3")
    ap.add_argument("--dump", help="write every set drawn and its measure here (JSON)")
    a = ap.parse_args()
    box = tomllib.load(open(a.box, "rb"))["pen"]
    names = [p["name"] for p in box]
    seeds = [t.strip() for t in a.seeds.split(",") if t.strip()]
    if "0" in seeds:
        ap.error("--seeds: the search draws at seed 0; re-draw at other seeds")
    work = tempfile.TemporaryDirectory()
    tmp = work.name
    cache = {}

    def measure(pens, seed="0", extra=()):
        key = (tuple(sorted(pens)), seed, tuple(extra))
        if key in cache:
            return cache[key]
        toml = os.path.join(tmp, "pens.toml")
        with open(toml, "w") as f:
            for i in sorted(pens):
                # Every key of the box's pen (width, dot gain, opacity), as
                # --choose draws it; JSON strings and numbers are TOML's.
                f.write("[[pen]]\n")
                for field, value in box[i].items():
                    f.write(f"{field} = {json.dumps(value)}\n")
                f.write("\n")
        svg = os.path.join(tmp, "d.svg")
        pen_arg = ["--pens", toml] if pens else list(extra)
        subprocess.run([a.pixelpie, "stipple", a.photo, "-o", svg, *pen_arg,
                        "--points", a.points, "--seed", seed, "-q"], check=True)
        out = subprocess.run([a.pixelpie, "fidelity", a.photo, svg], check=True,
                             capture_output=True).stdout
        e = json.loads(out)["colour"]["delta_e00_mean"]
        cache[key] = e
        return e

    said = subprocess.run([a.pixelpie, "stipple", a.photo, "-o", os.path.join(tmp, "c.svg"),
                           "--pens", a.box, "--choose", str(a.k), "--points", a.points],
                          check=True, capture_output=True, text=True).stderr
    line = re.search(r"^chose \d+ of \d+ pens for .*: (.+?) \(predicted", said, re.M)
    chosen = [names.index(n) for n in line.group(1).split(", ")]
    cur, best = chosen, measure(chosen)
    print(f"chosen: {', '.join(names[i] for i in cur)}: {best:.3f}", flush=True)
    for r in range(a.rounds):
        found = None
        for pos in range(len(cur)):
            for j in range(len(box)):
                if j in cur:
                    continue
                s = cur[:pos] + [j] + cur[pos + 1:]
                e = measure(s)
                if e < best:
                    best, found = e, s
        if found is None:
            break
        cur = found
        print(f"round {r + 1}: {', '.join(names[i] for i in cur)}: {best:.3f}", flush=True)
    for seed in seeds:
        print(f"seed {seed}: chosen {measure(chosen, seed):.3f}, found {measure(cur, seed):.3f}, "
              f"cmyk {measure([], seed, ('--pens', 'cmyk')):.3f}", flush=True)
    if a.dump:
        with open(a.dump, "w") as f:
            json.dump([{"pens": [names[i] for i in k[0]], "seed": k[1], "measured": e}
                       for k, e in cache.items() if k[0]], f, indent=1)


if __name__ == "__main__":
    main()
