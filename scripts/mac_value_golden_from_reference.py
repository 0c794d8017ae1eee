#!/usr/bin/env python3
"""Golden fixtures of MacroMARL's value-based methods from the reference's own code.

Runs, for MacDecQ, MacCenQ and MacDecDDRQN, the reference's runner worker (`envs_runner.py: worker`,
`envs_runner_cen_condi.py: worker`) over a scripted environment with random observations,
rewards, availability masks and macro-action ends (one episode ending in a terminal state, the
others cut by the horizon); pushes the recorded episodes into the reference's memory
(`ReplayMemory_rand` windows with FIFO eviction, or `ReplayMemory_epi`); samples batches with
`np.random.choice(..., replace=False)` as its `sample` does; separates them with the team's own
`sep_joint_exps` (MacDecDDRQN: `cen_sep_joint_exps`, `dec_sep_joint_exps`); and runs the reference
learner (`QLearn_squ`, `QLearn_squ_cen_condi_0`, `QLearn_squ_dec_cen_0`) on
its `DDRQN` nets and Adam three times, with a hard target copy before the third. Everything is
written to tests/golden_mac_value/<case>.json: the scripted environment, every record the
runner produced, the sampled indices, the hysteresis of each update, the initial weights and
the weights after each update. `cargo test --test golden_mac_value` matches them without torch.

Usage: python scripts/mac_value_golden_from_reference.py /path/to/MacroMARL
(needs torch, numpy and IPython, which the reference's utils import).
"""

import json
import os
import sys
import threading
from multiprocessing import Pipe
from types import SimpleNamespace

import numpy as np
import torch

REF = sys.argv[1] if len(sys.argv) > 1 else "/tmp/macromarl"
sys.path.insert(0, os.path.join(REF, "src"))

from macro_marl.cores.value_based.mac_dec_q import envs_runner as dec_runner  # noqa: E402
from macro_marl.cores.value_based.mac_dec_q.learning_methods import QLearn_squ  # noqa: E402
from macro_marl.cores.value_based.mac_dec_q.model import DDRQN  # noqa: E402
from macro_marl.cores.value_based.mac_dec_q.team import Team_RNN as DecTeam  # noqa: E402
from macro_marl.cores.value_based.mac_dec_q.utils.Agent import Agent  # noqa: E402
from macro_marl.cores.value_based.mac_dec_q.utils import memory as dec_memory  # noqa: E402
from macro_marl.cores.value_based.mac_cen_q import envs_runner_cen_condi as cen_runner  # noqa: E402
from macro_marl.cores.value_based.mac_cen_q.learning_methods_cen_condi import (  # noqa: E402
    QLearn_squ_cen_condi_0,
)
from macro_marl.cores.value_based.mac_cen_q.model_cen_condi import DDRQN as CenDDRQN  # noqa: E402
from macro_marl.cores.value_based.mac_cen_q.team_cen_condi import Team_RNN as CenTeam  # noqa: E402
from macro_marl.cores.value_based.mac_cen_q.utils.Cen_ctrl import Cen_Controller  # noqa: E402
from macro_marl.cores.value_based.mac_cen_q.utils import memory_cen_condi as cen_memory  # noqa: E402
from macro_marl.cores.value_based.mac_dec_ddrqn import envs_runner as ddrqn_runner  # noqa: E402
from macro_marl.cores.value_based.mac_dec_ddrqn.learning_methods import (  # noqa: E402
    QLearn_squ_dec_cen_0,
)
from macro_marl.cores.value_based.mac_dec_ddrqn.model import DDRQN as DdrqnDec, Cen_DDRQN  # noqa: E402
from macro_marl.cores.value_based.mac_dec_ddrqn.team import Team_RNN as DdrqnTeam  # noqa: E402
from macro_marl.cores.value_based.mac_dec_ddrqn.utils.Agent import Agent as DdrqnAgent  # noqa: E402
from macro_marl.cores.value_based.mac_dec_ddrqn.utils.Cen_ctrl import Cen_Controller as DdrqnCen  # noqa: E402
from macro_marl.cores.value_based.mac_dec_ddrqn.utils import memory as ddrqn_memory  # noqa: E402
from macro_marl.cores.value_based.parallel_mac_dec_ddrqn import envs_runner as par_runner  # noqa: E402
from macro_marl.cores.value_based.parallel_mac_dec_ddrqn.learning_methods import (  # noqa: E402
    QLearn_squ_dec_cen_0 as ParQLearn,
)
from macro_marl.cores.value_based.parallel_mac_dec_ddrqn.model import (  # noqa: E402
    DDRQN as ParDec,
    Cen_DDRQN as ParCen,
)
from macro_marl.cores.value_based.parallel_mac_dec_ddrqn.team import Team_RNN as ParTeam  # noqa: E402
from macro_marl.cores.value_based.parallel_mac_dec_ddrqn.utils.Agent import Agent as ParAgent  # noqa: E402
from macro_marl.cores.value_based.parallel_mac_dec_ddrqn.utils.Cen_ctrl import Cen_Controller as ParCtrl  # noqa: E402
from macro_marl.cores.value_based.parallel_mac_dec_ddrqn.utils import memory as par_memory  # noqa: E402

