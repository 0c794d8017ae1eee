"""The two readers of ACAC-axis learning curves that the ACAC comparison scripts share.

A curve is a list of (counted steps, undiscounted evaluation return) points: ACAC's `Timesteps`
(steps of finished training episodes) against its `Eval/Return`. Ours come from a run directory's
`metrics.csv` (or the `metrics.csv.gz` that `scripts/campaign.sh collect` commits), columns
`acac_timesteps` and `eval_return_undiscounted`; ACAC's from one of its committed log files
(`docs/reference_runs/acac/log/<env>/<alg>/<seed>.csv`). Python standard library only.
"""
import csv
import gzip
import os


def ours(run_dir):
    """Our run's curve, from its metrics.csv or metrics.csv.gz."""
    path = os.path.join(run_dir, "metrics.csv")
    opener = open
    if not os.path.exists(path):
        path, opener = path + ".gz", gzip.open
    with opener(path, "rt") as f:
        return [(float(r["acac_timesteps"]), float(r["eval_return_undiscounted"])) for r in csv.DictReader(f)]


def theirs(path):
    """One of ACAC's committed per-seed logs."""
    with open(path) as f:
        return [(float(r["Timesteps"]), float(r["Eval/Return"])) for r in csv.DictReader(f)]
