"""parallel_env: PettingZoo's API test on every domain, the same trajectory as `macdec replay`,
macro-action semantics, errors; vector_env equals N single environments."""

import json
import subprocess
import warnings

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test

import macdec

IDS = macdec.env_ids()


def test_every_built_in_domain_is_listed():
    assert IDS == ["BP_MA", "BP-MA-v0", "OSD_S_4", "OSD-D-v7", "OSD-T-v0", "OSD-T-v1", "OSD-F-v0", "Overcooked-MA-v1", "ACAC-Overcooked-MA-v1", "ACAC-Overcooked-MA-v0"]


def test_version_is_the_crates(root):
    import tomllib

    with open(root / "Cargo.toml", "rb") as f:
        assert macdec.__version__ == tomllib.load(f)["workspace"]["package"]["version"]


@pytest.mark.parametrize("env_id", IDS)
def test_pettingzoo_parallel_api_test_passes_without_warnings(env_id):
    env = macdec.parallel_env(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parallel_api_test(env, num_cycles=1000)


def random_episode(env, seed, rng):
    """Play one episode with random macro-actions (-1 for busy agents, as reference logs do)."""
    obs, infos = env.reset(seed=seed)
    steps, frames = [], []
    while env.agents:
        actions, row = {}, []
        for a in env.possible_agents:
            if infos[a]["mac_done"]:
                actions[a] = int(rng.integers(env.action_space(a).n))
                row.append(actions[a])
            else:
                row.append(-1)
        obs, rew, term, trunc, infos = env.step(actions)
        steps.append(row)
        a0 = env.possible_agents[0]
        frames.append({
            "obs": [obs[a].tolist() for a in env.possible_agents],
            "reward": rew[a0],
            "mac_done": [int(infos[a]["mac_done"]) for a in env.possible_agents],
            "executed": [infos[a]["executed"] for a in env.possible_agents],
            "state": env.state().tolist() if env.state_space is not None else None,
            "ended": term[a0] or trunc[a0],
        })
    return steps, frames


@pytest.mark.parametrize("env_id", IDS)
def test_a_random_episode_equals_macdec_replay_of_its_actions(env_id, run_cli, tmp_path):
    env = macdec.parallel_env(env_id)
    steps, frames = random_episode(env, 0, np.random.default_rng(1))
    assert frames[-1]["ended"] and len(steps) > 3
    log = tmp_path / "log.json"
    log.write_text(json.dumps({"env": env_id, "params": env.params, "steps": steps}))
    lines = [json.loads(l) for l in run_cli("replay", "--actions", log).splitlines()]
    assert len(lines) == len(frames) + 1
    for line, frame in zip(lines[1:], frames):
        for got, want in zip(line["obs"], frame["obs"], strict=True):
            assert np.array_equal(np.array(got, dtype=np.float32), np.array(want, dtype=np.float32))
        assert line["reward"] == frame["reward"]
        assert line["mac_done"] == frame["mac_done"]
        assert line["executed"] == frame["executed"]
        if frame["state"] is not None:
            assert np.array_equal(np.array(line["state"], dtype=np.float32), np.array(frame["state"], dtype=np.float32))


def test_a_busy_agent_keeps_its_macro_action_whatever_it_is_sent():
    env = macdec.parallel_env("BP_MA", grid_dim=10, env_terminate_step=100)
    obs, infos = env.reset(seed=0)
    assert env.action_names("agent_0")[0] == "GT_SB0"  # walks to small box 0: several steps
    obs, _, _, _, infos = env.step({"agent_0": 0, "agent_1": 0})
    busy = [a for a in env.agents if not infos[a]["mac_done"]]
    assert busy, "a multi-step macro-action must leave its agent busy"
    for a in busy:
        running = infos[a]["executed"]
        mask = infos[a]["action_mask"]
        assert mask.tolist() == [int(i == running) for i in range(env.action_space(a).n)]
        other = (running + 1) % env.action_space(a).n
        free = {f: 0 for f in env.agents if infos[f]["mac_done"]}
        _, _, _, _, infos = env.step({**free, a: other})
        assert infos[a]["executed"] == running


def test_the_horizon_is_a_truncation():
    env = macdec.parallel_env("BP_MA", grid_dim=8, env_terminate_step=5)
    env.reset(seed=0)
    stay = env.action_names("agent_0").index("Stay")
    for t in range(5):
        _, _, term, trunc, _ = env.step({a: stay for a in env.agents})
    assert trunc == {"agent_0": True, "agent_1": True} and not any(term.values())
    assert env.agents == []
    with pytest.raises(RuntimeError, match="reset"):
        env.step({})


def test_bad_input_raises_errors_naming_the_problem():
    with pytest.raises(ValueError, match="Pong"):
        macdec.parallel_env("Pong")
    with pytest.raises(ValueError, match="gird"):
        macdec.parallel_env("BP_MA", gird=10)
    with pytest.raises(ValueError, match="grid_dim"):
        macdec.parallel_env("BP_MA", grid_dim=3)
    with pytest.raises(ValueError, match="grid_dim"):
        macdec.parallel_env("BP_MA", grid_dim=object())
    env = macdec.parallel_env("BP_MA")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="agent 0 .*0..8, got 8"):
        env.step({"agent_0": 8, "agent_1": 0})
    with pytest.raises(ValueError, match="agent_1 may choose now"):
        env.step({"agent_0": 0})
    # Not truncated or parsed into another action: floats, strings, bools, arrays refused.
    for bad in (2.7, 2.0, "3", True, np.array([1, 2]), np.float64(1.0)):
        with pytest.raises(ValueError, match=r"agent_0: an action is one macro-action index, an integer in 0..8"):
            env.step({"agent_0": bad, "agent_1": 0})
    with pytest.raises(ValueError, match=r"agent_0: the macro-action must be in 0..8, got 1267650600228229401496703205376"):
        env.step({"agent_0": 2**100, "agent_1": 0})
    env.step({"agent_0": np.int64(1), "agent_1": np.array(0, dtype=np.uint8)})
    with pytest.raises(ValueError, match="unknown agent 'agent_7'"):
        env.step({"agent_0": 0, "agent_1": 0, "agent_7": 0})
    with pytest.raises(ValueError, match="num_envs"):
        macdec.vector_env("BP_MA", 0)
    for too_many in (10**7, 2**62):
        with pytest.raises(ValueError, match=r"num_envs must be 1..=65536"):
            macdec.vector_env("BP_MA", too_many)
    deep = 6
    for _ in range(100_000):
        deep = [deep]
    with pytest.raises(ValueError, match=r"parameter `grid_dim(\[0\])+`: lists and dicts nested more than 16 deep"):
        macdec.parallel_env("BP_MA", grid_dim=deep)
    with pytest.raises(ValueError, match="nested more than 16 deep"):
        macdec.vector_env("BP_MA", 2, grid_dim=deep)
    venv = macdec.vector_env("BP_MA", 2)
    venv.reset(seed=0)
    for shape in [(2, 3), (4,), (2, 2, 1), ()]:
        with pytest.raises(ValueError, match=r"shape \(num_envs, n_agents\) = \(2, 2\), got shape"):
            venv.step(np.zeros(shape, dtype=np.int64))
    with pytest.raises(ValueError, match=r"shape \(num_envs, n_agents\) = \(2, 2\), got a ragged"):
        venv.step([[0, 0], [0]])
    with pytest.raises(ValueError, match=r"env 1, agent 0: the macro-action must be in 0..8, got 18446744073709551615"):
        venv.step(np.array([[0, 0], [2**64 - 1, 0]], dtype=np.uint64))
    with pytest.raises(ValueError, match="env 1, agent 0"):
        venv.step(np.array([[0, 0], [9, 0]]))
    with pytest.raises(ValueError, match="integers"):
        venv.step(np.zeros((2, 2)))
    # Floats are refused, naming the entry, its agent's range and the value (not truncated).
    for bad, shown in [(np.inf, "inf"), (2.7, "2.7"), (-np.inf, "-inf"), (1e300, "1e\\+300"), ("3", "'3'")]:
        with pytest.raises(ValueError, match=rf"env 1, agent 0: an action is one macro-action index, an integer in 0..8, got {shown} "):
            venv.step(np.array([[0, 0], [bad, 0]], dtype=object if isinstance(bad, str) else float))


