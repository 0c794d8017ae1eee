#!/usr/bin/env python3
"""When ACAC's Overcooked runs first evaluate above a return threshold: ours against ACAC's logs.

For each setting, the first ACAC `Timesteps` (steps of finished training episodes) at which a
run's undiscounted evaluation return exceeds the threshold, for our runs
(`reproduction/acac/<env>/acac/seed-*/metrics.csv[.gz]`, columns `acac_timesteps`,
`eval_return_undiscounted`) and for ACAC's committed logs (`docs/reference_runs/acac/log/<env>/
acac/*.csv`, columns `Timesteps`, `Eval/Return`); then the exact one-sided rank-sum test that
ours rise later (the share of all splits of the pooled times whose "ours" rank sum is at least
the observed one; average ranks for ties, a run that never rises ranks last), per setting and
pooled over the settings (the rank sums' exact distribution, stratified by setting). These are
the numbers docs/REPRODUCTION.md reads ("ACAC: campaign in progress").

    python3 scripts/acac_first_rise.py ovcA7 ovcB7 ovcC7
"""

import argparse
import itertools
import math
import sys
from collections import Counter
from pathlib import Path

import acac_curves


def first_above(curve, threshold):
    """The first counted step at which the return exceeds the threshold, or infinity if never."""
    return next((steps for steps, value in curve if value > threshold), math.inf)


def ours(results, env, threshold):
    seed_dirs = sorted((results / env / "acac").glob("seed-*"))
    return [first_above(acac_curves.ours(d), threshold) for d in seed_dirs if (d / "finished").exists()]


def theirs(logs, env, threshold):
    files = sorted((logs / env / "acac").glob("*.csv"), key=lambda p: int(p.stem))
    return [first_above(acac_curves.theirs(p), threshold) for p in files]


def millions(times):
    return ", ".join(f"{t / 1e6:.2f}" for t in times)


def average_ranks(values):
    order = sorted(range(len(values)), key=lambda i: values[i])
    ranks = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        for k in range(i, j + 1):
            ranks[order[k]] = (i + j) / 2 + 1
        i = j + 1
    return ranks


def rank_sum_distribution(ours_times, their_times):
    """Observed rank sum of ours and the counts of every split's rank sum (doubled to stay integral)."""
    pooled = ours_times + their_times
    ranks = [round(2 * r) for r in average_ranks(pooled)]
    observed = sum(ranks[: len(ours_times)])
    counts = Counter(sum(c) for c in itertools.combinations(ranks, len(ours_times)))
    return observed, counts


def upper_tail(observed, counts):
    at_least = sum(n for s, n in counts.items() if s >= observed)
    return at_least, sum(counts.values())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("envs", nargs="+", help="ACAC env names, e.g. ovcA7 ovcB7 ovcC7")
    parser.add_argument("--results", type=Path, default=Path("reproduction/acac"))
    parser.add_argument("--logs", type=Path, default=Path("docs/reference_runs/acac/log"))
    parser.add_argument("--threshold", type=float, default=200.0)
    args = parser.parse_args()

    pooled_observed = 0
    pooled = Counter({0: 1})
    for env in args.envs:
        mine = ours(args.results, env, args.threshold)
        logs = theirs(args.logs, env, args.threshold)
        if not mine or not logs:
            sys.exit(f"{env}: no finished runs of ours ({len(mine)}) or no logs ({len(logs)})")
        observed, counts = rank_sum_distribution(mine, logs)
        at_least, total = upper_tail(observed, counts)
        print(f"{env}: ours [{millions(mine)}] M, ACAC's logs [{millions(logs)}] M, "
              f"one-sided p (ours later) = {at_least}/{total} = {at_least / total:.3f}")
        pooled_observed += observed
        merged = Counter()
        for a, na in pooled.items():
            for b, nb in counts.items():
                merged[a + b] += na * nb
        pooled = merged
    if len(args.envs) > 1:
        at_least, total = upper_tail(pooled_observed, pooled)
        print(f"pooled, stratified by setting: one-sided p = {at_least / total:.3f}")


if __name__ == "__main__":
    main()
