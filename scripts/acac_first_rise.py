#!/usr/bin/env python3
"""When ACAC's Overcooked runs first evaluate above a return threshold: ours against ACAC's logs.

For each setting, the first ACAC `Timesteps` (steps of finished training episodes) at which a
run's undiscounted evaluation return exceeds the threshold, for our runs
(`reproduction/acac/<env>/acac/seed-*/metrics.csv[.gz]`, columns `acac_timesteps`,
`eval_return_undiscounted`) and for ACAC's committed logs (`docs/reference_runs/acac/log/<env>/
acac/*.csv`, columns `Timesteps`, `Eval/Return`), or of a baseline's (`--method mac-iaicc` reads
`<results>/<env><suffix>/mac-iaicc/` against the logs' `mac_iaicc/`, `--method naive-mac-iacc`
against `mac_niacc/`); then the exact one-sided rank-sum test that
ours rise later (the share of all splits of the pooled times whose "ours" rank sum is at least
the observed one; average ranks for ties, a run that never rises, or rises only after the
shortest of ACAC's logs ends, ranks last), per setting and
pooled over the settings (the rank sums' exact distribution, stratified by setting). These are
the numbers docs/REPRODUCTION.md reads ("ACAC: campaign in progress" for `acac`, "ACAC's
baselines beside ours" for the baselines).

    python3 scripts/acac_first_rise.py ovcA7 ovcB7 ovcC7
    python3 scripts/acac_first_rise.py ovcA7 ovcB7 ovcC7 --results reproduction/acac_baselines \
        --suffix _acac_keys --method mac-iaicc

With `--late`, the same tests on how steady a trained team is instead: each run's mean
evaluation return over the second half of the budget (past half of the shortest log's last step,
up to it), tested one-sided for ours lower.

    python3 scripts/acac_first_rise.py ovcAR7 ovcBR7 ovcCR7 --late
"""

import argparse
import itertools
import math
import sys
from collections import Counter
from pathlib import Path

import acac_curves

# Our method name -> the folder of ACAC's logs that holds the same method's runs.
LOG_FOLDERS = {"acac": "acac", "mac-iaicc": "mac_iaicc", "naive-mac-iacc": "mac_niacc"}


def first_above(curve, threshold, budget):
    """The first counted step at which the return exceeds the threshold, or infinity if it does
    not by the budget."""
    return next((steps for steps, value in curve if steps <= budget and value > threshold), math.inf)


def our_curves(run_root):
    seed_dirs = sorted(run_root.glob("seed-*"), key=lambda d: int(d.name.removeprefix("seed-")))
    return [acac_curves.ours(d) for d in seed_dirs if (d / "finished").exists()]


def their_curves(log_root):
    files = sorted(log_root.glob("*.csv"), key=lambda p: int(p.stem))
    return [acac_curves.theirs(p) for p in files]


def late_mean(curve, budget):
    """The mean return of the evaluations past half the budget, up to the budget."""
    late = [value for steps, value in curve if budget / 2 < steps <= budget]
    return sum(late) / len(late) if late else -math.inf


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
    parser.add_argument("--method", choices=sorted(LOG_FOLDERS), default="acac")
    parser.add_argument("--suffix", default="", help="our experiment is <env><suffix>, e.g. _acac_keys")
    parser.add_argument("--late", action="store_true",
                        help="test the second half's mean return (ours lower) instead of the first rise")
    args = parser.parse_args()

    pooled_observed = 0
    pooled = Counter({0: 1})
    for env in args.envs:
        mine = our_curves(args.results / f"{env}{args.suffix}" / args.method)
        logs = their_curves(args.logs / env / LOG_FOLDERS[args.method])
        if not mine or not logs:
            sys.exit(f"{env}: no finished runs of ours ({len(mine)}) or no logs ({len(logs)})")
        # Equal budgets: a rise after the shortest of ACAC's logs ends counts as none.
        budget = min(curve[-1][0] for curve in logs)
        if args.late:
            # Negated, so that the upper tail is "ours lower", as it is "ours later" otherwise.
            mine = [-late_mean(curve, budget) for curve in mine]
            logs = [-late_mean(curve, budget) for curve in logs]
        else:
            mine = [first_above(curve, args.threshold, budget) for curve in mine]
            logs = [first_above(curve, args.threshold, budget) for curve in logs]
        observed, counts = rank_sum_distribution(mine, logs)
        at_least, total = upper_tail(observed, counts)
        p = f"{at_least}/{total} = {at_least / total:.3f}"
        if args.late:
            means = [", ".join(f"{-m:.1f}" for m in side) for side in (mine, logs)]
            print(f"{env}: second-half mean return, ours [{means[0]}], ACAC's logs [{means[1]}], "
                  f"one-sided p (ours lower) = {p}")
        else:
            print(f"{env}: ours [{millions(mine)}] M, ACAC's logs [{millions(logs)}] M, "
                  f"one-sided p (ours later) = {p}")
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
