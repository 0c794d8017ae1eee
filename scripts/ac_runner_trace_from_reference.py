#!/usr/bin/env python3
"""Runner-level traces of MacroMARL's actor-critic training loop (issue 42, item 6).

Usage:
    python3 scripts/ac_runner_trace_from_reference.py --ref PATH/TO/MacroMARL \
        [--out tests/fixtures/ac_runner] [--cases NAME ...] [--ref-commit SHA]

    --ref is a checkout (or `git archive`) of github.com/yuchen-x/MacroMARL (HEAD f5899cd7 was
    used). Needs Python 3 with torch, numpy, gym (0.26.2) and safetensors (for the shared
    helpers of scripts/ac_golden_from_reference.py). Optional tool: tests and CI never run it;
    tests/ac_runner_reference.rs reads what it wrote. Running it twice gives the same bytes.

The golden updates (scripts/ac_golden_from_reference.py) prove one learner update on a given
batch. This records what the reference's *runner* does around the learner, for a few updates of
a whole `learn()`: which macro-actions its controller sampled on every environment at every
lockstep step (training and evaluation), the exploration weight of each batch, the batch its
memory hands the learner, when it hard-copies the target critics, and its evaluation returns.
Our test replays those macro-actions through our own training loop and checks that it collects
the same batches on the same schedule and computes the same evaluation numbers.

What it does, per case (CASES below):
  * Seeds python `random`, numpy and torch (`torch.set_num_threads(1)`), builds the environment
    class with the kwargs scripts/pg_based_main.py passes for the published command (MacroMARL's
    experiments/*.sh row), and the reference's own algorithm object with every pg_based_main.py
    argument: the published row with a few counts made small so that a few updates show every
    part of the schedule (n_env, train_freq, c_target_update_freq, eps_stable_at, eval_freq,
    total_epi; each case lists them in `overrides`).
  * Calls the algorithm's own `learn()`, unchanged, in a temporary working directory (it writes
    its pickles, checkpoint and best policies there). Nothing of the reference is patched: a line
    tracer (`sys.settrace`) reads locals in `learn()` and in the runner's `EnvsRunner._step` (a
    line event fires before its line runs):
      - `_step`, at `parent.send(("step", actions))`: the macro-actions the controller returned
        for environment `idx` (decentralized actors: -1 for a busy agent; Mac-CAC: the joint
        action, whose busy components are the agents' running macro-actions);
      - `learn()`, at the evaluation's `runner.run(..., test_mode=True)`, the training
        `runner.run(eps=eps, ...)`, `learner.train(...)`, `update_critic_target_net()` and
        `self.envs_runner.eval_returns = []`: the phase, `epi_count`, `eps`, the memory's batch,
        the returns of the training episodes, the sync, the evaluation's returns and mean.
  * `wants` lists what the trace must show (`exercised` in the fixture says where); the case's
    seed is the first from its base that shows all of it.

Output: <out>/<case>.json.gz (gzip without name or time), a JSON object:
  format "macdec-ac-runner-1"; case; alg (reference class); method (our name);
  reference {repo, commit, torch}; env {gym_id, params (the env constructor's kwargs),
  macdec (our EnvSpec: `env_name` and its keys, as in experiments/macromarl/*.toml)};
  seed; config {every pg_based_main.py argument that matters to the loop: n_env, train_freq,
  total_epi, gamma, eps_start, eps_end, eps_stable_at, c_target_update_freq, eval_freq,
  eval_num_epi, env_terminate_step, n_step_TD, a_lr, c_lr, widths}; overrides (the keys changed
  from the published row, with the published value); exercised;
  phases: learn()'s phases in order, each
    {"kind": "eval", "epi_count": episodes done, "steps": S, "returns": [R of every evaluation
     episode in completion order], "mean": the value appended to eval_returns}
    {"kind": "train", "epi_count", "eps", "steps": S, "train_returns": [R of every training
     episode completed in this collection, in order], "target_sync_after": bool,
     "batch": the memory's episodes as `learner.train` gets them (oldest first, not padded;
     `Memory_epi.sample()` pads each with zero records to the longest), each
       {"obs": [[row]] steps + 1 rows, each every agent's observation concatenated (row t + 1 is
        record t's next_obs; record t's obs is checked to equal row t),
        "state": the same for get_state() (state-critic families only),
        "mac_start": [[0/1 per agent]] (families that record it), "action": [[executed]],
        "reward": [[acc_i]], "joint_reward": [accJ] (families that record it),
        "terminate": [0/1], "valid": [[0/1]]}}
  where S is the list of lockstep steps, each the list (one per environment, in index order)
  of the controller's joint action for that environment. Floats are the exact doubles of the
  reference's float32 tensors (observations, rewards) or its Python floats (eps, returns).
"""

