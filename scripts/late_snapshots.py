#!/usr/bin/env python3
"""How good a run's late policies are, snapshot by snapshot.

Usage:
    python3 scripts/late_snapshots.py --results reproduction --experiment fig5_wtd --optimal 262

A run's final return (the figures' tables) is the mean of its last 10% of evaluations. Each
evaluation scores one snapshot of the policy; in Warehouse a greedy policy returns the same on
every episode, so an evaluation is that snapshot's exact return and the spread among the last
10% is spread between snapshots, not evaluation noise. This prints, per finished run and pooled
per curve, how those late snapshots are distributed: the median, and the share at or above 95%
of the optimal return, between 0 and that, and below 0 (a collapsed snapshot). It separates "the
policy plateaus below the optimum" from "it is near the optimum but sometimes collapses".

Reads `metrics.csv` or `metrics.csv.gz` (column `eval_return`) of every run directory with a
`finished` marker (a finished run without metrics is an error). Standard library only; tests and CI never run it.
"""

import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_reference_curves import read_ours  # noqa: E402  (one reader of a run's metrics)


def late(returns):
    """The last 10% of evaluations, ceil(n / 10) and at least one, exactly as the figures' final
    return takes them (macdec's curve_stats::final_count)."""
    k = max(1, -(-len(returns) // 10))
    return returns[-k:]


def describe(values, optimal):
    """Median and the shares near-optimal / between 0 and near-optimal / collapsed, in percent."""
    near = 0.95 * optimal
    n = len(values)
    share = lambda pred: 100.0 * sum(1 for v in values if pred(v)) / n  # noqa: E731
    return (
        statistics.median(values),
        share(lambda v: v >= near),
        share(lambda v: 0 <= v < near),
        share(lambda v: v < 0),
    )


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--results", required=True, help="results tree, e.g. reproduction")
    p.add_argument("--experiment", required=True, help="experiment directory, e.g. fig5_wtd")
    p.add_argument("--optimal", required=True, type=float, help="the domain's optimal return")
    a = p.parse_args()

    root = os.path.join(a.results, a.experiment)
    if not os.path.isdir(root):
        sys.exit(f"late_snapshots: {root} is not a directory")
    print(f"late snapshots (last 10% of evaluations) in {root}; near = >= 95% of {a.optimal:g}")
    print(f"{'run':<24} {'n':>5} {'median':>8} {'near %':>7} {'0..near %':>10} {'<0 %':>6} {'last':>7}")
    for curve in sorted(os.listdir(root)):
        curve_dir = os.path.join(root, curve)
        if not os.path.isdir(curve_dir):
            continue
        pooled = []
        seeds = sorted(
            (d for d in os.listdir(curve_dir) if d.startswith("seed-")),
            key=lambda d: int(d[5:]) if d[5:].isdigit() else -1,
        )
        for seed in seeds:
            run = os.path.join(curve_dir, seed)
            if not os.path.exists(os.path.join(run, "finished")):
                continue
            returns = [r for _, r in read_ours(run)]
            if not returns:
                continue
            values = late(returns)
            pooled += values
            med, near, mid, low = describe(values, a.optimal)
            name = f"{curve}/{seed}"
            print(f"{name:<24} {len(values):>5} {med:>8.1f} {near:>7.1f} {mid:>10.1f} {low:>6.1f} {returns[-1]:>7.1f}")
        if pooled:
            med, near, mid, low = describe(pooled, a.optimal)
            name = f"{curve} (pooled)"
            print(f"{name:<24} {len(pooled):>5} {med:>8.1f} {near:>7.1f} {mid:>10.1f} {low:>6.1f}")


if __name__ == "__main__":
    main()