OBS_SIZES = [3, 2]
N_ACTIONS = [3, 2]
DISCOUNT = 0.9
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "golden_mac_value")


class ScriptedEnv:
    """A macro-action env replaying a fixed trace: what the runner's worker reads off a real one."""

    def __init__(self, episode):
        self.episode = episode
        self.n_agent = len(OBS_SIZES)
        self.n_action = N_ACTIONS
        self.obs_size = OBS_SIZES

    def reset(self):
        self.t = 0
        self.avail = self.episode["reset_avail"]
        return [np.array(o, dtype=np.float32) for o in self.episode["reset_obs"]]

    def step(self, actions):
        s = self.episode["steps"][self.t]
        self.t += 1
        self.avail = s["avail"]
        obs = [np.array(o, dtype=np.float32) for o in s["obs"]]
        reward = [s["reward"]] * self.n_agent
        info = {"cur_mac": s["executed"], "mac_done": s["mac_done"]}
        return obs, reward, s["terminal"], info

    def get_avail_actions(self):
        return self.avail


def random_mask(rng, n):
    m = (rng.random(n) < 0.7).astype(int).tolist()
    if sum(m) == 0:
        m[rng.integers(n)] = 1
    return m


def script_episode(rng, length, terminal_at_end):
    """A random trace: per step the observations after it, the team reward, each agent's executed
    macro-action (held while it runs) and whether it ended, the masks after it."""
    steps = []
    running = [int(rng.integers(n)) for n in N_ACTIONS]
    free = [True] * len(N_ACTIONS)
    for t in range(length):
        executed = []
        for i, n in enumerate(N_ACTIONS):
            if free[i]:
                running[i] = int(rng.integers(n))
            executed.append(running[i])
        done = [bool(rng.random() < 0.45) for _ in N_ACTIONS]
        if t == length - 1 and terminal_at_end:
            done = [True] * len(N_ACTIONS)
        free = done
        steps.append(
            {
                "obs": [rng.normal(size=k).round(3).tolist() for k in OBS_SIZES],
                "reward": float(rng.choice([-0.1, -0.1, 1.0, -5.0, 10.0])),
                "executed": executed,
                "mac_done": done,
                "terminal": bool(terminal_at_end and t == length - 1),
                "avail": [random_mask(rng, n) for n in N_ACTIONS],
            }
        )
    return {
        "reset_obs": [rng.normal(size=k).round(3).tolist() for k in OBS_SIZES],
        "reset_avail": [random_mask(rng, n) for n in N_ACTIONS],
        "steps": steps,
    }


def run_worker(worker, episode, horizon):
    """Drive the reference's worker over one scripted episode in a thread, as the runner's parent
    does (reset, then step until terminate or the horizon); returns what it sent per step."""
    parent, child = Pipe()
    env = ScriptedEnv(episode)
    th = threading.Thread(target=worker, args=(child, env, DISCOUNT, 0), daemon=True)
    th.start()
    parent.send(("reset", None))
    reset = parent.recv()
    sent = []
    last_avail = reset[-1]
    for t in range(len(episode["steps"])):
        parent.send(("step", [0] * len(N_ACTIONS)))
        exp = parent.recv()
        sent.append((last_avail, exp))
        avail_at, terminate_at = {cen_runner.worker: (6, 7), ddrqn_runner.worker: (7, 8),
                                  par_runner.worker: (7, 8)}.get(worker, (5, 6))
        last_avail = exp[avail_at]
        if exp[terminate_at] or t + 1 == horizon:
            break
    parent.send(("close", None))
    th.join()
    return sent


