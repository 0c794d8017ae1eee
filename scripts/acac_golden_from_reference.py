#!/usr/bin/env python3
"""Goldens of ACAC's learners from ACAC's own code (issue 41 item 4).

For one algorithm (`acac`, `acac_vanilla`, `acac_micro_gae`) and one ACAC setting (`bp6`,
`ovcA7`, ...) this builds ACAC's algorithm object as `scripts/acac_main.py` does (merged
parameters, seeds, `gym.make`, the Overcooked wrapper, then `ACAC(env, **vars(args))`, which
builds its `MAC` controller, `Memory_epi`, `EnvsRunner` and learner), collects one batch with
ACAC's runner and runs one `learner.train(...)` call, recording everything the learner
computed: the batch it received, its squeezed batch, bootstraps, macro-level GAE advantages and
returns, PopArt statistics, old log-probabilities, every dropout mask the critic's GPT-2 block
drew, per PPO epoch the values, TD errors, losses, ratios, clipped losses and gradient norms,
full gradients of the first epoch, and every net's weights after every optimizer step.
tests/golden_acac/README.md documents the output; `cargo test` replays it without torch.

Nothing of ACAC's learning code is copied or changed. What is patched, and why:
- `envs_runner.Process` / `envs_runner.Pipe`: ACAC's `worker` runs in a thread of this process
  instead of a forked process, one command at a time (the parent blocks until the worker is
  waiting again), with its own copy of the env (deep-copied, as fork copies it) and its own
  `random` / `np.random` states, swapped in around each command: the same streams a separate
  process would have (`random.seed(seed + idx)`, `np.random.seed(seed + idx)`).
- `torch.nn.Dropout.forward`: calls the original, then re-draws the same Bernoulli noise from
  the RNG state saved before the call to record the keep mask, checks that it reproduces the
  original output bit for bit and that the torch RNG ends in the same state.
- Hooks only observe: optimizer step pre/post hooks (gradients, the learner's local variables
  read from its frame, weights after), wrappers around the learner's `memory.sample`,
  `_squeeze_*`, `_get_bootstrap`, `_get_gae*`, PopArt's `update`, and the clip functions.
- Stand-in modules for `IPython`, `pygame` and `wandb` (imported, never used on this path) and
  `numpy.bool8 = numpy.bool_` for gym 0.26's checker under numpy 2.

Usage (see scripts/acac_goldens.sh for the setup):
  python scripts/acac_golden_from_reference.py --acac /tmp/acac --alg acac --env bp6 \\
      --out tests/golden_acac
"""

import argparse
import copy
import json
import os
import platform
import queue
import random
import subprocess
import sys
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
FORMAT = "acac-golden-1"


# --------------------------------------------------------------------------------------------
# stand-ins (before anything imports ACAC)


def install_stand_ins():
    sys.path.insert(0, HERE)
    from reference_stand_ins import install_all

    install_all()


# --------------------------------------------------------------------------------------------
# ACAC's worker in-process


class _Rng:
    """Python's and numpy's global RNG states: what a separate process would own."""

    @staticmethod
    def get():
        import numpy as np

        return (random.getstate(), np.random.get_state())

    @staticmethod
    def set(state):
        import numpy as np

        random.setstate(state[0])
        np.random.set_state(state[1])


class WorkerLink:
    """Both ends of one `Pipe()` between the runner and one in-process `worker`."""

    def __init__(self):
        self.to_worker = queue.Queue()
        self.to_parent = queue.Queue()
        self.idle = threading.Event()
        self.worker_rng = None
        self.parent = _ParentEnd(self)
        self.child = _ChildEnd(self)


class _ParentEnd:
    def __init__(self, link):
        self.link = link

    def send(self, msg):
        """Runs the worker on `msg` to its next `recv`, with the worker's own RNG states."""
        link = self.link
        main = _Rng.get()
        _Rng.set(link.worker_rng)
        link.idle.clear()
        link.to_worker.put(msg)
        link.idle.wait()
        link.worker_rng = _Rng.get()
        _Rng.set(main)

    def recv(self):
        return self.link.to_parent.get_nowait()  # the worker has already answered

    def close(self):
        pass


