#!/usr/bin/env python3
"""Step traces of MacroMARL's domains from the reference code itself (issue 27), for macdec's
step-for-step replay tests. Tests never run this; they read the fixtures it writes.

For one domain (the reference's gym id and keyword arguments) and one action sequence it writes
two files:

  NAME.actions.json  the input of `macdec replay --actions`:
                     {"env": ID, "params": {...}, "steps": [[a_0, ..., a_n], ...]}
                     (-1 for a busy agent, whose value the environment ignores)
  NAME.trace.jsonl.gz  (gzip, no name or time in the header, so a rerun gives the same bytes)
                     what the reference printed, one JSON line per primitive step: first
                     {"t": 0, "obs": [...], "state": [...]} for the reset, then
                     {"t", "executed", "obs", "reward", "rewards", "done", "mac_done", "state"}
                     (executed = info['cur_mac'], mac_done = info['mac_done'] as 0/1,
                     done = the env's terminate, state only where the env has get_state()).

The actions are given (--steps FILE, a JSON list of joint actions), or planned per agent (--plan
'[[2, 4], [3, 4]]': agent i starts its list's macro-actions in order whenever it is free and
repeats the last one), or drawn uniformly at random for the free agents (--random-seed S,
numpy's RandomState, so a seed gives the same file everywhere), or chosen by trained actors
(--actors DIR: MacroMARL's `agent_state_dict*.pt` files, in agent order by file name; each free
agent takes the argmax of its actor on its observation, its GRU state carried across its own
decisions, as the reference's controller acts; needs torch); planned, random and actor episodes
run until the env terminates or --horizon steps. With --actors, --gamma G also prints the
episode's return discounted per primitive step.

With --speed SECONDS it writes nothing and prints the reference env's primitive steps per second
under random macro-actions instead (the Python side of the environment-speed comparison).

Setup (Python 3.11; gym 0.26 runs the reference unchanged):
  python3.11 -m venv venv && venv/bin/pip install numpy gym==0.26.2
  # a checkout of github.com/yuchen-x/MacroMARL at MACROMARL
  venv/bin/python scripts/macromarl_traces.py --macromarl MACROMARL --env BP-MA-v0 \\
      --params '{"grid_dim": [6, 6], "big_box_reward": 300, "small_box_reward": 20, "penalty": -10}' \\
      --random-seed 0 --horizon 100 --out tests/fixtures/macromarl/bp_ma_6_random0
"""

import argparse
import gzip
import json
import os
import sys

from reference_stand_ins import install_pygame


def as_floats(values):
    return [float(v) for v in values]


def as_ints(values):
    return [int(v) for v in values]


def speed(env, args):
    """Primitive steps per second of `env` under uniformly random macro-actions for the free
    agents (numpy's RandomState, seed --random-seed or 0), as macdec's `bench envs` measures."""
    import time

    import numpy as np

    rng = np.random.RandomState(args.random_seed or 0)
    n_actions = list(env.n_action)
    steps = episodes = 0
    start = time.perf_counter()
    while time.perf_counter() - start < args.speed:
        env.reset()
        episodes += 1
        free = [True] * env.n_agent
        for _ in range(args.horizon):
            actions = [int(rng.randint(n)) if free[i] else -1 for i, n in enumerate(n_actions)]
            _, _, done, info = env.step(actions)
            steps += 1
            free = [bool(d) for d in info["mac_done"]]
            if done:
                break
    seconds = time.perf_counter() - start
    return {
        "steps": steps,
        "episodes": episodes,
        "seconds": seconds,
        "steps_per_second": steps / seconds,
    }


