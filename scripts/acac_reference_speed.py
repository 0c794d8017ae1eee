#!/usr/bin/env python3
"""CPU time of ACAC's own training code (LGAI-Research/acac), for issue 41 item 6.

Runs ACAC's entry point `scripts/acac_main.py` unchanged (via runpy, with the given flags), after
three things that do not touch its learning code:
- torch pinned to one thread (`torch.set_num_threads(1)`, `set_num_interop_threads(1)`); also
  set OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 in the environment, as below.
- stand-in modules for `IPython`, `pygame` and `wandb` (imported by ACAC, never used on this
  path) and `numpy.bool8 = numpy.bool_` for gym 0.26's checker under numpy 2 (as
  scripts/acac_golden_from_reference.py does).
- ACAC's PROJECT_DIR pointed at --data, with `scripts` linked to the checkout's, so ACAC's logs,
  checkpoints and policies go to --data instead of into the checkout.

ACAC always forks one worker process per environment (`n_env`; its `parallel` setting is read
but unused), so time the whole process tree: /usr/bin/time counts the children, which ACAC
joins at the end of training. At exit this script prints its own and its children's CPU
seconds (getrusage) and the last Timesteps / Episodes row of ACAC's progress.csv.

Run (from any directory):
  OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 nice -n 5 /usr/bin/time -f '%U %S' \\
      /tmp/torchenv/bin/python acac_reference_speed.py --acac /tmp/acac --data /tmp/acac-speed-bp6 \\
      -- --alg_name acac --env_name bp6 --device cpu --seed 1 --total_epi 500
Everything after `--` is passed to acac_main.py (settings: default.json, then alg/<alg>.json,
then env/<env>.json, then these flags). Use a fresh --data folder for each run.
"""

import argparse
import csv
import glob
import os
import resource
import runpy
import sys

from reference_stand_ins import install_all


def last_progress_row(data_dir):
    rows = []
    for path in glob.glob(os.path.join(data_dir, "data", "log", "**", "progress.csv"), recursive=True):
        with open(path) as f:
            rows += list(csv.DictReader(f))
    return rows[-1] if rows else {}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--acac", default="/tmp/acac", help="a copy of LGAI-Research/acac")
    parser.add_argument("--data", required=True, help="fresh folder for ACAC's data/ output")
    parser.add_argument("acac_args", nargs=argparse.REMAINDER, help="-- then acac_main.py flags")
    cli = parser.parse_args()
    acac_args = cli.acac_args[1:] if cli.acac_args[:1] == ["--"] else cli.acac_args
    acac_dir = os.path.abspath(cli.acac)
    data_dir = os.path.abspath(cli.data)
    os.makedirs(data_dir, exist_ok=True)
    link = os.path.join(data_dir, "scripts")
    if not os.path.exists(link):
        os.symlink(os.path.join(acac_dir, "scripts"), link)

    install_all()
    import torch

    torch.set_num_threads(1)
    torch.set_num_interop_threads(1)
    sys.path.insert(0, acac_dir)
    import acac.acac_marl

    acac.acac_marl.PROJECT_DIR = data_dir  # read by every ACAC module when it is imported

    main_py = os.path.join(acac_dir, "scripts", "acac_main.py")
    sys.argv = [main_py] + acac_args
    runpy.run_path(main_py, run_name="__main__")

    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = last_progress_row(data_dir)
    print(
        "acac_reference_speed: torch threads %d | cpu_s self %.2f (user %.2f sys %.2f) | "
        "children %.2f (user %.2f sys %.2f) | total %.2f | Timesteps %s | Episodes %s"
        % (
            torch.get_num_threads(),
            me.ru_utime + me.ru_stime, me.ru_utime, me.ru_stime,
            kids.ru_utime + kids.ru_stime, kids.ru_utime, kids.ru_stime,
            me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime,
            row.get("Timesteps"), row.get("Episodes"),
        ),
        flush=True,
    )


if __name__ == "__main__":
    main()