class _ChildEnd:
    def __init__(self, link):
        self.link = link

    def recv(self):
        self.link.idle.set()
        return self.link.to_worker.get()

    def send(self, msg):
        self.link.to_parent.put(msg)

    def close(self):
        pass


def fake_pipe():
    link = WorkerLink()
    return link.parent, link.child


class FakeProcess:
    """`Process(target=worker, args=(child, env, gamma, seed, idx))` as a thread: starts it up
    to its first `recv` (it has seeded `random` and `np.random` by then) with its own copy of
    the env, keeping the main process's RNG states as they were."""

    def __init__(self, target, args):
        child, env, *rest = args
        self.link = child.link
        self.target = target
        self.args = (child, copy.deepcopy(env), *rest)
        self.daemon = True

    def start(self):
        main = _Rng.get()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()
        self.link.idle.wait()
        self.link.worker_rng = _Rng.get()
        _Rng.set(main)

    def _run(self):
        try:
            self.target(*self.args)
        finally:
            self.link.idle.set()

    def terminate(self):
        pass

    def join(self):
        pass


# --------------------------------------------------------------------------------------------
# number formatting


def f32_list(t):
    """A tensor or array as nested lists of the shortest decimals that round-trip its f32s."""
    import numpy as np

    a = np.asarray(t.detach().cpu().numpy() if hasattr(t, "detach") else t, dtype=np.float32)
    if a.ndim == 0:
        return float(str(a))
    flat = [float(str(x)) for x in a.ravel()]
    return np.array(flat, dtype=object).reshape(a.shape).tolist()


def f32(x):
    import numpy as np

    return float(str(np.float32(x.item() if hasattr(x, "item") else x)))


def int_list(t):
    import numpy as np

    a = np.asarray(t.detach().cpu().numpy() if hasattr(t, "detach") else t)
    return a.astype(np.int64).tolist()


def pack_bits(mask):
    """A 0/1 array flattened row-major, 4 bits per hex digit, most significant first."""
    import numpy as np

    bits = np.asarray(mask, dtype=np.uint8).ravel()
    pad = (-len(bits)) % 4
    bits = np.concatenate([bits, np.zeros(pad, dtype=np.uint8)]).reshape(-1, 4)
    digits = bits[:, 0] * 8 + bits[:, 1] * 4 + bits[:, 2] * 2 + bits[:, 3]
    return "".join("0123456789abcdef"[d] for d in digits)


# --------------------------------------------------------------------------------------------
# the recorder


LEFT_OUT = (".attn.bias", ".attn.masked_bias")  # not c_attn.bias


