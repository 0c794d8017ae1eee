#!/usr/bin/env python3
"""Learning curves from MacroMARL's own code (yuchen-x/MacroMARL), for comparison with ours.

Usage (Python 3.11 with torch, numpy and gym==0.26.2):
    python3 scripts/macromarl_reference_curve.py --ref PATH/TO/MacroMARL \
        --overcooked PATH/TO/gym-macro-overcooked --out DIR [--main value] -- <the entry's own flags>

The reference entry point runs unchanged, in-process (runpy), with its working directory set to
DIR (it writes `performance/` and `policy_nns/` there): `scripts/pg_based_main.py` (the
actor-critic methods; `--main pg`, the default) or `scripts/value_based_main.py` (MacDec-Q,
MacCen-Q and the DDRQN variants; `--main value`). The only things done around it:
  * `<ref>/src` and the gym-macro-overcooked checkout go on sys.path (pg_based_main.py imports
    `gym_macro_overcooked` unconditionally, even for Box Pushing);
  * stand-in modules, when they are not installed, for `IPython` (the env files import it for a
    debugger they never call), `matplotlib.pyplot` (imported, unused, by the value-based teams that
    `macro_marl.algs` imports too) and `pygame` (Overcooked's renderer; never used here);
  * with numpy >= 2, `np.bool8 = np.bool_`: gym 0.26.2's passive env checker, which gym.make wraps
    around every env and which runs on the first step only, still names the alias numpy 2 removed;
  * gym.make's passive env checker is skipped for environments without an `action_space` (the
    Warehouse `OSD-*` envs define none; gym 0.21, the reference's, had no such check): the
    checker only inspects, so the env is the same either way;
  * `torch.set_num_threads(1)` before the script runs (with an explicit non-zero `--seed` this
    makes a run repeatable: two BP 6x6 MacIAC runs, seed 1, 200 episodes, gave identical curves;
    `--seed` 0, the default, leaves the main process unseeded, docs/MACROMARL.md §1.5).
The runner forks `--n_env` worker processes (multiprocessing, fork start method).

Outputs in DIR:
  curve.csv    `episode,return`: evaluation k (actor-critic: mean discounted return of 10
               *sampled* test episodes, docs/MACROMARL.md §2.5, at episode k * (eval_freq -
               eval_freq % train_freq); value-based: one greedy episode's discounted return at
               episode k * eval_freq, docs/MACROMARL.md §8), the first at episode 0, before training. Written as each evaluation is printed (parsed from
               the reference's own progress line, so a long run can be watched), and rewritten at
               the end from the reference's pickle `performance/<save_dir>/test/test_perform<run_id>
               .pickle`, which is checked against the printed values.
  timing.json  wall seconds and CPU seconds (user+sys of this process plus its reaped children,
               i.e. the n_env workers), episodes, n_env.
  log.txt      the reference's stdout.

Commands that produced docs/reference_runs/macromarl/ (2 cores; every run pinned to CPU 1, one at a
time; PY=/tmp/tv/bin/python = Python 3.11.7, torch 2.15.0, gym 0.26.2, numpy 2.4.6; MM=/tmp/mm
(MacroMARL), OC=/tmp/oc (gym-macro-overcooked)). The flags are experiments/BoxPushing/mac_iac.sh and
mac_iaicc.sh's for that grid (mac_iaicc.sh runs --alg=MacIAISC), verbatim, with --total_epi=8000
instead of 40_000 and an explicit --seed=K (K = 1, 2, 3) added:

  BP6_IAC='--save_dir=ma_iac_bp6 --alg=MacIAC --env_id=BP-MA-v0 --n_agent=2 --env_terminate_step=100
    --big_box_reward=300 --a_lr=0.0005 --c_lr=0.003 --train_freq=32 --n_env=32
    --c_target_update_freq=32 --n_step_TD=0 --grad_clip_norm=0 --eps_start=1.0 --eps_end=0.01
    --eps_stable_at=4_000 --total_epi=8000 --grid_dim 6 6 --gamma=0.98 --eval_policy --sample_epi
    --run_id=0'
  BP10_IAC='--save_dir=ma_iac_bp10 --alg=MacIAC --env_id=BP-MA-v0 --n_agent=2
    --env_terminate_step=100 --big_box_reward=300 --a_lr=0.001 --c_lr=0.001 --train_freq=16
    --n_env=16 --c_target_update_freq=32 --n_step_TD=0 --grad_clip_norm=0 --eps_start=1.0
    --eps_end=0.01 --eps_stable_at=6_000 --total_epi=8000 --grid_dim 10 10 --gamma=0.98
    --eval_policy --sample_epi --run_id=0'
  BP6_IAISC='--save_dir=ma_iaicc_bp6 --alg=MacIAISC --env_id=BP-MA-v0 --n_agent=2
    --env_terminate_step=100 --big_box_reward=300 --a_lr=0.0003 --c_lr=0.003 --train_freq=32
    --n_env=32 --c_target_update_freq=128 --n_step_TD=0 --grad_clip_norm=0 --eps_start=1.0
    --eps_end=0.01 --eps_stable_at=4_000 --total_epi=8000 --grid_dim 6 6 --gamma=0.98
    --eval_policy --sample_epi --run_id=0'
  BP10_IAISC='--save_dir=ma_iaicc_bp10 --alg=MacIAISC --env_id=BP-MA-v0 --n_agent=2
    --env_terminate_step=100 --big_box_reward=300 --a_lr=0.0003 --c_lr=0.003 --train_freq=32
    --n_env=32 --c_target_update_freq=64 --n_step_TD=0 --grad_clip_norm=0 --eps_start=1.0
    --eps_end=0.01 --eps_stable_at=6_000 --total_epi=8000 --grid_dim 10 10 --gamma=0.98
    --eval_policy --sample_epi --run_id=0'
  for b in BP6_IAC BP6_IAISC BP10_IAC BP10_IAISC; do for k in 1 2 3; do
    OMP_NUM_THREADS=1 /usr/bin/time -v -o /tmp/mmref/$b-$k.time.txt taskset -c 1 $PY \
      scripts/macromarl_reference_curve.py --ref $MM --overcooked $OC --out /tmp/mmref/$b-$k \
      -- ${!b} --seed=$k
  done; done
Sequentially, one run at a time. Each DIR/curve.csv was copied to
docs/reference_runs/macromarl/bp<grid>_<alg>_seed<k>.csv; timings.csv there has /usr/bin/time's
elapsed wall time and user+sys CPU time (whole process tree, start-up included) of each run.

Optional tool: tests and CI never run it. Slow (the reference is PyTorch plus n_env Python worker
processes); run it in the background.
"""

