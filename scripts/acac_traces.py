#!/usr/bin/env python3
"""Step traces of ACAC's environment copies from ACAC's own code (issue 41 item 3), for macdec's
step-for-step replay tests (tests/acac_replay.rs). Tests never run this; they read the fixtures.

The env is built as ACAC's runner builds it: the kwargs are what `scripts/params/utils.py
get_env_params` returns for `scripts/params/default.json` overridden by `env/<NAME>.json`
(`--setting ovcAR7`), `gym.make(env_id, **kwargs)`, Overcooked behind ACAC's `MacEnvWrapper`.
Then `np.random.seed(--np-seed)`, one `reset()`, and free agents draw uniform macro-actions from
their own `RandomState(--random-seed)` (never the global stream), or follow --plan ('[[1, 15],
[0]]': agent i starts its list's macro-actions in order whenever it is free and repeats the last
one), until done or the horizon (`env_terminate_step` unless --horizon).

It writes NAME.actions.json, the input of `macdec replay --actions`:
  {"source": "acac", "env": ID, "params": {kwargs}, "np_seed": S, "start_map": [[...]] (random
   starts only: the grid the reset produced), "steps": [[a_0, ..., a_n], ...]}
and NAME.trace.jsonl.gz (gzip without name or time), what ACAC's env returned: first
{"t": 0, "obs", "state"}, then {"t", "executed", "obs", "reward", "rewards", "done", "mac_done",
"state"} per primitive step (state = the wrapper's get_state(), where it has one).

Setup: Python 3.11 with numpy and gym 0.26.2; pygame is replaced by a stand-in.
  python scripts/acac_traces.py --acac ACAC --setting ovcAR7 --np-seed 3 --random-seed 0 \\
      --out tests/fixtures/acac/ovc_ar7_np3_random0
"""

import argparse
import gzip
import json
import os
import sys
import types

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from macromarl_traces import as_floats, as_ints  # noqa: E402
from reference_stand_ins import install_all  # noqa: E402


def runner_kwargs(acac, setting):
    """`get_env_params` of ACAC's merged params for env setting `setting`, and the horizon."""
    with open(os.path.join(acac, "scripts", "params", "default.json")) as f:
        params = json.load(f)
    with open(os.path.join(acac, "scripts", "params", "env", setting + ".json")) as f:
        for k, v in json.load(f).items():
            if k not in params:
                raise ValueError(f"Key {k} is not in params")
            params[k] = v
    # utils.py imports PROJECT_DIR from the learner package (torch); only the path is needed.
    stub = types.ModuleType("acac.acac_marl")
    stub.PROJECT_DIR = acac
    sys.modules["acac.acac_marl"] = stub
    sys.path.insert(0, os.path.join(acac, "scripts"))
    from params.utils import get_env_params

    args = argparse.Namespace(**params)
    return args.env_id, get_env_params(args), params["env_terminate_step"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--acac", required=True, help="a checkout of LGAI-Research/acac")
    parser.add_argument("--setting", required=True, help="scripts/params/env/NAME.json, e.g. ovcA7")
    parser.add_argument("--np-seed", type=int, required=True, help="np.random.seed before reset")
    parser.add_argument("--random-seed", type=int, default=0, help="the free agents' actions")
    parser.add_argument("--plan", help="JSON list per agent of macro-actions started in order")
    parser.add_argument("--horizon", type=int, help="most steps (env_terminate_step by default)")
    parser.add_argument("--out", required=True, help="output path without extension")
    args = parser.parse_args()

    sys.path.insert(0, args.acac)
    install_all()
    import contextlib
    import io

    import gym
    import numpy as np

    env_id, kwargs, horizon = runner_kwargs(args.acac, args.setting)
    import acac.env  # noqa: F401  (registers the gym ids)
    from acac.env import OvercookedMacEnvWrapper

    with contextlib.redirect_stdout(io.StringIO()):  # the constructor prints rand_start
        env = gym.make(env_id, disable_env_checker=True, **kwargs)
    if env_id.startswith("Overcooked-MA"):
        env = OvercookedMacEnvWrapper(env)
    inner = env.unwrapped
    n_agent = env.n_agent
    n_actions = list(env.n_action)

    np.random.seed(args.np_seed)
    obs = env.reset()
    has_state = True
    try:
        env.get_state()
    except (AttributeError, NotImplementedError):
        has_state = False

    def state_fields():
        return {"state": as_floats(np.asarray(env.get_state()).ravel())} if has_state else {}

    head = {"source": "acac", "env": env_id, "params": kwargs, "np_seed": args.np_seed}
    if kwargs.get("rand_start"):
        head["start_map"] = [[int(c) for c in row] for row in np.asarray(inner.map)]

    lines = [{"t": 0, "obs": [as_floats(o) for o in obs], **state_fields()}]
    rng = np.random.RandomState(args.random_seed)
    plan = json.loads(args.plan) if args.plan else None
    if plan is not None and len(plan) != n_agent:
        parser.error(f"--plan needs one list per agent ({n_agent})")
    started = [0] * n_agent
    free = [True] * n_agent
    steps = []
    for t in range(1, (args.horizon or horizon) + 1):
        if plan is None:
            actions = [int(rng.randint(n)) if free[i] else -1 for i, n in enumerate(n_actions)]
        else:
            actions = []
            for i in range(n_agent):
                if free[i]:
                    actions.append(int(plan[i][min(started[i], len(plan[i]) - 1)]))
                    started[i] += 1
                else:
                    actions.append(-1)
        steps.append(actions)
        obs, rewards, done, info = env.step(actions)
        mac_done = as_ints(info["mac_done"])
        lines.append(
            {
                "t": t,
                "executed": as_ints(info["cur_mac"]),
                "obs": [as_floats(o) for o in obs],
                "reward": float(rewards[0]),
                "rewards": as_floats(rewards),
                "done": bool(done),
                "mac_done": mac_done,
                **state_fields(),
            }
        )
        free = [bool(d) for d in mac_done]
        if done:
            break

    with open(args.out + ".actions.json", "w") as f:
        json.dump({**head, "steps": steps}, f)
        f.write("\n")
    text = "".join(json.dumps(line, separators=(",", ":")) + "\n" for line in lines)
    with open(args.out + ".trace.jsonl.gz", "wb") as raw:
        with gzip.GzipFile(filename="", mode="wb", compresslevel=9, fileobj=raw, mtime=0) as f:
            f.write(text.encode())
    total = sum(l.get("reward", 0.0) for l in lines)
    print(f"{args.out}: {len(steps)} steps, return {total:.4f}")


if __name__ == "__main__":
    main()