class Recorder:
    """Observes one `learner.train` call: the tensors for the safetensors file (`tensors`), the
    learner's intermediate results (`out`), every critic forward with its dropout masks
    (`dropout`) and one record per epoch (`epochs`), filled by the hooks installed below."""

    def __init__(self, model, alg, n_agent):
        import torch

        self.torch = torch
        self.model = model
        self.alg = alg
        self.n_agent = n_agent
        self.learner = model.learner
        self.critic = self.learner.joint_critic_net
        self.target = self.learner.joint_critic_tgt_net
        self.out = {}
        self.tensors = {}
        self.dropout = []
        self.current_forward = None
        self.critic_steps = 0
        self.epochs = []
        self.pre_clip = {}
        self.module_names = {}
        for net_name, net in (("critic", self.critic), ("critic_target", self.target)):
            for name, m in net.named_modules():
                self.module_names[id(m)] = (net_name, name)
        self.nets = {f"actor{i}": a.actor_net for i, a in enumerate(model.controller.agents)}
        self.nets["critic"] = self.critic

    # -- weights --------------------------------------------------------------------------
    def snapshot(self, prefix, nets, full=False):
        for net_name in nets:
            for name, t in self.nets[net_name].state_dict().items():
                if name.endswith(LEFT_OUT):
                    continue
                if not full and name.endswith("time_embedding.weight"):
                    continue
                if not full and name.endswith("wpe.weight"):
                    t = t[: self.n_agent]
                self.tensors[f"{prefix}/{net_name}/{name}"] = t.detach().clone().float().contiguous()

    def grads(self, prefix, net_name):
        for name, p in self.nets[net_name].named_parameters():
            if p.grad is not None:
                self.tensors[f"{prefix}/{net_name}/{name}"] = p.grad.detach().clone().contiguous()

    def grad_norms(self, net_name):
        norms, total = {}, 0.0
        for name, p in self.nets[net_name].named_parameters():
            if p.grad is not None:
                n = p.grad.detach().double().norm().item()
                norms[name] = f32(n)
                total += n * n
        return norms, f32(total**0.5)

    # -- dropout --------------------------------------------------------------------------
    def install_dropout_hook(self):
        torch = self.torch
        original = torch.nn.Dropout.forward
        rec = self

        def forward(module, x):
            if not module.training or module.p == 0.0:
                return original(module, x)
            before = torch.get_rng_state()
            y = original(module, x)
            after = torch.get_rng_state()
            torch.set_rng_state(before)
            noise = torch.empty_like(x).bernoulli_(1 - module.p)
            assert torch.equal(torch.get_rng_state(), after), "dropout drew another RNG amount"
            keep = noise.bool()
            assert torch.equal(y, x * noise.div_(1 - module.p)), "dropout mask not reproduced"
            net, name = rec.module_names.get(id(module), ("?", "?"))
            assert rec.current_forward is not None and rec.current_forward["net"] == net
            rec.current_forward["masks"].append(
                {"module": name, "p": module.p, "shape": list(x.shape), "bits": pack_bits(keep.numpy())}
            )
            return y

        torch.nn.Dropout.forward = forward

        def pre(net_name):
            def hook(module, args, kwargs):
                if net_name == "critic_target":
                    call = "bootstrap"
                elif self.alg == "acac_vanilla":
                    n = self.critic_steps
                    # one critic-loss forward before each critic step, then one for the
                    # advantage after it (c_train_iteration 1)
                    call = f"epoch{n}/critic" if self._vanilla_next_is_loss else f"epoch{n - 1}/advantage"
                    self._vanilla_next_is_loss = not self._vanilla_next_is_loss
                else:
                    call = f"epoch{self.critic_steps}"
                x, v = args[0], args[1]
                time_emb = kwargs.get("time_emb", args[3] if len(args) > 3 else None)
                assert kwargs.get("h") is None and (len(args) < 3 or args[2] is None)
                self.current_forward = {
                    "call": call,
                    "net": net_name,
                    "x_shape": list(x.shape),
                    "v": int_list(v),
                    "time_emb": None if time_emb is None else int_list(time_emb),
                    "masks": [],
                }
                self.dropout.append(self.current_forward)

            return hook

        def post(module, args, output):
            # the target critic's raw (still PopArt-normalized) output, before any squeeze
            self.current_forward["output"] = f32_list(output[0])

        self._vanilla_next_is_loss = True
        self.critic.register_forward_pre_hook(pre("critic"), with_kwargs=True)
        self.target.register_forward_pre_hook(pre("critic_target"), with_kwargs=True)
        self.target.register_forward_hook(post)

    # -- learner frames -------------------------------------------------------------------
    def train_locals(self):
        f = sys._getframe(1)
        while f is not None:
            if f.f_code.co_name == "train" and f.f_locals.get("self") is self.learner:
                return f.f_locals
            f = f.f_back
        raise RuntimeError("no train frame")

    def install_learner_wrappers(self):
        L = self.learner

        orig_sample = L.memory.sample

        def sample(*a, **k):
            out = orig_sample(*a, **k)
            self.out["batch_raw"] = out
            self.out["batch"] = self.batch_json(*out)
            return out

        L.memory.sample = sample

        orig_cen = L._squeeze_cen_exp

        def squeeze_cen(*a, **k):
            out = orig_cen(*a, **k)
            self.out["squeezed_cen"] = out
            return out

        L._squeeze_cen_exp = squeeze_cen

        orig_dec = L._squeeze_dec_exp

        def squeeze_dec(*a, **k):
            out = orig_dec(*a, **k)
            self.out.setdefault("squeezed_dec", []).append(out)
            return out

        L._squeeze_dec_exp = squeeze_dec

        if hasattr(L, "_get_bootstrap"):
            orig_boot = L._get_bootstrap

            def get_bootstrap(*a, **k):
                out = orig_boot(*a, **k)
                self.out["bootstrap"] = out
                return out

            L._get_bootstrap = get_bootstrap

        gae_name = "_get_gae_old" if hasattr(L, "_get_gae_old") else "_get_gae"
        if hasattr(L, gae_name):
            orig_gae = getattr(L, gae_name)

            def get_gae(*a, **k):
                self.out["popart_before"] = self.popart_stats()
                out = orig_gae(*a, **k)
                self.out["popart_after"] = self.popart_stats()
                self.out["gae"] = out
                return out

            setattr(L, gae_name, get_gae)

        value = getattr(self.critic, "value", None)
        if value is not None and hasattr(value, "update"):
            orig_update = value.update

            def update(x):
                self.out["returns_raw_flat"] = x.detach().clone()
                return orig_update(x)

            value.update = update

        # Clip functions: record the norm before clipping (ACAC's settings clip nothing).
        mod = sys.modules[type(L).__module__]
        for fname in ("clip_grad_norm_", "clip_grad_value_"):
            orig = getattr(mod, fname)

            def clip(params, *a, _orig=orig, **k):
                params = list(params)
                total = sum(float(p.grad.double().norm() ** 2) for p in params if p.grad is not None)
                self.pre_clip[id(params[0]) if params else 0] = total**0.5
                return _orig(params, *a, **k)

            setattr(mod, fname, clip)

        # Optimizer hooks.
        crit_opt = L.joint_critic_optimizer
        crit_opt.register_step_pre_hook(lambda opt, a, k: self.critic_pre_step())
        crit_opt.register_step_post_hook(lambda opt, a, k: self.after_step("critic"))
        for i, agent in enumerate(self.model.controller.agents):
            agent.actor_optimizer.register_step_pre_hook(lambda opt, a, k, i=i: self.actor_pre_step(i))
            agent.actor_optimizer.register_step_post_hook(lambda opt, a, k, i=i: self.after_step(f"actor{i}"))

    def popart_stats(self):
        v = self.critic.value
        if not hasattr(v, "debiasing_term"):
            return None
        return {
            "mean": f32_list(v.mean),
            "mean_sq": f32_list(v.mean_sq),
            "debiasing_term": f32_list(v.debiasing_term),
            "stddev": f32_list(v.stddev),
            "weight": f32_list(v.weight),
            "bias": f32_list(v.bias),
        }

    def norms_record(self, net_name):
        norms, total = self.grad_norms(net_name)
        first = next(iter(self.nets[net_name].parameters()))
        pre = self.pre_clip.pop(id(first), None)
        return {
            "grad_norm_pre_clip": f32(pre) if pre is not None else total,
            "grad_norm_post_clip": total,
            "grad_norms": norms,
        }

    def critic_pre_step(self):
        loc = self.train_locals()
        n = self.critic_steps
        if "old_log_pi_a_agent" in loc and "old_log_pi" not in self.out:
            self.out["old_log_pi"] = [f32_list(x) for x in loc["old_log_pi_a_agent"]]
        if "Gt" in loc and "Gt_train" not in self.out:
            self.out["Gt_train"] = loc["Gt"]
        rec = {
            "values": f32_list(loc["values"]),
            "V_value": f32_list(loc["V_value"]),
            "TD": f32_list(loc["TD"]),
            "loss": f32(loc["joint_critic_loss"]),
            **self.norms_record("critic"),
        }
        if n == 0:
            self.grads("epoch0/mb0/grad", "critic")
        self.epochs.append({"epoch": n, "minibatches": [{"indices": None, "critic": rec, "actors": []}]})

    def actor_pre_step(self, i):
        loc = self.train_locals()
        n = self.critic_steps - 1
        agent = self.model.controller.agents[i]
        if self.alg == "acac_vanilla":
            rec = {
                "adv": f32_list(loc["adv"]),
                "Gt_agent": f32_list(loc["Gt_agent"]),
                "V_value_agent": f32_list(loc["V_value_agent"]),
                "log_pi_a": f32_list(loc["log_pi_a"]),
                "pi_entropy": f32_list(loc["pi_entropy"]),
                "actor_loss_per_episode": f32_list(loc["actor_loss"]),
                "loss": f32(agent.actor_loss),
            }
        else:
            rec = {
                "log_pi_a": f32_list(loc["log_pi_a"]),
                "is_ratio": f32_list(loc["is_ratio"]),
                "adv_agent": f32_list(loc["adv_agent"]),
                "pg_loss1": f32_list(loc["pg_loss1"]),
                "pg_loss2": f32_list(loc["pg_loss2"]),
                "clipped_rate": f32(loc["clipped_rate"]),
                "pi_entropy": f32_list(loc["pi_entropy"]),
                "loss": f32(agent.actor_loss),
            }
        rec.update(self.norms_record(f"actor{i}"))
        mb = self.epochs[n]["minibatches"][0]
        if self.alg == "acac_vanilla" and "values_for_advantage" not in mb:
            # the critic's forward after its step, whose output the actors' advantages use
            mb["values_for_advantage"] = f32_list(loc["V_value"])
        if n == 0:
            self.grads("epoch0/mb0/grad", f"actor{i}")
        self.epochs[n]["minibatches"][0]["actors"].append(rec)

    def after_step(self, net_name):
        if net_name == "critic":
            self.critic_steps += 1
        n = self.critic_steps - 1
        self.snapshot(f"epoch{n}/mb0/after", [net_name])

    # -- batch ----------------------------------------------------------------------------
    def batch_json(self, batch, max_len, epi_len):
        """The padded episodes `memory.sample()` returned: tuples (last_obs, last_mac_start,
        last_avail, action, reward, joint_reward, obs, avail, terminate, mac_v, j_mac_v, exp_v)."""
        import numpy as np

        n = self.n_agent

        def per_agent(field, e, t, i):
            return batch[e][t][field][i].reshape(-1)

        def agents_float(field):
            return [
                f32_list(np.stack([np.stack([per_agent(field, e, t, i).numpy() for t in range(max_len)]) for e in range(len(batch))]))
                for i in range(n)
            ]

        def joint_int(field, agentwise):
            if agentwise:
                arr = [[[int(batch[e][t][field][i].item()) for i in range(n)] for t in range(max_len)] for e in range(len(batch))]
            else:
                arr = [[int(batch[e][t][field].item()) for t in range(max_len)] for e in range(len(batch))]
            return arr

        # next_obs[t] is obs[t + 1] inside an episode (the worker sends last_obs, then keeps
        # obs as the next last_obs): only each episode's final next_obs is written.
        final_next_obs = []
        for i in range(n):
            rows = []
            for e in range(len(batch)):
                last = epi_len[e] - 1
                for t in range(last):
                    assert torch_equal(per_agent(6, e, t, i), per_agent(0, e, t + 1, i))
                rows.append(per_agent(6, e, last, i).numpy())
            final_next_obs.append(f32_list(np.stack(rows)))
        return {
            "final_next_obs": final_next_obs,
            "n_episodes": len(batch),
            "max_len": int(max_len),
            "epi_len": [int(x) for x in epi_len],
            "obs": agents_float(0),
            "mac_start": joint_int(1, True),
            "avail": agents_float(2),
            "action": joint_int(3, True),
            "reward": [[[f32(batch[e][t][4][i]) for i in range(n)] for t in range(max_len)] for e in range(len(batch))],
            "joint_reward": [[f32(batch[e][t][5]) for t in range(max_len)] for e in range(len(batch))],
            "terminate": joint_int(8, False),
            "mac_valid": joint_int(9, True),
            "joint_mac_valid": joint_int(10, False),
            "exp_valid": joint_int(11, True),
        }