import argparse
import gzip
import io
import json
import linecache
import os
import random
import sys
import tempfile

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ac_golden_from_reference as golden  # noqa: E402  (import_reference, record_to_json)

KNOWN_COMMIT = golden.KNOWN_COMMIT
MAX_SEED_TRIES = 200


def bp_env(grid, horizon):
    """BP-MA-v0 as experiments/BoxPushing/*.sh build it (--big_box_reward=300, argparse
    defaults for the rest)."""
    return golden.bp_params(grid, horizon)


def wh_a_env(horizon):
    """OSD-D-v7 as experiments/Warehouse/*A*.sh build it: human steps [27, 20, 20, 20] for both
    humans, Turtlebot speed 0.8, delay penalty -20 (`n_agent` is passed and ignored)."""
    p = golden.bp_params((6, 6), horizon)
    p["n_agent"] = 3
    p["TB_move_speed"] = 0.8
    p["delay_delivery_penalty"] = -20.0
    p["human_speed_per_step"] = [[27, 20, 20, 20], [27, 20, 20, 20]]
    return p


CASES = [
    dict(name="bp6_mac_iaisc", alg="MacIAISC", method="mac-iaisc", gym_id="BP-MA-v0",
         env_params=bp_env((6, 6), 30),
         macdec_env={"env_name": "BP-MA-v0", "grid_dim": [6, 6], "env_terminate_step": 30,
                     "big_box_reward": 300.0, "small_box_reward": 20.0, "penalty": -10.0},
         # experiments/BoxPushing/mac_iaicc.sh, 6x6 (it runs MacIAISC).
         published=dict(env_terminate_step=100, a_lr=3e-4, c_lr=3e-3, n_env=32, train_freq=32,
                        c_target_update_freq=128, n_step_TD=0, eps_end=0.01,
                        eps_stable_at=4000, total_epi=40000, gamma=0.98, eval_freq=100,
                        a_rnn_layer_size=32, c_rnn_layer_size=32, c_mlp_layer_size=[32, 32]),
         # 3 environments for 4 episodes per update (as BP 12x12 Mac-IAC runs 8 for 16): the
         # lockstep length bias with overshoot; a horizon of 30 so that early episodes end both
         # ways (at 100 nearly all of them reach a box first); sync every 2nd update; eps reaches
         # its end value at the 4th; evaluation period 10 - 10 % 4 = 8; none after the last
         # update.
         overrides=dict(env_terminate_step=30, n_env=3, train_freq=4, c_target_update_freq=8,
                        eps_stable_at=12, eval_freq=10, total_epi=24),
         wants=["overshoot", "unfinished_dropped", "lengths_differ", "terminal",
                "time_limit_cut", "eval_overshoot", "sync", "no_sync", "eps_at_end",
                "busy_agent"]),
    dict(name="wh_a_mac_cac", alg="MacCAC", method="mac-cac", gym_id="OSD-D-v7",
         env_params=wh_a_env(200),
         # experiments/Warehouse/mac_cac.sh, Warehouse A; evaluation period 10 - 10 % 4 = 8.
         macdec_env={"env_name": "OSD-D-v7", "env_terminate_step": 200,
                     "human_speed_per_step": [[27, 20, 20, 20], [27, 20, 20, 20]],
                     "TB_move_speed": 0.8, "delay_delivery_penalty": -20.0},
         published=dict(env_terminate_step=200, a_lr=3e-4, c_lr=3e-3, n_env=4, train_freq=4,
                        c_target_update_freq=32, n_step_TD=5, eps_end=0.05, eps_stable_at=10000, total_epi=40000,
                        gamma=1.0, eval_freq=100, a_rnn_layer_size=64, c_rnn_layer_size=64,
                        c_mlp_layer_size=[32, 32]),
         overrides=dict(c_target_update_freq=8, eps_stable_at=12, eval_freq=10, total_epi=16),
         wants=["time_limit_cut", "eval_overshoot", "sync", "no_sync", "eps_at_end",
                "busy_agent", "joint_with_busy"]),
]