def dec_records(sent):
    """The dec runner's `exp_to_tensor` layout: (last_obs, last_avail, a, r, gamma, obs, avail, t, v)."""
    out = []
    for last_avail, e in sent:
        out.append(
            (
                [torch.from_numpy(o).float() for o in e[0]],
                [torch.FloatTensor(a) for a in last_avail],
                [torch.tensor(a).view(1, -1) for a in e[1]],
                [torch.tensor(r).float().view(1, -1) for r in e[2]],
                [torch.tensor(g).float().view(1, -1) for g in e[3]],
                [torch.from_numpy(o).float() for o in e[4]],
                [torch.FloatTensor(a).view(1, -1) for a in e[5]],
                torch.tensor(e[6]).float().view(1, -1),
                [torch.tensor(v, dtype=torch.bool).view(1, -1) for v in e[7]],
            )
        )
    return out


def cen_records(sent):
    """The cen runner's layout: (last_obs, last_avail, a, id_r, joint_r, gamma, obs, avail, t, id_v, joint_v)."""
    out = []
    for last_avail, e in sent:
        out.append(
            (
                [torch.from_numpy(o).float() for o in e[0]],
                [torch.FloatTensor(a).view(1, -1) for a in last_avail],
                [torch.tensor(a).view(1, 1) for a in e[1]],
                [torch.tensor(r).float().view(1, -1) for r in e[2]],
                torch.tensor(e[3]).float().view(1, -1),
                torch.tensor(e[4]).float().view(1, -1),
                [torch.from_numpy(o).float() for o in e[5]],
                [torch.FloatTensor(a).view(1, -1) for a in e[6]],
                torch.tensor(e[7]).float().view(1, -1),
                [torch.tensor(v, dtype=torch.bool).view(1, -1) for v in e[8]],
                torch.tensor(e[9], dtype=torch.bool).view(1, -1),
            )
        )
    return out


def ddrqn_records(sent):
    """The MacDecDDRQN runner's `exp_to_tensor` layout: (last_obs, last_avail, a, id_r, joint_r,
    id_gamma, joint_gamma, obs, avail, t, id_v, joint_v)."""
    out = []
    for last_avail, e in sent:
        out.append(
            (
                [torch.from_numpy(o).float() for o in e[0]],
                [torch.FloatTensor(a).view(1, -1) for a in last_avail],
                [torch.tensor(a).view(1, -1) for a in e[1]],
                [torch.tensor(r).float().view(1, -1) for r in e[2]],
                torch.tensor(e[3]).float().view(1, -1),
                [torch.tensor(g).float().view(1, -1) for g in e[4]],
                torch.tensor(e[5]).float().view(1, -1),
                [torch.from_numpy(o).float() for o in e[6]],
                [torch.FloatTensor(a).view(1, -1) for a in e[7]],
                torch.tensor(e[8]).float().view(1, -1),
                [torch.tensor(v, dtype=torch.bool).view(1, -1) for v in e[9]],
                torch.tensor(e[10], dtype=torch.bool).view(1, -1),
            )
        )
    return out


def check_ddrqn_record(rec, d, c):
    """MacDecDDRQN's runner keeps both runners' accumulators: its per-agent ones must be MacDec-Q's
    and its joint ones MacCen-Q's (so one recorder serves all three)."""
    for a, b in zip(rec[3], d[3]):
        assert abs(a.item() - b.item()) < 1e-6
    for a, b in zip(rec[5], d[4]):
        assert abs(a.item() - b.item()) < 1e-6
    assert abs(rec[4].item() - c[4].item()) < 1e-6 and abs(rec[6].item() - c[5].item()) < 1e-6


def record_json(dec, cen):
    """One record as the Rust `Step` holds it, from both runners' outputs of the same step."""
    return {
        "obs": torch.cat(dec[0]).tolist(),
        "actions": [int(a.item()) for a in dec[2]],
        "rewards": [float(r.item()) for r in dec[3]],
        "gammas": [float(g.item()) for g in dec[4]],
        "joint_reward": float(cen[4].item()),
        "joint_gamma": float(cen[5].item()),
        "next_obs": torch.cat(dec[5]).tolist(),
        "next_avail": torch.cat([a.view(-1) for a in dec[6]]).tolist(),
        "terminal": bool(dec[7].item()),
        "valid": [bool(v.item()) for v in dec[8]],
    }