def torch_equal(a, b):
    import torch

    return torch.equal(a, b)


def tensor_json(t):
    import torch

    if t is None:
        return None
    if t.dtype in (torch.bool, torch.int64, torch.int32, torch.long):
        return int_list(t)
    return f32_list(t)


def check_joint_gather(name, t, batch_eps, cen_epi_len, n_agent):
    """jobs[e][k] (n_jobs[e][k]) is the agents' obs (next_obs) at the k-th step t of episode e
    where any macro-action ended (joint_mac_valid), concatenated in agent order."""
    import torch

    batch, _, _ = batch_eps
    field = 0 if name == "jobs" else 6
    for e, ep in enumerate(batch):
        ts = [t_ for t_, step in enumerate(ep) if bool(step[10].item())]
        assert len(ts) == int(cen_epi_len[e])
        for k, t_ in enumerate(ts):
            row = torch.cat([ep[t_][field][i].reshape(-1) for i in range(n_agent)])
            assert torch.equal(t[e, k], row), (name, e, k)
        assert not t[e, len(ts):].any()


def check_agent_gather(t, batch_eps, i, epi_len):
    """agents[i].obs[e][j] is agent i's obs at the j-th step where its macro-action ended."""
    import torch

    batch, _, _ = batch_eps
    for e, ep in enumerate(batch):
        ts = [t_ for t_, step in enumerate(ep) if bool(step[9][i].item())]
        assert len(ts) == int(epi_len[e])
        for j, t_ in enumerate(ts):
            assert torch.equal(t[e, j], ep[t_][0][i].reshape(-1)), (i, e, j)
        assert not t[e, len(ts):].any()