def alg_kwargs(case, seed):
    """Every pg_based_main.py argument: the published row, then the case's overrides."""
    row = dict(case["published"])
    row.update(case["overrides"])
    kw = dict(env_id=case["gym_id"], env_terminate_step=case["env_params"]["terminate_step"],
              n_env=row["n_env"], n_agent=case["env_params"]["n_agent"], l_mode=0, seed=seed,
              run_id=0, save_dir="runner_trace", resume=False, device="cpu",
              total_epi=row["total_epi"], gamma=row["gamma"], a_lr=row["a_lr"],
              c_lr=row["c_lr"], c_train_iteration=1, eps_start=1.0, eps_end=row["eps_end"],
              eps_stable_at=row["eps_stable_at"], c_hys_start=1.0, c_hys_end=1.0,
              adv_hys_start=1.0, adv_hys_end=1.0, hys_stable_at=4000, critic_hys=False,
              adv_hys=False, etrpy_w_start=0.0, etrpy_w_end=0.0, etrpy_w_stable_at=4000,
              train_freq=row["train_freq"], c_target_update_freq=row["c_target_update_freq"],
              c_target_soft_update=False, tau=0.01, n_step_TD=row["n_step_TD"], TD_lambda=0.0,
              grad_clip_value=0.0, grad_clip_norm=0.0, obs_last_action=False, eval_policy=True,
              eval_freq=row["eval_freq"], eval_num_epi=10, sample_epi=True, trace_len=10,
              a_mlp_layer_size=[32, 32], a_rnn_layer_size=row["a_rnn_layer_size"],
              c_mlp_layer_size=row["c_mlp_layer_size"],
              c_rnn_layer_size=row["c_rnn_layer_size"], c_mid_layer_size=32)
    return kw


def as_int(a):
    if isinstance(a, torch.Tensor):
        return int(a.reshape(-1)[0].item())
    return int(a)


def episode_json(records, family):
    """One memory episode as rows (see the module doc); checks obs/next_obs continuity."""
    recs = [golden.record_to_json(r, family) for r in records]
    flat = lambda per_agent: [v for o in per_agent for v in o]  # noqa: E731
    out = {"obs": [flat(recs[0]["obs"])]}
    for t, r in enumerate(recs):
        assert flat(r["obs"]) == out["obs"][-1], f"record {t}: obs is not the previous next_obs"
        out["obs"].append(flat(r["next_obs"]))
    if "state" in recs[0]:
        out["state"] = [recs[0]["state"]]
        for t, r in enumerate(recs):
            assert r["state"] == out["state"][-1], f"record {t}: state is not the previous one"
            out["state"].append(r["next_state"])
    for key in ["mac_start", "action", "reward", "joint_reward", "terminate", "valid"]:
        if key in recs[0]:
            out[key] = [r[key] for r in recs]
    for r in recs:
        assert r["exp_valid"] == [1.0] * len(r["valid"]), "exp_valid is not all ones"
        if "joint_valid" in r:
            assert r["joint_valid"] == max(r["valid"]), "joint_valid is not max(valid)"
    return out


