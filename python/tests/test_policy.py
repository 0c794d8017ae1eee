"""Policy: loads a run's policy/, an export and a run directory; acting through parallel_env
gives exactly `macdec eval`'s episodes (Q-nets and actors)."""

import json

import numpy as np
import pytest

import macdec

VALUE = {
    "name": "pol", "methods": ["our1"], "seeds": "4",
    "params": {"env_name": "OSD_S_4", "env_terminate_step": 60, "total_epi": 30, "eps_l_d_steps": 20,
               "batch_size": 8, "replay_buffer_size": 500, "eval_freq": 10},
}
ACTOR = {
    "name": "pol_ac", "methods": ["mac-iac"], "seeds": "2",
    "params": {"env_name": "BP-MA-v0", "grid_dim": [6, 6], "env_terminate_step": 40, "total_epi": 16,
               "n_env": 4, "train_freq": 8, "eval_freq": 8},
}


def episode(policy, env, seed):
    """One greedy episode: (discounted return, undiscounted return, executed per step)."""
    obs, infos = env.reset(seed=seed)
    policy.reset()
    ret, plain, weight, trace = 0.0, 0.0, 1.0, []
    while env.agents:
        actions, scores = policy.act(obs, infos, return_scores=True)
        for a, s in scores.items():
            assert infos[a]["mac_done"] and actions[a] == int(np.argmax(s))
        obs, rew, _, _, infos = env.step(actions)
        r = rew["agent_0"]
        ret, plain, weight = ret + weight * r, plain + r, weight * policy.discount
        trace.append([infos[a]["executed"] for a in env.possible_agents])
    return ret, plain, trace


@pytest.mark.parametrize("config", [VALUE, ACTOR], ids=["q-nets", "actors"])
def test_acting_equals_macdec_eval(config, tmp_path, run_cli):
    (run,) = macdec.train(config, out=tmp_path)
    export = tmp_path / "export"
    run_cli("export", "--run", run, "--out", export)
    for where in (run, run / "policy", export):
        policy = macdec.Policy.load(where)
        assert policy.run["seed"] == int(config["seeds"]) and policy.env_id == config["params"]["env_name"]
        env = policy.make_env()
        line = json.loads(run_cli("eval", "--policy", where if where != run else run / "policy", "--trajectories").splitlines()[0])
        ret, plain, trace = episode(policy, env, seed=0)
        assert ret == line["return"] and plain == line["undiscounted_return"], where
        assert trace == [s["executed"] for s in line["trajectory"]]
    kinds = macdec.Policy.load(run).kinds
    assert kinds == (["q"] * 3 if config is VALUE else ["actor"] * 2)


def test_a_busy_agent_keeps_its_action_and_its_hidden_state(tmp_path):
    (run,) = macdec.train(VALUE, out=tmp_path)
    p = macdec.Policy.load(run)
    env = p.make_env()
    obs, infos = env.reset(seed=0)
    first = p.act(obs, infos)
    s0 = {a: s.copy() for a, s in p.scores.items()}
    assert set(first) == set(env.agents) and set(s0) == set(env.agents)
    # Not done: no agent decides, nothing moves; the same observation again after a reset
    # gives the same scores (the hidden state did not advance).
    assert p.act(obs, {a: False for a in env.agents}) == first and p.scores == {}
    p.reset()
    p.act(obs, infos)
    assert all(np.array_equal(p.scores[a], s0[a]) for a in s0)
    p.act(obs, infos)
    assert any(not np.array_equal(p.scores[a], s0[a]) for a in s0), "the hidden state must advance"


def test_bad_policy_directories_and_observations_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere"):
        macdec.Policy.load(tmp_path / "nowhere")
    with pytest.raises(ValueError, match="policy.json"):
        macdec.Policy.load(tmp_path)
    (run,) = macdec.train(VALUE, out=tmp_path / "r")
    p = macdec.Policy.load(run)
    with pytest.raises(ValueError, match="agent 2: observation has 3 values, the policy expects 4"):
        p.act([np.zeros(13), np.zeros(13), np.zeros(3)], [True, True, True])
    with pytest.raises(ValueError, match="one per agent"):
        p.act([np.zeros(13)], [True])


def test_a_failed_act_leaves_every_agent_as_it_was(tmp_path):
    (run,) = macdec.train(VALUE, out=tmp_path)
    p = macdec.Policy.load(run)
    env = p.make_env()
    obs, infos = env.reset(seed=0)
    p.act(obs, infos)
    first = {a: s.copy() for a, s in p.scores.items()}
    p.reset()
    # The last agent's observation overflows its net; the agents before it decided first in
    # the loop and must not have advanced either.
    last = env.agents[-1]
    bad = dict(obs)
    bad[last] = np.full_like(obs[last], np.finfo(np.float32).max)
    with pytest.raises(RuntimeError, match=r"agent 2: the net answered a non-finite .*no agent's state changed"):
        p.act(bad, infos)
    p.act(obs, infos)
    assert all(np.array_equal(p.scores[a], first[a]) for a in first), "a failed act advanced a hidden state"


def test_a_rust_panic_is_a_runtime_error_not_a_base_exception():
    from macdec import _macdec

    try:
        _macdec._panic_for_test()
    except Exception as e:  # noqa: BLE001 - the point: `except Exception` must see it
        assert type(e) is RuntimeError and "internal error in macdec: a test panic" in str(e), repr(e)
    else:
        raise AssertionError("no error")