def actor_policy(directory):
    """The trained actors in `directory` (agent_state_dict*.pt in file-name order) as a function
    from (free flags, observations) to joint actions, greedy, each GRU state carried across its
    agent's own decisions. The module is MacroMARL's Actor (fc1, fc2, GRU, fc3, fc4,
    log_softmax), rebuilt here with the sizes the state_dict implies."""
    import glob

    import torch
    import torch.nn.functional as F

    class Actor(torch.nn.Module):
        def __init__(self, sd):
            super().__init__()
            m0, obs = sd["fc1.weight"].shape
            hidden = sd["gru.weight_hh_l0"].shape[1]
            m1 = sd["fc3.weight"].shape[0]
            actions = sd["fc4.weight"].shape[0]
            self.fc1 = torch.nn.Linear(obs, m0)
            self.fc2 = torch.nn.Linear(m0, m0)
            self.gru = torch.nn.GRU(m0, hidden, num_layers=1, batch_first=True)
            self.fc3 = torch.nn.Linear(hidden, m1)
            self.fc4 = torch.nn.Linear(m1, actions)
            self.load_state_dict(sd)

        def forward(self, x, h):
            x = F.leaky_relu(self.fc1(x))
            x = F.leaky_relu(self.fc2(x))
            x, h = self.gru(x, h)
            x = F.leaky_relu(self.fc3(x))
            return F.log_softmax(self.fc4(x), dim=-1), h

    files = sorted(glob.glob(os.path.join(directory, "*.pt")))
    actors = [Actor(torch.load(f, map_location="cpu")) for f in files]
    hidden = [None] * len(actors)

    def act(free, obs):
        actions = []
        with torch.no_grad():
            for i, actor in enumerate(actors):
                if not free[i]:
                    actions.append(-1)
                    continue
                x = torch.as_tensor(obs[i], dtype=torch.float32).view(1, 1, -1)
                logp, hidden[i] = actor(x, hidden[i])
                actions.append(int(logp.view(-1).argmax()))
        return actions

    return act


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--macromarl", required=True, help="a MacroMARL checkout (its src/ is imported)")
    parser.add_argument(
        "--overcooked", help="a gym-macro-overcooked checkout, for Overcooked-MA-v1"
    )
    parser.add_argument("--env", required=True, help="gym id, e.g. BP-MA-v0")
    parser.add_argument("--params", default="{}", help="JSON object of the env's keyword arguments")
    parser.add_argument("--steps", help="JSON file: a list of joint actions (-1 for busy agents)")
    parser.add_argument("--plan", help="JSON list per agent of macro-actions started in order")
    parser.add_argument("--random-seed", type=int, help="draw the free agents' actions at random")
    parser.add_argument("--actors", help="directory of trained agent_state_dict*.pt files")
    parser.add_argument("--gamma", type=float, default=1.0, help="discount of the printed return")
    parser.add_argument("--horizon", type=int, default=100, help="most steps of a random episode")
    parser.add_argument("--out", help="output path without extension")
    parser.add_argument(
        "--speed",
        type=float,
        help="instead of a trace: step random macro-actions for this many seconds (resetting at "
        "the end of an episode or --horizon) and print primitive steps per second",
    )
    args = parser.parse_args()
    if args.speed is None and [args.steps, args.plan, args.random_seed, args.actors].count(None) != 3:
        parser.error("give exactly one of --steps, --plan, --random-seed and --actors")
    if args.speed is None and args.out is None:
        parser.error("give --out (or --speed)")

    sys.path.insert(0, os.path.join(args.macromarl, "src"))
    # The env files import IPython (for debugging) but never use it: a stand-in will do.
    try:
        import IPython  # noqa: F401
    except ImportError:
        import types

        for name in ["IPython", "IPython.core", "IPython.core.debugger"]:
            sys.modules[name] = types.ModuleType(name)
        sys.modules["IPython.core.debugger"].set_trace = lambda *a, **k: None
    import gym
    import numpy as np
    import macro_marl.my_env  # noqa: F401  (registers the gym ids)

    params = json.loads(args.params)
    kwargs = dict(params)
    if "grid_dim" in kwargs:
        kwargs["grid_dim"] = tuple(kwargs["grid_dim"])
    if args.env.startswith("Overcooked"):
        if not args.overcooked:
            parser.error("Overcooked needs --overcooked DIR")
        sys.path.insert(0, args.overcooked)
        # Overcooked imports pygame only to draw; a stand-in module is enough to step it.
        install_pygame()
        import gym_macro_overcooked  # noqa: F401  (registers the gym ids)
        from gym_macro_overcooked.macActEnvWrapper import MacEnvWrapper

        # As scripts/pg_based_main.py builds it: the macro-action env behind MacEnvWrapper.
        env = MacEnvWrapper(gym.make(args.env, disable_env_checker=True, **kwargs).unwrapped)
    else:
        env = gym.make(args.env, disable_env_checker=True, **kwargs).unwrapped
    has_state = callable(getattr(env, "get_state", None))
    n_actions = list(env.n_action)

    def state_fields():
        return {"state": as_floats(np.asarray(env.get_state()).ravel())} if has_state else {}

    if args.speed is not None:
        print(json.dumps({"env": args.env, "params": params, **speed(env, args)}))
        return

    lines = []
    obs = env.reset()
    # OSD-T-v1 and OSD-F-v0 define get_state() only to raise NotImplementedError.
    if has_state:
        try:
            env.get_state()
        except NotImplementedError:
            has_state = False
    lines.append({"t": 0, "obs": [as_floats(o) for o in obs], **state_fields()})

    given = None
    if args.steps:
        with open(args.steps) as f:
            given = json.load(f)
    rng = np.random.RandomState(args.random_seed if args.random_seed is not None else 0)
    plan = json.loads(args.plan) if args.plan else None
    actors = actor_policy(args.actors) if args.actors else None
    last_obs = obs
    started = [0] * env.n_agent
    free = [True] * env.n_agent
    steps = []
    t = 0
    while True:
        if given is not None:
            if t == len(given):
                break
            actions = [int(a) for a in given[t]]
        else:
            if t == args.horizon:
                break
            if actors is not None:
                actions = actors(free, last_obs)
            elif plan is not None:
                actions = []
                for i in range(env.n_agent):
                    if free[i]:
                        actions.append(int(plan[i][min(started[i], len(plan[i]) - 1)]))
                        started[i] += 1
                    else:
                        actions.append(-1)
            else:
                actions = [
                    int(rng.randint(n)) if free[i] else -1 for i, n in enumerate(n_actions)
                ]
        steps.append(actions)
        obs, rewards, done, info = env.step(actions)
        last_obs = obs
        t += 1
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
        if done and given is None:
            break

    with open(args.out + ".actions.json", "w") as f:
        json.dump({"env": args.env, "params": params, "steps": steps}, f)
        f.write("\n")
    text = "".join(json.dumps(line, separators=(",", ":")) + "\n" for line in lines)
    with open(args.out + ".trace.jsonl.gz", "wb") as raw:
        with gzip.GzipFile(filename="", mode="wb", compresslevel=9, fileobj=raw, mtime=0) as f:
            f.write(text.encode())
    discounted = sum(args.gamma ** (l["t"] - 1) * l["reward"] for l in lines[1:])
    print(
        f"{args.out}: {len(steps)} steps, return {sum(l.get('reward', 0.0) for l in lines):.4f}"
        f", discounted by {args.gamma}: {discounted:.4f}"
    )


if __name__ == "__main__":
    main()