import argparse
import csv
import json
import os
import pickle
import re
import resource
import runpy
import sys
import time
import types

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference_stand_ins import install_all  # noqa: E402
from reference_curve import flag  # noqa: E402  (one reading of the reference's argv)


def write_curve(out, rows):
    tmp = os.path.join(out, ".curve.csv.tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["episode", "return"])
        for e, r in rows:
            w.writerow([e, repr(float(r))])
    os.replace(tmp, os.path.join(out, "curve.csv"))


# Each entry's progress line after an evaluation: the actor-critic runner's, and the value-based
# learners' (printed when the episode count is a multiple of eval_freq, with the latest return).
EVAL_LINES = {
    "pg": re.compile(
        r"Finished: (\d+)/\d+ Evaluate learned policies with averaged returns (\S+) \.\.\."),
    "value": re.compile(r"to finish (\d+)(?:\.0)? episodes .* latest return \((\S+)\)"),
}
# What the value-based learners print once the evaluation record is saved; MacCenQ and the two
# DDRQN learners then end with a NameError (docs/MACROMARL.md §8), which is not a failed run.
FINISHED = "inish entire training"


class Tee:
    """The reference's stdout, copied to log.txt; each evaluation line updates curve.csv."""

    def __init__(self, out, stream, eval_line):
        self.out, self.stream, self.buf, self.rows = out, stream, "", []
        self.eval_line, self.finished = eval_line, False
        self.log = open(os.path.join(out, "log.txt"), "w")

    def write(self, s):
        self.stream.write(s)
        self.log.write(s)
        self.buf += s
        *lines, self.buf = self.buf.split("\n")
        new = False
        for line in lines:
            self.finished = self.finished or FINISHED in line
            m = self.eval_line.search(line)
            if m and (int(m.group(1)), float(m.group(2))) not in self.rows[-1:]:
                self.rows.append((int(m.group(1)), float(m.group(2))))
                new = True
        if new:
            write_curve(self.out, self.rows)
        return len(s)

    def flush(self):
        self.stream.flush()
        self.log.flush()

    def __getattr__(self, name):
        return getattr(self.stream, name)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--ref", required=True, help="checkout of yuchen-x/MacroMARL")
    p.add_argument("--overcooked", required=True, help="checkout of WeihaoTan/gym-macro-overcooked")
    p.add_argument("--out", required=True, help="working directory for the reference run")
    p.add_argument("--main", choices=["pg", "value"], default="pg",
                   help="pg_based_main.py (actor-critic, default) or value_based_main.py")
    p.add_argument("args", nargs=argparse.REMAINDER, help="-- then the entry's own flags")
    a = p.parse_args()
    argv = a.args[1:] if a.args[:1] == ["--"] else a.args
    ref = os.path.abspath(a.ref)
    script = os.path.join(ref, "scripts", f"{a.main}_based_main.py")
    if not os.path.isfile(script):
        sys.exit(f"no reference script {script}")
    save_dir = flag(argv, "save_dir", "test")
    if "/" in save_dir or save_dir in ("", ".", ".."):
        sys.exit("give the reference a plain --save_dir name (it becomes a directory under --out)")
    run_id = int(flag(argv, "run_id", "0"))
    eval_freq = int(flag(argv, "eval_freq", "100"))
    if a.main == "pg":
        train_freq = int(flag(argv, "train_freq", "2"))
        period = eval_freq - eval_freq % train_freq
    else:
        period = eval_freq
    if int(flag(argv, "seed", "0")) == 0:
        print("warning: --seed 0 (the default) leaves the main process unseeded", file=sys.stderr)

    sys.path[:0] = [os.path.join(ref, "src"), os.path.abspath(a.overcooked)]
    install_all()
    import numpy as np
    import torch

    import gym.envs.registration as registration

    checker = registration.PassiveEnvChecker

    def checked(env):
        # The Warehouse envs have no action_space, which gym 0.26's checker asserts on.
        return checker(env) if hasattr(env, "action_space") else env

    registration.PassiveEnvChecker = checked
    torch.set_num_threads(1)

    os.makedirs(a.out, exist_ok=True)
    out = os.path.abspath(a.out)
    os.chdir(out)
    tee = Tee(out, sys.stdout, EVAL_LINES[a.main])
    sys.stdout = tee
    sys.argv = [script] + argv
    wall0 = time.monotonic()
    try:
        runpy.run_path(script, run_name="__main__")
    except NameError as e:
        if not (a.main == "value" and tee.finished):
            raise
        print(f"note: the reference ended with its known NameError after saving ({e})",
              file=sys.stderr)
    finally:
        sys.stdout = tee.stream
        tee.log.close()
    wall = time.monotonic() - wall0
    import multiprocessing

    multiprocessing.active_children()  # reap any worker not yet joined, so its CPU time counts
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime

    src = os.path.join(out, "performance", save_dir, "test", f"test_perform{run_id}.pickle")
    with open(src, "rb") as f:
        returns = pickle.load(f)
    rows = [(k * period, r) for k, r in enumerate(returns)]
    printed = tee.rows
    recorded = dict(rows)
    if a.main == "pg":
        same = [e for e, _ in printed] == [e for e, _ in rows]
    else:
        # The value-based learners print only at some evaluations (not before training).
        same = all(e in recorded for e, _ in printed)
    if not same or any(
        abs(float(x) - float(recorded[e])) > 1e-9 * max(1.0, abs(float(recorded[e])))
        for e, x in printed
    ):
        sys.exit("the pickled evaluation record differs from the printed one")
    write_curve(out, rows)
    with open(os.path.join(out, "timing.json"), "w") as f:
        json.dump({"wall_seconds": wall, "cpu_seconds": cpu,
                   "episodes": int(flag(argv, "total_epi", "40000").replace("_", "")),
                   "n_env": int(flag(argv, "n_env", "1")), "evaluations": len(rows)}, f)
        f.write("\n")


if __name__ == "__main__":
    main()