CEN_NAMES = {
    "acac": ["jobs", "jr", "n_jobs", "j_terminate", "mac_v_b", "j_mac_v_b", "j_discount", "exp_valid", "mac_st", "jobs_seq", "n_jobs_seq"],
    "acac_micro_gae": ["jobs", "jr", "n_jobs", "j_terminate", "mac_v_b", "j_mac_v_b", "j_discount", "exp_valid", "mac_st", "jobs_seq", "n_jobs_seq", "j_gae_lambda"],
    "acac_vanilla": ["jobs", "reward", "n_jobs", "terminate", "mac_v_b", "discount", "exp_valid", "bootstrap", "mac_st", "jobs_seq"],
}
DEC_NAMES = ["obs", "action", "discount", "exp_valid", "obs_mask", "obs_seq", "mac_st_j"]


# --------------------------------------------------------------------------------------------


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--acac", required=True, help="a checkout of LGAI-Research/acac")
    parser.add_argument("--alg", required=True, choices=["acac", "acac_vanilla", "acac_micro_gae"])
    parser.add_argument("--env", required=True, help="ACAC's --env_name, e.g. bp6, ovcA7")
    parser.add_argument("--seed", type=int, default=1, help="ACAC's --seed (0 would skip seeding)")
    parser.add_argument("--n-env", type=int, default=2)
    parser.add_argument("--train-freq", type=int, default=2)
    parser.add_argument("--eps", type=float, default=0.5, help="pick epi_count so eps is near this")
    parser.add_argument("--acac-commit", help="ACAC's commit, when --acac is an archive without .git")
    parser.add_argument("--out", required=True, help="output folder")
    args_cli = parser.parse_args()

    install_stand_ins()
    acac_dir = os.path.abspath(args_cli.acac)
    sys.path.insert(0, acac_dir)
    sys.path.insert(0, os.path.join(acac_dir, "scripts"))

    import numpy as np
    import torch
    import gym
    import transformers

    torch.set_num_threads(1)
    from acac.env import OvercookedMacEnvWrapper  # (importing acac.env registers the gym ids)
    from acac.acac_marl.algs import ACAC, ACAC_Vanilla, ACAC_Micro_GAE
    from acac.acac_marl.cores.acac import envs_runner
    from acac.acac_marl.cores.acac.utils import Linear_Decay
    from params.utils import get_env_params, merge_params

    algs = {"acac": ACAC, "acac_vanilla": ACAC_Vanilla, "acac_micro_gae": ACAC_Micro_GAE}

    # The in-process worker (see the module doc).
    envs_runner.Process = FakeProcess
    envs_runner.Pipe = fake_pipe

    # acac_main.py: defaults, then --flags (None unless given), merged with alg and env files.
    with open(os.path.join(acac_dir, "scripts", "params", "default.json")) as f:
        default_params = json.load(f)
    cli = {k: None for k in default_params}
    overrides = {
        "alg_name": args_cli.alg,
        "env_name": args_cli.env,
        "device": "cpu",
        "seed": args_cli.seed,
        "n_env": args_cli.n_env,
        "train_freq": args_cli.train_freq,
    }
    cli.update(overrides)
    import contextlib
    import io

    with contextlib.redirect_stdout(io.StringIO()):
        args = merge_params(argparse.Namespace(**cli), default_params)
    args.duplicate = False
    args.wandb = False
    args.wandb_project = "acac_marl"

    random.seed(args.seed)
    np.random.seed(args.seed)
    torch.manual_seed(args.seed)
    env_params = get_env_params(args)
    if args.share_encoder or args.time_emb_actor:
        # acac_main.py's own adjustments (share_encoder is false in every published setting)
        if args.share_encoder:
            args.a_mlp_layer_size[0] = args.c_mlp_layer_size[0]
            args.a_rnn_layer_size = args.c_rnn_layer_size
            args.time_emb_actor = args.time_emb_actor or args.time_emb
        if args.time_emb_actor:
            args.time_emb = True
    with contextlib.redirect_stdout(io.StringIO()):
        env = gym.make(args.env_id, **env_params)
    if args.env_id.startswith("Overcooked-MA"):
        env = OvercookedMacEnvWrapper(env)
    settings_before_save_dir = dict(vars(args))
    args.save_dir = os.path.join(args.exp_name, args.env_name)
    with contextlib.redirect_stdout(io.StringIO()):
        model = algs[args.alg_name](env, **vars(args))
    n_agent = env.n_agent

    rec = Recorder(model, args.alg_name, n_agent)
    rec.snapshot("init", list(rec.nets), full=True)
    # The target critic equals the critic at init (load_state_dict); check rather than store.
    for (k1, v1), (k2, v2) in zip(rec.critic.state_dict().items(), rec.target.state_dict().items()):
        assert k1 == k2 and torch.equal(v1, v2)
    rec.install_dropout_hook()
    rec.install_learner_wrappers()

    # learn()'s first lines, at an episode count where eps is near --eps.
    eps_call = Linear_Decay(args.eps_stable_at, args.eps_start, args.eps_end)
    frac = (args.eps_start - args_cli.eps) / (args.eps_start - args.eps_end)
    epi_count = int(round(frac * args.eps_stable_at / args.train_freq)) * args.train_freq
    eps = eps_call.get_value(epi_count)
    c_hys_value = Linear_Decay(args.hys_stable_at, args.c_hys_start, args.c_hys_end).get_value(epi_count)
    adv_hys_value = Linear_Decay(args.hys_stable_at, args.adv_hys_start, args.adv_hys_end).get_value(epi_count)
    etrpy_w = Linear_Decay(args.etrpy_w_stable_at, args.etrpy_w_start, args.etrpy_w_end).get_value(epi_count)

    torch_rng_before_run = torch.get_rng_state()
    model.envs_runner.run(eps=eps, n_epis=model.train_freq)
    with contextlib.redirect_stdout(io.StringIO()):
        model.learner.train(eps, c_hys_value, adv_hys_value, etrpy_w, model.critic_hys, model.adv_hys)
    diag = model.learner.get_diagnostics()

    # ---- assemble --------------------------------------------------------------------------
    out = rec.out
    doc = {"format": FORMAT, "case": f"{args.alg_name}_{args.env_name}", "alg": args.alg_name, "env": args.env_name}
    commit = args_cli.acac_commit
    if not commit:
        try:
            commit = subprocess.run(
                ["git", "-C", acac_dir, "rev-parse", "HEAD"], capture_output=True, text=True
            ).stdout.strip()
        except OSError:
            commit = ""
    doc["versions"] = {
        "python": platform.python_version(),
        "torch": torch.__version__,
        "transformers": transformers.__version__,
        "numpy": np.__version__,
        "gym": gym.__version__,
        "acac_commit": commit or "unknown (no git metadata: pass --acac-commit)",
    }
    settings = {k: v for k, v in settings_before_save_dir.items()}
    doc["settings"] = settings
    doc["overrides"] = overrides
    doc["env_params"] = env_params
    doc["obs_size"] = [int(x) for x in env.obs_size]
    doc["n_action"] = [int(x) for x in env.n_action]
    doc["seeds"] = {"seed": args.seed, "worker_seeds": [args.seed + i for i in range(args.n_env)]}
    doc.update(
        {
            "epi_count": epi_count,
            "eps": eps,
            "c_hys_value": c_hys_value,
            "adv_hys_value": adv_hys_value,
            "etrpy_w": etrpy_w,
            "critic_hys": model.critic_hys,
            "adv_hys": model.adv_hys,
        }
    )
    doc["weights_file"] = f"{doc['case']}.safetensors"
    doc["nets"] = {
        name: [k for k in net.state_dict() if not k.endswith(LEFT_OUT)] for name, net in rec.nets.items()
    }
    doc["batch"] = out["batch"]

    cen, cen_trace_len, cen_epi_len = out["squeezed_cen"]
    sq = {"cen_epi_len": int_list(cen_epi_len), "cen_trace_len": int(cen_trace_len)}
    batch_eps = out["batch_raw"]
    for name, t in zip(CEN_NAMES[args.alg_name], cen):
        if name in ("jobs", "n_jobs"):
            check_joint_gather(name, t, batch_eps, cen_epi_len, n_agent)
            continue  # gathers of batch rows: see the README
        sq[name] = tensor_json(t)
    dec_batches, dec_trace_lens, dec_epi_lens = out["squeezed_dec"][0]
    sq["agents"] = []
    for d, tl, el in zip(dec_batches, dec_trace_lens, dec_epi_lens):
        a = {"epi_len": int_list(el), "trace_len": int(tl)}
        for name, t in zip(DEC_NAMES, d):
            if name == "obs":
                check_agent_gather(t, batch_eps, len(sq["agents"]), el)
                continue  # a gather of batch rows: see the README
            a[name] = tensor_json(t)
        sq["agents"].append(a)
    if len(out["squeezed_dec"]) > 1:
        # acac_vanilla squeezes again in every epoch; check it is the same each time
        for later in out["squeezed_dec"][1:]:
            for d0, d1 in zip(dec_batches, later[0]):
                for x0, x1 in zip(d0, d1):
                    assert (x0 is None and x1 is None) or torch.equal(x0, x1)
    doc["squeezed"] = sq

    if "gae" in out:
        init_value, bootstrap = out["bootstrap"]
        adv, Gt = out["gae"]
        gae = {
            "init_value": f32_list(init_value),
            "bootstrap": f32_list(bootstrap),
            "advantage": f32_list(adv),
            "returns": f32_list(Gt),
        }
        if "returns_raw_flat" in out:
            flat = out["returns_raw_flat"].reshape(-1)
            raw = torch.zeros_like(Gt)
            pos = 0
            for e, length in enumerate(cen_epi_len.tolist()):
                raw[e, :length, 0] = flat[pos : pos + length]
                pos += length
            gae["returns_raw"] = f32_list(raw)
        else:
            gae["returns_raw"] = gae["returns"]
        assert torch.equal(out["Gt_train"], Gt)
        doc["gae"] = gae
        doc["popart"] = {"before": out["popart_before"], "after": out["popart_after"]}
        doc["old_log_pi"] = out["old_log_pi"]
    else:
        doc["returns"] = {"returns": f32_list(out["Gt_train"])}
        doc["popart"] = None
    doc["dropout"] = rec.dropout
    n_epi = doc["batch"]["n_episodes"]
    for ep in rec.epochs:
        ep["minibatches"][0]["indices"] = list(range(n_epi))
        ep["minibatches"][0]["weights_after"] = f"epoch{ep['epoch']}/mb0/after"
        ep["minibatches"][0]["grads"] = "epoch0/mb0/grad" if ep["epoch"] == 0 else None
    doc["epochs"] = rec.epochs
    doc["diagnostics"] = {k: [f32(x) for x in v] for k, v in diag.items()}
    doc["torch_rng_state_before_run_sha256"] = __import__("hashlib").sha256(torch_rng_before_run.numpy().tobytes()).hexdigest()

    os.makedirs(args_cli.out, exist_ok=True)
    from safetensors.torch import save_file

    base = os.path.join(args_cli.out, doc["case"])
    save_file(rec.tensors, base + ".safetensors.tmp", metadata={"format": FORMAT})
    os.chmod(base + ".safetensors.tmp", 0o644)
    os.replace(base + ".safetensors.tmp", base + ".safetensors")
    with open(base + ".json.tmp", "w") as f:
        json.dump(doc, f, separators=(",", ":"), allow_nan=False)  # serde_json reads no NaN
        f.write("\n")
    os.replace(base + ".json.tmp", base + ".json")
    print(base, os.path.getsize(base + ".json"), os.path.getsize(base + ".safetensors"))


if __name__ == "__main__":
    main()