def test_step_before_reset_says_so():
    env = macdec.parallel_env("BP_MA")
    with pytest.raises(RuntimeError, match=r"step called before reset\(\)"):
        env.step({"agent_0": 0, "agent_1": 0})
    venv = macdec.vector_env("BP_MA", 2)
    with pytest.raises(RuntimeError, match=r"call reset\(\) before step\(\)"):
        venv.step(np.zeros((2, 2), dtype=np.int64))


def test_same_seed_same_episode_and_render_draws_rgb():
    a = macdec.parallel_env("OSD_S_4", render_mode="rgb_array", tb_m_noisy=0.1)
    b = macdec.parallel_env("OSD_S_4", tb_m_noisy=0.1)
    _, fa = random_episode(a, 7, np.random.default_rng(3))
    _, fb = random_episode(b, 7, np.random.default_rng(3))
    assert fa == fb
    _, fc = random_episode(b, 8, np.random.default_rng(3))
    assert fc != fa, "another seed must change the noisy episode (the test can fail)"
    img = a.render()
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3 and img.shape[1] == 420
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 3


@pytest.mark.parametrize("env_id,params", [("BP_MA", {"grid_dim": 8, "env_terminate_step": 40}), ("OSD_S_4", {"tb_m_noisy": 0.2}), ("Overcooked-MA-v1", {})])
def test_vector_env_equals_n_single_envs(env_id, params):
    n, seed, steps = 3, 11, 400
    venv = macdec.vector_env(env_id, n, **params)
    singles = [macdec.parallel_env(env_id, **params) for _ in range(n)]
    vobs, vinfo = venv.reset(seed=seed)
    sobs = [s.reset(seed=seed + k) for k, s in enumerate(singles)]
    rng = np.random.default_rng(0)
    ends = 0
    for _ in range(steps):
        acts = np.stack([rng.integers(0, venv.n_actions) for _ in range(n)])
        vobs, vrew, vterm, vtrunc, vinfo = venv.step(acts)
        for k, s in enumerate(singles):
            o, r, te, tr, inf = s.step({a: int(acts[k, i]) for i, a in enumerate(s.possible_agents)})
            for i, a in enumerate(s.possible_agents):
                size = venv.obs_sizes[i]
                assert np.array_equal(vinfo["final_obs"][k, i, :size], o[a])
                assert vinfo["final_mac_done"][k, i] == inf[a]["mac_done"]
                assert vinfo["executed"][k, i] == inf[a]["executed"]
            a0 = s.possible_agents[0]
            assert (vrew[k], vterm[k], vtrunc[k]) == (r[a0], te[a0], tr[a0])
            if te[a0] or tr[a0]:
                ends += 1
                o, inf = s.reset()
            for i, a in enumerate(s.possible_agents):
                size = venv.obs_sizes[i]
                assert np.array_equal(vobs[k, i, :size], o[a])
                assert not vobs[k, i, size:].any()
                # Who chooses next: after an auto-reset, every agent of the new episode.
                assert vinfo["mac_done"][k, i] == inf[a]["mac_done"]
                if te[a0] or tr[a0]:
                    assert vinfo["mac_done"][k, i]
                m = vinfo["action_mask"][k, i]
                assert m[: venv.n_actions[i]].astype(np.int8).tolist() == inf[a]["action_mask"].tolist()
    assert ends > 0, "no episode ended: the auto-reset was not tested"