class Tracer:
    """Reads learn()'s and the runner's locals (see the module doc)."""

    def __init__(self, model, family):
        self.model, self.family = model, family
        self.phases = []
        self.codes = {type(model).learn.__code__: "learn",
                      type(model.envs_runner)._step.__code__: "step"}
        self.n_train_returns = 0

    def on_enter(self, where):
        if where == "step":
            self.phases[-1]["steps"].append([])

    def on_line(self, frame, where):
        line = linecache.getline(frame.f_code.co_filename, frame.f_lineno).strip()
        f = frame.f_locals
        if where == "step":
            if line == 'parent.send(("step", actions))':
                self.phases[-1]["steps"][-1].append([as_int(a) for a in f["actions"]])
            return
        me = f["self"]
        if line.startswith("self.envs_runner.run(n_epis=self.eval_num_epi, test_mode=True)"):
            self.phases.append({"kind": "eval", "epi_count": f["epi_count"], "steps": []})
        elif line == "self.envs_runner.eval_returns = []":
            ph = self.phases[-1]
            ph["returns"] = [float(r) for r in me.envs_runner.eval_returns]
            ph["mean"] = float(me.eval_returns[-1])
        elif line.startswith("self.envs_runner.run(eps=eps"):
            self.phases.append({"kind": "train", "epi_count": f["epi_count"],
                                "eps": float(f["eps"]), "steps": []})
        elif line.startswith("self.learner.train("):
            ph = self.phases[-1]
            returns = me.envs_runner.train_returns
            ph["train_returns"] = [float(r) for r in returns[self.n_train_returns:]]
            self.n_train_returns = len(returns)
            ph["target_sync_after"] = False
            ph["batch"] = [episode_json(e, self.family) for e in me.memory.buf]
        elif line.startswith("self.learner.update_critic_target_net()"):
            self.phases[-1]["target_sync_after"] = True

    def run(self):
        golden.trace_lines(self.codes, self.on_line, self.model.learn, on_enter=self.on_enter)


def exercised(case, phases, n_env):
    """{key: evidence} of what the trace shows (the keys of CASES' `wants`)."""
    ev = {}
    horizon = case["env_params"]["terminate_step"]
    train_freq = alg_kwargs(case, 0)["train_freq"]

    def note(key, text):
        ev.setdefault(key, text)

    for k, ph in enumerate(phases):
        if ph["kind"] == "eval":
            if len(ph["returns"]) > 10:
                note("eval_overshoot", f"phase {k}: {len(ph['returns'])} evaluation episodes "
                     "completed, the mean is over the last 10")
            continue
        n_done = len(ph["train_returns"])
        if n_done > train_freq:
            note("overshoot", f"phase {k}: {n_done} episodes completed for {train_freq}; the "
                 "memory keeps the last ones")
        if len(ph["steps"]) * n_env > sum(len(e["action"]) for e in ph["batch"]):
            note("unfinished_dropped", f"phase {k}: steps of unfinished or overwritten "
                 "episodes are not in the batch")
        lens = [len(e["action"]) for e in ph["batch"]]
        if len(set(lens)) > 1:
            note("lengths_differ", f"phase {k}: episode lengths {lens}")
        for e in ph["batch"]:
            if e["terminate"][-1] == 1:
                note("terminal", f"phase {k}: an episode ends terminally at step "
                     f"{len(e['terminate'])}")
            elif len(e["terminate"]) == horizon:
                note("time_limit_cut", f"phase {k}: an episode is cut at the horizon {horizon}")
            for t, v in enumerate(e["valid"]):
                if 0 < sum(v) < len(v):
                    note("busy_agent", f"phase {k}: step {t} ends some agents' macro-actions "
                         "only")
        if ph["target_sync_after"]:
            note("sync", f"phase {k}: targets copied after the update at episode "
                 f"{ph['epi_count'] + train_freq}")
        else:
            note("no_sync", f"phase {k}: no copy after the update at episode "
                 f"{ph['epi_count'] + train_freq}")
        if ph["eps"] == case["overrides"].get("eps_end", case["published"]["eps_end"]) or \
                ph["epi_count"] >= alg_kwargs(case, 0)["eps_stable_at"]:
            note("eps_at_end", f"phase {k}: eps {ph['eps']!r} at episode {ph['epi_count']}")
        if case["alg"] == "MacCAC":
            for t in range(1, len(ph["steps"])):
                for j, a in enumerate(ph["steps"][t]):
                    if a != ph["steps"][t - 1][j] and any(
                            x == y for x, y in zip(a, ph["steps"][t - 1][j])):
                        note("joint_with_busy", f"phase {k} step {t} env {j}: joint action "
                             f"{a} after {ph['steps'][t - 1][j]}")
    return ev


