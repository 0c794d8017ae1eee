#!/usr/bin/env python3
"""Compare our learning curves with the reference implementation's, side by side.

Usage:
    python3 scripts/compare_reference_curves.py --ours DIR[,DIR...] --reference DIR[,DIR...] \
        [--bin 250] [--until 3000] [--csv OUT.csv]

--ours: macdec run directories (each with metrics.csv or metrics.csv.gz); --reference:
directories written by scripts/reference_curve.py (each with curve.csv), or such curve.csv files
themselves (e.g. docs/reference_runs/our2_wtd_seed*.csv). A shell glob works, e.g.
`--ours "$(ls -d reproduction/fig5_wtd/our2/seed-* | paste -sd,)"`.

Each run's evaluations are averaged within episode bins ([0, bin), [bin, 2 bin), ...), then the
bins are averaged over runs. Prints a Markdown table: per bin the mean +- standard error over runs
for both sides, and how many runs have a bin mean above --good (default 200; the Warehouse
optimum is 262). Standard library only.
"""

import argparse
import csv
import gzip
import math
import os
import sys


def read_ours(run):
    for name, opener in (("metrics.csv", open), ("metrics.csv.gz", gzip.open)):
        path = os.path.join(run, name)
        if os.path.exists(path):
            with opener(path, "rt", newline="") as f:
                return [(int(r["episode"]), float(r["eval_return"])) for r in csv.DictReader(f)]
    sys.exit(f"{run}: no metrics.csv or metrics.csv.gz")


def read_reference(run):
    """A reference_curve.py output directory, or one of its curve.csv files kept elsewhere
    (docs/reference_runs/ keeps them as single files)."""
    path = run if os.path.isfile(run) else os.path.join(run, "curve.csv")
    if not os.path.exists(path):
        sys.exit(f"{run}: no curve.csv (written by scripts/reference_curve.py)")
    with open(path, newline="") as f:
        return [(int(r["episode"]), float(r["return"])) for r in csv.DictReader(f)]


def binned(points, width, until):
    """Mean evaluation return per bin; bins past the run's last evaluation are None."""
    sums = {}
    for episode, ret in points:
        if episode < until:
            s = sums.setdefault(episode // width, [0.0, 0])
            s[0] += ret
            s[1] += 1
    return {k: s[0] / s[1] for k, s in sums.items()}


def summary(values):
    n = len(values)
    if n == 0:
        return None
    mean = sum(values) / n
    if n < 2:
        return mean, float("nan"), n
    var = sum((v - mean) ** 2 for v in values) / (n - 1)
    return mean, math.sqrt(var / n), n


def fmt(s):
    if s is None:
        return "-"
    mean, se, n = s
    return f"{mean:.1f}" if math.isnan(se) else f"{mean:.1f} ± {se:.1f} (n={n})"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--ours", required=True)
    p.add_argument("--reference", required=True)
    p.add_argument("--bin", type=int, default=250)
    p.add_argument("--until", type=int, default=3000)
    p.add_argument("--good", type=float, default=200.0)
    p.add_argument("--csv")
    a = p.parse_args()
    if a.bin <= 0 or a.until <= 0:
        sys.exit("--bin and --until must be positive")
    sides = {
        "ours": [binned(read_ours(r), a.bin, a.until) for r in a.ours.split(",") if r],
        "reference": [binned(read_reference(r), a.bin, a.until)
                      for r in a.reference.split(",") if r],
    }
    rows = []
    print(f"| episodes | ours | reference | ours > {a.good:g} | reference > {a.good:g} |")
    print("|---|---|---|---|---|")
    for k in range((a.until + a.bin - 1) // a.bin):
        cells = [f"{k * a.bin}-{(k + 1) * a.bin}"]
        good = []
        for side in ("ours", "reference"):
            vals = [b[k] for b in sides[side] if k in b]
            cells.append(fmt(summary(vals)))
            good.append(f"{sum(v > a.good for v in vals)}/{len(vals)}" if vals else "-")
            rows.append((k * a.bin, side, summary(vals)))
        print("| " + " | ".join(cells + good) + " |")
    if a.csv:
        tmp = a.csv + ".tmp"
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["bin_start", "side", "mean", "se", "n"])
            for start, side, s in rows:
                if s is not None:
                    w.writerow([start, side, repr(s[0]), repr(s[1]), s[2]])
        os.replace(tmp, a.csv)


if __name__ == "__main__":
    main()