def test_a_key_the_domain_does_not_read_is_refused_never_dropped(macdec_bin, tmp_path):
    # Box Pushing has no noise: 0.5 was kept as 0.0 and the episode ran noiseless.
    with pytest.raises(ValueError, match=r"`tb_m_noisy`.*leave it out"):
        macdec.parallel_env("BP_MA", tb_m_noisy=0.5)
    with pytest.raises(ValueError, match=r"`tb_m_noisy`"):
        macdec.vector_env("BP_MA", 2, tb_m_noisy=0.5)
    assert macdec.parallel_env("BP_MA", tb_m_noisy=0).params["tb_m_noisy"] == 0.0
    # MacroMARL's script passes these to every env; Box Pushing and the Warehouses do not read them.
    with pytest.raises(ValueError, match=r"`TB_move_speed`.*does not read it"):
        macdec.parallel_env("BP-MA-v0", TB_move_speed=0.6)
    with pytest.raises(ValueError, match=r"`n_agent`"):
        macdec.vector_env("OSD-D-v7", 2, n_agent=3)
    # `train` refuses the same keys, through the same check.
    cfg = tmp_path / "bp.toml"
    cfg.write_text('name = "bp"\nmethods = ["mac-iac"]\n[params]\nenv_name = "BP-MA-v0"\nTB_move_speed = 0.6\n')
    out = subprocess.run([str(macdec_bin), "train", "--config", str(cfg), "--out", str(tmp_path / "out")], capture_output=True, text=True)
    assert out.returncode != 0 and "`TB_move_speed`" in out.stderr, out.stderr
    with pytest.raises(ValueError, match="`TB_move_speed`"):
        macdec.train(config=str(cfg), out=str(tmp_path / "out2"))
