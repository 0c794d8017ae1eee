"""Policy.load and Policy.act on a trained run of every method (issue 40 item 3; ACAC's, whose
actors read the step, issue 41):
greedy acting gives exactly `macdec eval`'s episode, whether the policy is one net per agent or
one centralized net for the team (Cen-DDRQN, Mac-CAC); sample=True gives exactly
`macdec eval --sample`'s episode for actors and is refused for Q-nets."""

import json

import numpy as np
import pytest

import macdec

VALUE = {
    "name": "every", "methods": ["dec-hddrqn", "cen-ddrqn", "our1", "our1-r", "our2"], "seeds": "1",
    "params": {"env_name": "BP_MA", "grid_dim": 8, "env_terminate_step": 30, "total_epi": 40,
               "eps_l_d_steps": 10, "batch_size": 8, "replay_buffer_size": 500, "eval_freq": 20,
               "sample_epi": True},
}
ACTOR = {
    "name": "every_ac",
    "methods": ["mac-iac", "mac-cac", "naive-mac-iacc", "naive-mac-iasc", "mac-iaicc", "mac-iaisc"],
    "seeds": "0",
    "params": {"env_name": "BP-MA-v0", "grid_dim": [6, 6], "env_terminate_step": 30, "total_epi": 16,
               "n_env": 4, "train_freq": 4, "c_target_update_freq": 8, "eval_freq": 8, "eval_num_epi": 2},
}
ACAC = {
    "name": "every_acac", "methods": ["acac", "acac-vanilla", "acac-micro-gae"], "seeds": "0",
    "params": {"env_name": "BP-MA-v0", "grid_dim": [6, 6], "env_terminate_step": 30, "total_epi": 12,
               "n_env": 4, "train_freq": 4, "c_target_update_freq": 8, "eval_freq": 8, "eval_num_epi": 2},
}
CENTRALIZED = {"cen-ddrqn", "mac-cac"}


def episode(policy, env, sample):
    """One episode from the env's seed-0 reset: (discounted, undiscounted, executed per step)."""
    obs, infos = env.reset(seed=0)
    policy.reset()
    ret, plain, weight, trace = 0.0, 0.0, 1.0, []
    while env.agents:
        actions, scores = policy.act(obs, infos, return_scores=True, sample=sample)
        deciding = [a for a in env.agents if infos[a]["mac_done"]]
        if policy.centralized:
            # One decision for the team, over joint macro-actions.
            assert list(scores) == (["team"] if deciding else [])
            assert all(len(s) == int(np.prod(policy._core.n_actions)) for s in scores.values())
        else:
            assert sorted(scores) == sorted(deciding)
            if not sample:
                assert all(actions[a] == int(np.argmax(s)) for a, s in scores.items())
        obs, rew, _, _, infos = env.step(actions)
        r = rew["agent_0"]
        ret, plain, weight = ret + weight * r, plain + r, weight * policy.discount
        trace.append([infos[a]["executed"] for a in env.possible_agents])
    return ret, plain, trace


def eval_line(run_cli, run, *flags):
    return json.loads(run_cli("eval", "--policy", run / "policy", "--trajectories", *flags).splitlines()[0])


@pytest.mark.parametrize("config", [VALUE, ACTOR, ACAC], ids=["value", "actor-critic", "acac"])
def test_every_method_acts_as_macdec_eval_greedy_and_sampled(config, tmp_path, run_cli):
    runs = macdec.train(config, out=tmp_path)
    assert len(runs) == len(config["methods"])
    actors = config is not VALUE
    for run in runs:
        method = run.parent.name
        policy = macdec.Policy.load(run)
        assert policy.run["method"] == method
        assert policy.centralized == (method in CENTRALIZED), method
        assert policy.kinds == ["actor" if actors else "q"] * policy._core.n_agents
        env = policy.make_env()
        ret, plain, trace = episode(policy, env, sample=False)
        line = eval_line(run_cli, run)
        assert (ret, plain) == (line["return"], line["undiscounted_return"]), method
        assert trace == [s["executed"] for s in line["trajectory"]], method
        if actors:
            # A fresh load starts the sampling streams where `eval --sample` starts them.
            sampled = episode(macdec.Policy.load(run), env, sample=True)
            line = eval_line(run_cli, run, "--sample")
            assert sampled[1] == line["undiscounted_return"], method
            assert sampled[2] == [s["executed"] for s in line["trajectory"]], method
        else:
            obs, infos = env.reset(seed=0)
            with pytest.raises(ValueError, match="is a Q-net, whose scores are Q-values"):
                policy.act(obs, infos, sample=True)


def test_a_centralized_policy_keeps_busy_agents_and_names_a_missing_decision(tmp_path):
    (run,) = macdec.train({**ACTOR, "methods": ["mac-cac"]}, out=tmp_path)
    p = macdec.Policy.load(run)
    assert p.centralized and p.kinds == ["actor", "actor"]
    env = p.make_env()
    obs, infos = env.reset(seed=0)
    # Before any decision, a busy agent has no running macro-action to keep.
    with pytest.raises(ValueError, match="agent 1 is not done but has no macro-action yet"):
        p.act(obs, [True, False])
    first = p.act(obs, infos)
    assert set(first) == set(env.agents) and list(p.scores) == ["team"]
    # Agent 0 busy: whatever the team net now prefers, agent 0 keeps its macro-action.
    for _ in range(5):
        again = p.act(obs, [False, True])
        assert again["agent_0"] == first["agent_0"]
    # Nobody done: nothing is decided and the net does not step.
    assert p.act(obs, [False, False]) == again and p.scores == {}


@pytest.mark.parametrize("method,net", [("mac-cac", "centralized actor"), ("cen-ddrqn", "centralized Q-net")])
def test_a_failed_centralized_act_names_the_net_and_changes_nothing(method, net, tmp_path):
    config = {**ACTOR, "methods": [method]} if method == "mac-cac" else {**VALUE, "methods": [method]}
    (run,) = macdec.train(config, out=tmp_path)
    p = macdec.Policy.load(run)
    env = p.make_env()
    obs, infos = env.reset(seed=0)
    p.act(obs, infos)
    first = p.scores["team"].copy()
    p.reset()
    bad = {a: np.full_like(o, np.finfo(np.float32).max) for a, o in obs.items()}
    with pytest.raises(RuntimeError, match=rf"the {net} answered a non-finite .*its state is unchanged"):
        p.act(bad, infos)
    # The team's hidden state did not advance: the same observation gives the same scores.
    p.act(obs, infos)
    assert np.array_equal(p.scores["team"], first), "a failed act advanced the team's hidden state"
