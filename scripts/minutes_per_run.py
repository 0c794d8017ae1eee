#!/usr/bin/env python3
"""Minutes per run of every curve of a results tree, from each finished run's recorded wall clock.

Usage:
    python3 scripts/minutes_per_run.py [RESULTS]      # default: reproduction/macromarl

For every `<experiment>/<curve>/` below RESULTS, the finished runs' `wall_seconds` of their last
metrics row (for a resumed run, the recorded total over its segments), as a Markdown table: runs,
median, min and max minutes, and the curve's total run-minutes. Standard library only.
"""

import csv
import gzip
import os
import statistics
import sys


def last_wall_seconds(run):
    for name, opener in (("metrics.csv", open), ("metrics.csv.gz", gzip.open)):
        path = os.path.join(run, name)
        if os.path.exists(path):
            with opener(path, "rt", newline="") as f:
                rows = list(csv.DictReader(f))
            return float(rows[-1]["wall_seconds"]) if rows else None
    return None


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "reproduction/macromarl"
    print("| experiment | curve | runs | median min | min | max | total run-min |")
    print("|---|---|---|---|---|---|---|")
    for exp in sorted(os.listdir(root)):
        exp_dir = os.path.join(root, exp)
        if not os.path.isdir(exp_dir):
            continue
        for curve in sorted(os.listdir(exp_dir)):
            curve_dir = os.path.join(exp_dir, curve)
            if not os.path.isdir(curve_dir):
                continue
            minutes = []
            for run in sorted(os.listdir(curve_dir)):
                run_dir = os.path.join(curve_dir, run)
                if os.path.exists(os.path.join(run_dir, "finished")):
                    s = last_wall_seconds(run_dir)
                    if s is not None:
                        minutes.append(s / 60)
            if minutes:
                print(
                    f"| {exp} | {curve} | {len(minutes)} | {statistics.median(minutes):.2f} | "
                    f"{min(minutes):.2f} | {max(minutes):.2f} | {sum(minutes):.1f} |"
                )


if __name__ == "__main__":
    main()
