#!/usr/bin/env python3
"""Learning curves from the authors' reference implementation, for comparison with ours.

Usage:
    pip install torch numpy
    python3 scripts/reference_curve.py --ref PATH/TO/MacDec-via-Cen --out DIR \
        --script ma_dec_cen_hddrqn_sep.py -- <the reference script's own flags>

e.g. the reference README's Warehouse command for Our-2 (Parallel-MacDec-MADDRQN), seed 3, first
5000 episodes:
    python3 scripts/reference_curve.py --ref /work/ref-checkout --out /tmp/ref-our2-s3 \
        --script ma_dec_cen_hddrqn_sep.py -- --env_name=OSD_S_4 --env_terminate_step=150 \
        --batch_size=16 --dec_rnn_h_size=64 --cen_rnn_h_size=64 --train_freq=30 --total_epi=5000 \
        --replay_buffer_size=1000 --eps_l_d_steps=6000 --l_rate=0.0006 --discount=1.0 \
        --start_train=2 --l_mode=0 --eps_end=0.1 --h_explore --sample_epi --dynamic_h --eps_l_d \
        --eval_freq=10 --save_dir=run --seed=3 --run_id=0

The reference script runs unchanged, in-process, with its working directory set to DIR (it writes
`performance/` and `policy_nns/` there). It is imported from the checkout and instrumented exactly
as scripts/golden_from_reference.py does (stand-ins for `gym`/`matplotlib`/`IPython`, and the two
uint8-mask functions recompiled with `.bool()` so current torch accepts them; same logic). While it
runs and when it ends, its evaluation record (`performance/<save_dir>/test/test_perform<run_id>
.pickle`, one greedy return per evaluation, the first before training) is converted to
DIR/curve.csv with columns `episode,return` (evaluation k at episode k * eval_freq).

Optional tool: tests and CI never run it. Slow (the reference is single-threaded PyTorch); run it
in the background.
"""

import argparse
import csv
import os
import pickle
import runpy
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import golden_from_reference  # noqa: E402  (the shared instrumentation of the reference)


def flag(argv, name, default):
    """The value of `--name=V` or `--name V` in the reference's argv."""
    for i, a in enumerate(argv):
        if a.startswith(f"--{name}="):
            return a.split("=", 1)[1]
        if a == f"--{name}" and i + 1 < len(argv):
            return argv[i + 1]
    return default


def convert(out, save_dir, run_id, eval_freq):
    """Write DIR/curve.csv from the reference's pickle, atomically; False if none yet."""
    src = os.path.join(out, "performance", save_dir, "test", f"test_perform{run_id}.pickle")
    try:
        with open(src, "rb") as f:
            returns = pickle.load(f)
    except (FileNotFoundError, EOFError, pickle.UnpicklingError):
        return False
    tmp = os.path.join(out, ".curve.csv.tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["episode", "return"])
        for k, r in enumerate(returns):
            w.writerow([k * eval_freq, repr(float(r))])
    os.replace(tmp, os.path.join(out, "curve.csv"))
    return True


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--ref", required=True, help="checkout of yuchen-x/MacDec-via-Cen")
    p.add_argument("--out", required=True, help="working directory for the reference run")
    p.add_argument("--script", required=True, help="file name under the checkout's scripts/")
    p.add_argument("args", nargs=argparse.REMAINDER, help="-- then the script's own flags")
    a = p.parse_args()
    argv = a.args[1:] if a.args[:1] == ["--"] else a.args
    script = os.path.join(os.path.abspath(a.ref), "scripts", os.path.basename(a.script))
    if not os.path.isfile(script):
        sys.exit(f"no reference script {script}")
    save_dir = flag(argv, "save_dir", None)
    if save_dir is None or "/" in save_dir or save_dir in ("", ".", ".."):
        sys.exit("give the reference a plain --save_dir name (it becomes a directory under --out)")
    run_id = int(flag(argv, "run_id", "0"))
    eval_freq = int(flag(argv, "eval_freq", "100"))

    golden_from_reference.import_reference(os.path.abspath(a.ref))
    os.makedirs(a.out, exist_ok=True)
    out = os.path.abspath(a.out)
    os.chdir(out)

    done = threading.Event()

    def keep_converting():
        while not done.wait(60):
            convert(out, save_dir, run_id, eval_freq)

    threading.Thread(target=keep_converting, daemon=True).start()
    sys.argv = [script] + argv
    try:
        runpy.run_path(script, run_name="__main__")
    finally:
        done.set()
        if not convert(out, save_dir, run_id, eval_freq):
            sys.exit("the reference wrote no evaluation record")


if __name__ == "__main__":
    main()
