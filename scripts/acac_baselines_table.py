#!/usr/bin/env python3
"""The table of docs/REPRODUCTION.md "ACAC's baselines": our Mac-IAICC / Naive Mac-IACC runs
(reproduction/acac_baselines, every assumption of experiments/acac_baselines) against ACAC's
committed curves of its baselines (docs/reference_runs/acac/log/bp*/{mac_iaicc,mac_niacc}), along
ACAC's Timesteps (steps of completed training episodes; our column acac_timesteps).

    python3 scripts/acac_baselines_table.py [--results reproduction/acac_baselines]

Per grid, method and source: the steps counted at the first evaluation (96 episodes of uniformly
random play, so they depend only on the runner's lanes and batch size: a fingerprint of the
runner's settings), how many runs find the big box (an evaluation above 250; 299.x there, 39.x
at the two small boxes) by ACAC's budget of 500 000 counted steps and where, and the mean
evaluation return at that budget (each run's last evaluation at or before it).
Reads only the Python standard library.
"""
import argparse
import glob
import os
import statistics

from acac_curves import ours, theirs

BUDGET = 500_000
BIG_BOX = 250.0
LOGS = os.path.join(os.path.dirname(__file__), "..", "docs", "reference_runs", "acac", "log")
# (ACAC's log folder, our history-critic method, our state-critic method)
METHODS = [("mac_iaicc", "mac-iaicc", "mac-iaisc"), ("mac_niacc", "naive-mac-iacc", "naive-mac-iasc")]
# (experiment suffix, what it assumes, the critic column of METHODS it trains)
ASSUMPTIONS = [
    ("", "MacroMARL's rows, history critics", 1),
    ("_state", "MacroMARL's rows, state critics", 2),
    ("_acac_keys", "ACAC's keys, history critics", 1),
    ("_state_acac_keys", "ACAC's keys, state critics", 2),
]


def row(label, runs):
    """One table row from runs of (counted steps, undiscounted return) points; ours start with a
    row at 0 steps (the evaluation before training), ACAC's logs do not."""
    first = [next(s for s, _ in r if s > 0) for r in runs]
    found, finals = [], []
    for r in runs:
        within = [p for p in r if p[0] <= BUDGET]
        hit = next((s for s, v in within if v > BIG_BOX), None)
        if hit is not None:
            found.append(hit)
        finals.append(within[-1][1])
    if any(r[-1][0] < BUDGET for r in runs):
        label += " (a run ends before the budget)"
    where = ", ".join(f"{s / 1000:.0f} k" for s in sorted(found))
    return (f"| {label} | {len(runs)} | {statistics.mean(first):.0f} ({min(first):.0f}-{max(first):.0f}) "
            f"| {len(found)} of {len(runs)}{' (' + where + ')' if where else ''} | {statistics.mean(finals):.1f} |")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--results", default="reproduction/acac_baselines")
    a = p.parse_args()
    print("| runs | n | counted steps at the first evaluation, mean (range) | big box by 500 k | mean return at 500 k |")
    print("|---|---|---|---|---|")
    for g in (6, 8, 10):
        for log, history, state in METHODS:
            logs = sorted(glob.glob(os.path.join(LOGS, f"bp{g}", log, "*.csv")))
            print(row(f"bp{g} {log}: ACAC's logs", [theirs(f) for f in logs]))
            for suffix, assumed, which in ASSUMPTIONS:
                method = (log, history, state)[which]
                dirs = sorted(glob.glob(os.path.join(a.results, f"bp{g}{suffix}", method, "seed-*")))
                dirs = [d for d in dirs if os.path.exists(os.path.join(d, "finished"))]
                if dirs:
                    print(row(f"bp{g} {method}: ours, {assumed}", [ours(d) for d in dirs]))


if __name__ == "__main__":
    main()