def weights(net):
    """The net's tensors in the order of macdec's GRU_ACTOR_TENSOR_NAMES (the reference's `rnn.*`
    is macdec's `gru.*`)."""
    sd = net.state_dict()
    names = ["fc1.weight", "fc1.bias", "fc2.weight", "fc2.bias", "rnn.weight_ih_l0",
             "rnn.weight_hh_l0", "rnn.bias_ih_l0", "rnn.bias_hh_l0", "fc3.weight", "fc3.bias",
             "fc4.weight", "fc4.bias"]
    return [sd[k].flatten().tolist() for k in names]


def make_case(alg, sample_epi, seed):
    rng = np.random.default_rng(seed)
    horizon = 9
    parallel = alg == "ParallelMacDecDDRQN"
    n_episodes = 10 if parallel else 6
    scripted = [script_episode(rng, int(rng.integers(4, 10)), k == 1) for k in range(n_episodes)]
    episodes_dec, episodes_cen, episodes_ddrqn, records = [], [], [], []
    for ep in scripted:
        d = dec_records(run_worker(dec_runner.worker, ep, horizon))
        c = cen_records(run_worker(cen_runner.worker, ep, horizon))
        dd = ddrqn_records(run_worker(par_runner.worker if parallel else ddrqn_runner.worker, ep, horizon))
        assert len(d) == len(c) == len(dd)
        for a, b, e in zip(dd, d, c):
            check_ddrqn_record(a, b, e)
        episodes_dec.append(d)
        episodes_cen.append(c)
        episodes_ddrqn.append(dd)
        records.append([record_json(a, b) for a, b in zip(d, c)])

    trace_len, capacity, batch_size = 4, 30, 5
    if sample_epi:
        capacity = 5
    torch.manual_seed(seed)
    mlp, rnn_h, lr = [6, 5], 4, 0.01
    hysteresis = [0.3, 0.55, 1.0]
    updates = []
    if alg == "MacDecQ":
        mem = (dec_memory.ReplayMemory_epi(2, OBS_SIZES, N_ACTIONS, batch_size, size=capacity)
               if sample_epi else
               dec_memory.ReplayMemory_rand(2, OBS_SIZES, N_ACTIONS, trace_len, batch_size, size=capacity))
        for ep in episodes_dec:
            mem.scenario_cache += ep
            mem.flush_scenario_cache()
        agents = []
        for i in range(2):
            a = Agent()
            a.idx = i
            a.policy_net = DDRQN(OBS_SIZES[i], N_ACTIONS[i], mlp_layer_size=mlp, rnn_h_size=rnn_h)
            a.target_net = DDRQN(OBS_SIZES[i], N_ACTIONS[i], mlp_layer_size=mlp, rnn_h_size=rnn_h)
            a.target_net.load_state_dict(a.policy_net.state_dict())
            a.optimizer = torch.optim.Adam(a.policy_net.parameters(), lr=lr)
            agents.append(a)
        nets = lambda: [weights(a.policy_net) for a in agents]  # noqa: E731
        team = SimpleNamespace(n_agent=2)
        sep = lambda b: DecTeam.sep_joint_exps(team, b)  # noqa: E731
    elif alg == "MacDecDDRQN":
        mem = (ddrqn_memory.ReplayMemory_epi(2, OBS_SIZES, N_ACTIONS, batch_size, size=capacity)
               if sample_epi else
               ddrqn_memory.ReplayMemory_rand(2, OBS_SIZES, N_ACTIONS, trace_len, batch_size, size=capacity))
        for ep in episodes_ddrqn:
            mem.scenario_cache += ep
            mem.flush_scenario_cache()
        sizes = dict(dec_mlp_layer_size=mlp, dec_rnn_h_size=rnn_h, cen_mlp_layer_size=[7, 6],
                     cen_rnn_h_size=5)
        agents = []
        for i in range(2):
            a = DdrqnAgent()
            a.idx = i
            a.policy_net = DdrqnDec(OBS_SIZES[i], N_ACTIONS[i], **sizes)
            a.target_net = DdrqnDec(OBS_SIZES[i], N_ACTIONS[i], **sizes)
            a.target_net.load_state_dict(a.policy_net.state_dict())
            a.optimizer = torch.optim.Adam(a.policy_net.parameters(), lr=lr)
            agents.append(a)
        ctrl = DdrqnCen()
        n_joint = int(np.prod(N_ACTIONS))
        ctrl.policy_net = Cen_DDRQN(sum(OBS_SIZES), n_joint, **sizes)
        ctrl.target_net = Cen_DDRQN(sum(OBS_SIZES), n_joint, **sizes)
        ctrl.target_net.load_state_dict(ctrl.policy_net.state_dict())
        ctrl.optimizer = torch.optim.Adam(ctrl.policy_net.parameters(), lr=lr)
        nets = lambda: [weights(a.policy_net) for a in agents] + [weights(ctrl.policy_net)]  # noqa: E731
        team = SimpleNamespace(n_agent=2, env=SimpleNamespace(n_action=N_ACTIONS))
        sep = lambda b: (DdrqnTeam.cen_sep_joint_exps(team, b), DdrqnTeam.dec_sep_joint_exps(team, b))  # noqa: E731
    elif parallel:
        def memory():
            return (par_memory.ReplayMemory_epi(2, OBS_SIZES, N_ACTIONS, batch_size, size=capacity)
                    if sample_epi else
                    par_memory.ReplayMemory_rand(2, OBS_SIZES, N_ACTIONS, trace_len, batch_size, size=capacity))
        # The centralized runner's episodes (the first half) and the agents' (the second).
        mem_cen, mem = memory(), memory()
        half = n_episodes // 2
        for k, ep in enumerate(episodes_ddrqn):
            m = mem_cen if k < half else mem
            m.scenario_cache += ep
            m.flush_scenario_cache()
        sizes = dict(dec_mlp_layer_size=mlp, dec_rnn_h_size=rnn_h, cen_mlp_layer_size=[7, 6],
                     cen_rnn_h_size=5)
        agents = []
        for i in range(2):
            a = ParAgent()
            a.idx = i
            a.policy_net = ParDec(OBS_SIZES[i], N_ACTIONS[i], **sizes)
            a.target_net = ParDec(OBS_SIZES[i], N_ACTIONS[i], **sizes)
            a.target_net.load_state_dict(a.policy_net.state_dict())
            a.optimizer = torch.optim.Adam(a.policy_net.parameters(), lr=lr)
            agents.append(a)
        ctrl = ParCtrl()
        n_joint = int(np.prod(N_ACTIONS))
        ctrl.policy_net = ParCen(sum(OBS_SIZES), n_joint, **sizes)
        ctrl.target_net = ParCen(sum(OBS_SIZES), n_joint, **sizes)
        ctrl.target_net.load_state_dict(ctrl.policy_net.state_dict())
        ctrl.optimizer = torch.optim.Adam(ctrl.policy_net.parameters(), lr=lr)
        nets = lambda: [weights(a.policy_net) for a in agents] + [weights(ctrl.policy_net)]  # noqa: E731
        team = SimpleNamespace(n_agent=2, env=SimpleNamespace(n_action=N_ACTIONS),
                               env_dec=SimpleNamespace(n_action=N_ACTIONS),
                               env_cen=SimpleNamespace(n_action=N_ACTIONS))
    else:
        mem = (cen_memory.ReplayMemory_epi(2, OBS_SIZES, N_ACTIONS, batch_size, size=capacity)
               if sample_epi else
               cen_memory.ReplayMemory_rand(2, OBS_SIZES, N_ACTIONS, trace_len, batch_size, size=capacity))
        for ep in episodes_cen:
            mem.scenario_cache += ep
            mem.flush_scenario_cache()
        ctrl = Cen_Controller()
        n_joint = int(np.prod(N_ACTIONS))
        ctrl.policy_net = CenDDRQN(sum(OBS_SIZES), n_joint, mlp_layer_size=mlp, rnn_h_size=rnn_h)
        ctrl.target_net = CenDDRQN(sum(OBS_SIZES), n_joint, mlp_layer_size=mlp, rnn_h_size=rnn_h)
        ctrl.target_net.load_state_dict(ctrl.policy_net.state_dict())
        ctrl.optimizer = torch.optim.Adam(ctrl.policy_net.parameters(), lr=lr)
        nets = lambda: [weights(ctrl.policy_net)]  # noqa: E731
        team = SimpleNamespace(n_agent=2, env=SimpleNamespace(n_action=N_ACTIONS))
        sep = lambda b: CenTeam.sep_joint_exps(team, b)  # noqa: E731
    init = nets()
    np.random.seed(seed)
    for k, h in enumerate(hysteresis):
        sync = k == 2
        if sync:
            if alg != "MacCenQ":
                for a in agents:
                    a.target_net.load_state_dict(a.policy_net.state_dict())
            if alg != "MacDecQ":
                ctrl.target_net.load_state_dict(ctrl.policy_net.state_dict())
        # The memory's own `sample`, with its indices kept.
        def sample(m):
            indices = np.random.choice(len(m.buf), batch_size, replace=False)
            batch = [m.buf[i] for i in indices]
            if sample_epi:
                batch, length = m.padding_batches(batch)
            else:
                length = trace_len
            return indices, batch, length
        cen_indices = []
        if parallel:
            # `Team_RNN.train`: the centralized memory is sampled first.
            cen_indices, batch_cen, len_cen = sample(mem_cen)
        indices, batch, length = sample(mem)
        if parallel:
            batch = (ParTeam.cen_sep_joint_exps(team, batch_cen), ParTeam.cen_sep_joint_exps(team, batch),
                     ParTeam.dec_sep_joint_exps(team, batch))
            params = dict(trace_lens=(len_cen, length), sub_trace_len=1, batch_size=batch_size)
        else:
            batch = sep(batch)
            params = dict(trace_len=length, sub_trace_len=1, batch_size=batch_size)
        if parallel:
            ParQLearn(SimpleNamespace(n_action=N_ACTIONS), agents, ctrl, batch, h, DISCOUNT, **params)
        elif alg == "MacDecQ":
            QLearn_squ(agents, batch, h, DISCOUNT, **params)
        elif alg == "MacDecDDRQN":
            QLearn_squ_dec_cen_0(SimpleNamespace(n_action=N_ACTIONS), agents, ctrl, batch, h, DISCOUNT, **params)
        else:
            QLearn_squ_cen_condi_0(SimpleNamespace(n_action=N_ACTIONS), ctrl, batch, h, DISCOUNT, **params)
        updates.append({"indices": [int(i) for i in indices], "cen_indices": [int(i) for i in cen_indices],
                        "hysteresis": h,
                        "sync_before": sync, "weights_after": nets()})
    return {
        "alg": alg,
        "obs_sizes": OBS_SIZES,
        "n_actions": N_ACTIONS,
        "discount": DISCOUNT,
        "horizon": horizon,
        "scripted": scripted,
        "episodes": records,
        "memory": {"sample_epi": sample_epi, "trace_len": trace_len, "capacity": capacity,
                   "batch_size": batch_size, "held": len(mem.buf),
                   "cen_held": len(mem_cen.buf) if parallel else 0},
        "mlp_layer_size": mlp,
        "rnn_h_size": rnn_h,
        "cen_mlp_layer_size": [7, 6],
        "cen_rnn_h_size": 5,
        "l_rate": lr,
        "init_weights": init,
        "updates": updates,
    }


def main():
    torch.set_num_threads(1)
    os.makedirs(OUT, exist_ok=True)
    cases = [("mac_dec_q_windows", "MacDecQ", False, 1), ("mac_dec_q_episodes", "MacDecQ", True, 2),
             ("mac_cen_q_windows", "MacCenQ", False, 3), ("mac_cen_q_episodes", "MacCenQ", True, 4),
             ("mac_dec_ddrqn_windows", "MacDecDDRQN", False, 5),
             ("mac_dec_ddrqn_episodes", "MacDecDDRQN", True, 6),
             ("parallel_mac_dec_ddrqn_windows", "ParallelMacDecDDRQN", False, 7),
             ("parallel_mac_dec_ddrqn_episodes", "ParallelMacDecDDRQN", True, 8)]
    for name, alg, epi, seed in cases:
        case = make_case(alg, epi, seed)
        with open(os.path.join(OUT, name + ".json"), "w") as f:
            json.dump(case, f)
        print(name, "held", case["memory"]["held"])


if __name__ == "__main__":
    main()