def run_once(ref, case, seed):
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)
    torch.set_num_threads(1)
    p = dict(case["env_params"])
    p["grid_dim"] = tuple(p["grid_dim"])
    env = ref.envs[case["gym_id"]](**p)
    kw = alg_kwargs(case, seed)
    cwd = os.getcwd()
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        try:
            for d in ["performance/runner_trace/train", "performance/runner_trace/test",
                      "performance/runner_trace/ckpt", "policy_nns/runner_trace"]:
                os.makedirs(d)
            model = ref.algs[case["alg"]](env, **kw)
            tracer = Tracer(model, golden.ALGS[case["alg"]][2])
            tracer.run()
        finally:
            os.chdir(cwd)
    meta = dict(obs_sizes=[int(x) for x in env.obs_size],
                n_actions=[int(x) for x in env.n_action])
    return tracer.phases, kw, meta


def run_case(ref, case, base_seed, out, commit):
    for seed in range(base_seed, base_seed + MAX_SEED_TRIES):
        phases, kw, meta = run_once(ref, case, seed)
        ev = exercised(case, phases, kw["n_env"])
        missing = [w for w in case["wants"] if w not in ev]
        if not missing:
            break
        print(f"{case['name']}: seed {seed} lacks {missing}", flush=True)
    else:
        raise RuntimeError(f"{case['name']}: no seed shows {missing}")
    keys = ["n_env", "train_freq", "total_epi", "gamma", "eps_start", "eps_end", "eps_stable_at",
            "c_target_update_freq", "eval_freq", "eval_num_epi", "env_terminate_step",
            "n_step_TD", "a_lr", "c_lr", "a_mlp_layer_size", "a_rnn_layer_size",
            "c_mlp_layer_size", "c_rnn_layer_size", "c_mid_layer_size"]
    doc = {
        "format": "macdec-ac-runner-1",
        "case": case["name"],
        "alg": case["alg"],
        "method": case["method"],
        "reference": {"repo": "yuchen-x/MacroMARL", "commit": commit,
                      "torch": torch.__version__.split("+")[0]},
        "env": {"gym_id": case["gym_id"], "params": case["env_params"],
                "macdec": case["macdec_env"], **meta},
        "seed": seed,
        "config": {k: kw[k] for k in keys},
        "overrides": {k: {"value": v, "published": case["published"][k]}
                      for k, v in case["overrides"].items()},
        "exercised": [f"{k}: {v}" for k, v in sorted(ev.items())],
        "phases": phases,
    }
    raw = json.dumps(doc, separators=(",", ":")).encode()
    buf = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buf, mtime=0) as gz:
        gz.write(raw)
    path = os.path.join(out, case["name"] + ".json.gz")
    tmp = path + ".tmp"
    with open(tmp, "wb") as fh:
        fh.write(buf.getvalue())
    os.replace(tmp, path)
    return doc, len(buf.getvalue())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ref", required=True, help="checkout of yuchen-x/MacroMARL")
    ap.add_argument("--out", default="tests/fixtures/ac_runner", help="output directory")
    ap.add_argument("--cases", nargs="*", help="case names (default: all)")
    ap.add_argument("--ref-commit", default=None,
                    help=f"commit of --ref if it is not a git checkout (default {KNOWN_COMMIT})")
    args = ap.parse_args()
    ref_dir = os.path.abspath(args.ref)
    commit = golden.reference_commit(ref_dir, args.ref_commit)
    ref = golden.import_reference(ref_dir)
    os.makedirs(args.out, exist_ok=True)
    out = os.path.abspath(args.out)
    for k, case in enumerate(CASES):
        if args.cases and case["name"] not in args.cases:
            continue
        doc, size = run_case(ref, case, 1 + 1000 * k, out, commit)
        keys = [e.split(":", 1)[0] for e in doc["exercised"]]
        print(f"{case['name']}: seed {doc['seed']}, {size} bytes, exercised {', '.join(keys)}",
              flush=True)


if __name__ == "__main__":
    main()
