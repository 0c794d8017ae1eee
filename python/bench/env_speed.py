"""Primitive steps per second seen from Python: macdec.parallel_env (one PettingZoo step per
Python call, dicts in and out) and macdec.vector_env (N copies per call, NumPy in and out),
random macro-actions for the free agents, resets at episode ends, one thread.

    python python/bench/env_speed.py [--seconds 3] [--only BP-MA-v0]

The reference's own Python environments, stepped the same way, are measured by
scripts/macromarl_speed.sh (docs/PERFORMANCE.md, issue 27).
"""

import argparse
import json
import random
import time

import numpy as np

import macdec

SETTINGS = [
    ("BP-MA-v0", {"grid_dim": [10, 10]}),
    ("OSD-D-v7", {}),
    ("Overcooked-MA-v1", {"map_type": "A"}),
    ("BP_MA", {"grid_dim": 10, "env_terminate_step": 100}),
]


def parallel_speed(env_id, params, seconds):
    env = macdec.parallel_env(env_id, **params)
    n = {a: env.action_space(a).n for a in env.possible_agents}
    obs, infos = env.reset(seed=0)
    steps, start = 0, time.perf_counter()
    rnd = random.Random(0)
    while True:
        actions = {a: rnd.randrange(n[a]) for a in env.agents if infos[a]["mac_done"]}
        obs, rew, term, trunc, infos = env.step(actions)
        steps += 1
        if not env.agents:
            obs, infos = env.reset()
        if steps % 256 == 0 and time.perf_counter() - start >= seconds:
            return steps / (time.perf_counter() - start)


def vector_speed(env_id, params, num_envs, seconds):
    venv = macdec.vector_env(env_id, num_envs, **params)
    rng = np.random.default_rng(0)
    high = np.array(venv.n_actions)
    # Pre-drawn actions: the sampling is the learner's cost, not the environment's.
    pool = [rng.integers(0, high, size=(num_envs, venv.n_agents)) for _ in range(64)]
    venv.reset(seed=0)
    calls, start = 0, time.perf_counter()
    while True:
        venv.step(pool[calls % 64])
        calls += 1
        if calls % 16 == 0 and time.perf_counter() - start >= seconds:
            return calls * num_envs / (time.perf_counter() - start)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=3.0)
    p.add_argument("--only")
    p.add_argument("--num-envs", type=int, nargs="*", default=[1, 64, 1024])
    args = p.parse_args()
    for env_id, params in SETTINGS:
        if args.only and args.only != env_id:
            continue
        row = {"env": env_id, "params": params, "parallel_env": round(parallel_speed(env_id, params, args.seconds))}
        for n in args.num_envs:
            row[f"vector_env_{n}"] = round(vector_speed(env_id, params, n, args.seconds))
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
