#!/usr/bin/env python3
"""Golden actor-critic updates from the authors' MacroMARL reference code.

Usage:
    python3 scripts/ac_golden_from_reference.py --ref PATH/TO/MacroMARL [--out tests/golden_ac]
                                                [--cases NAME ...] [--ref-commit SHA]

    --ref is a checkout (or `git archive`) of github.com/yuchen-x/MacroMARL; HEAD f5899cd7 was
    used. Needs Python 3 with torch, numpy, gym (0.26.2 was used; only `gym.Env` and
    `gym.spaces` are touched) and safetensors. Optional tool: tests and CI never run it; they read
    what it wrote under tests/golden_ac/. Running it twice gives byte-identical files.

What it does, per case (CASES below):
  * Seeds python `random`, numpy and torch (`torch.manual_seed`, `torch.set_num_threads(1)`),
    builds the environment class directly with the kwargs scripts/pg_based_main.py would pass,
    and builds the reference's own algorithm object (`macro_marl.algs.pg_based.<module>.<Alg>`
    with every pg_based_main.py argument): its memory (`Memory_epi`, `--sample_epi`), controller
    (actors, and per-agent critics where the family keeps them there), `EnvsRunner` (its worker
    processes, forked, each seeded `seed + idx` by the reference) and learner (critics, target
    critics, Adam optimisers).
  * Target critics are set to online + N(0, 0.05^2) noise (torch.Generator seeded with seed+1),
    so bootstrap-from-target is tested; Adam starts fresh as in the reference. The actor target
    nets (created by the reference, never used by any learner) are left alone and not written.
  * Two updates, each exactly the reference's `learn()` loop body with `eps` fixed per update:
    `envs_runner.run(eps=eps, n_epis=train_freq)` (all n_env envs reset, stepped in lockstep until
    >= train_freq episodes completed), then `learner.train(eps, 1.0, 1.0, 0.0, False, False)`
    (c_hys = adv_hys = 1, entropy weight 0, no hysteresis: the published settings). Then, as in
    `learn()`, a hard target copy (`update_critic_target_net()`, `update_actor_target_net()`)
    iff `(k * train_freq) % c_target_update_freq == 0`; see `target_sync_after` below.
  * Everything the learner computes is read from its local variables with a line tracer
    (`sys.settrace`) on `train`, `_get_bootstrap_return` and (where the family has a start-flag
    filter) the squeeze function. A line event fires before its line runs. Where a value exists
    only inline in a line (e.g. the online V in `TD = Gt - critic(jobs)[0]`, the target-critic
    bootstrap in `Gt = reward + mac_discount * critic_net(n_state)[0]...`), the hook evaluates the
    same expression on the frame's own locals under no_grad (the nets are deterministic), so the
    value is bit-identical to the one the line uses.
  * Each case's seed is the first seed from its base whose two updates show everything the case
    must exercise (`wants`); see `exercised` in golden.json. One line per case is printed.

Nothing of the reference is copied here. Import-time stand-ins only: the environments import
`IPython` (for `set_trace`, never called), replaced by an empty module when absent; and
`macro_marl/algs/__init__.py` (which also imports the value-based methods and so matplotlib) is
bypassed by registering `macro_marl.algs` as a bare package; the pg_based modules are imported
unchanged. No reference function is patched: torch 2.x runs the pg_based code as it is (Mac-CAC's
`get_conditional_logits` uses `Tensor.where` with a uint8 mask, which torch 2.15 still accepts
with a deprecation warning; that warning is silenced).

Output per case, directory <out>/<case>/:
  init.safetensors     every net's initial weights, `<net>.<state_dict name>` (float32).
  update<k>_grads.safetensors   (k = 1, 2) every stepped net's `.grad` read at the line
                       `<...>_optimizer.step()` of that net, i.e. right before its Adam step,
                       under `<net>.<param name>`.
  update<k>_weights.safetensors every net's weights right after `learner.train` of update k
                       (online and target; before the optional sync that follows it).
  golden.json          described below.
Net names: decentralised actors `actor0`, `actor1`, ...; Mac-CAC's centralised actor `actor`;
one shared critic `critic` (MacCAC, NaiveMacIACC, NaiveMacIASC) or per-agent critics `critic0`,
`critic1`, ... (MacIAC, MacIAICC, MacIAISC); target critics `critic_tgt` / `critic<i>_tgt`.
Parameter names are PyTorch's: fc1.weight, fc1.bias, fc2.*, gru.weight_ih_l0, gru.weight_hh_l0,
gru.bias_ih_l0, gru.bias_hh_l0 (gates r,z,n), fc3.*, fc4.* for GRU nets; the state critic
(mac_niasc/models.py Critic, used by NaiveMacIASC and MacIAISC) is fc1..fc5 without GRU.

golden.json:
  format "macdec-ac-golden-1"; case; alg (reference class name); learner (reference file and
  class); reference {repo, commit, torch}; env (gym id); env_class; env_params (constructor
  kwargs as given); seed; target_noise_std;
  hyper {gamma, n_step_TD, a_lr, c_lr, a_mlp_layer_size, a_rnn_layer_size, c_mlp_layer_size,
         c_rnn_layer_size, c_mid_layer_size, n_agent, obs_sizes, n_actions, state_size (null if
         the family does not use it), train_freq, n_env, env_terminate_step,
         c_target_update_freq, c_train_iteration (1), entropy_weight (0), c_hys/adv_hys (off),
         grad_clip (off), obs_last_action (false)};
  nets {name: {role: actor|critic|critic_target, online: name of the online net for targets}};
  record_fields: the record field names this family stores (see below);
  exercised: list of "key: evidence" strings, computed from the recorded data by
    `exercised_items` (time_limit_cut, env_terminal_before_horizon, env_terminal_at_horizon,
    truncated_macro_at_end, joint_macro_truncated_at_end, episode_lengths_differ,
    macro_longer_than_one_step, squeezed_lengths_differ, last_kept_record_bootstraps,
    last_kept_record_terminal, n_step_bootstrap_mid, n_step_full_return_tail,
    terminal_episode_agent_bootstraps (P9), busy_agent_at_joint_decision (Mac-CAC, P4),
    naive_adv_at_joint_record, mac_start_filter_applied, agent_start_not_every_joint_record,
    actor_grads_nonzero, target_critic_differs_from_online, target_sync_between_updates,
    eps_below_one); only the keys that hold are listed;
  Floats: every tensor value is float32 in the reference and is written as the exact double of
  that float32 (e.g. -0.10000000149011612 is float32(-0.1)); 0/1 flags and actions are ints.
  updates: [update1, update2], each
    eps                the eps passed to runner.run and learner.train (the eps-mixture of P3);
    target_sync_after  true if the reference loop hard-copies online -> target critics (and the
                       unused actor targets) after this update; the next update then starts from
                       update<k>_weights with every `*_tgt` replaced by its online net;
    episodes           the batch exactly as `memory.buf` holds it when `train` starts (the deque
                       of the last train_freq completed episodes, oldest first), NOT padded:
                       `Memory_epi.sample()` pads every episode to `padded_len` with its
                       ZERO_PADDING record (zero obs/state, action 0, rewards 0, terminate 0,
                       valid 0, joint_valid 0, mac_start 0, exp_valid 0, avail 0);
    epi_len, padded_len  as sample() returns them;
    learner            what train() computed (below).

  Records (one per primitive step). The runner's tuple (EnvsRunner._exp_to_tensor) per family,
  slot -> field; per-agent slots become lists indexed by agent:
    MacIAC   (mac_iac runner/memory):
      0 last_obs->obs, 1 last_avail (omitted), 2 a->action, 3 acc_i->reward, 4 obs->next_obs,
      5 avail (omitted), 6 terminate, 7 mac_v->valid, 8 exp_v->exp_valid
    MacCAC   (mac_cac):
      0 obs, 1 (avail, omitted), 2 action, 3 reward, 4 j_r->joint_reward, 5 next_obs,
      6 (avail, omitted), 7 terminate, 8 valid, 9 j_mac_v->joint_valid, 10 exp_valid
    NaiveMacIACC, MacIAICC (mac_niacc runner/memory):
      0 obs, 1 last_mac_start->mac_start, 2 (avail), 3 action, 4 reward, 5 joint_reward,
      6 next_obs, 7 (avail), 8 terminate, 9 valid, 10 joint_valid, 11 exp_valid
    NaiveMacIASC, MacIAISC (mac_niasc runner/memory):
      0 last_state->state, 1 obs, 2 mac_start, 3 (avail), 4 action, 5 reward, 6 joint_reward,
      7 state->next_state, 8 next_obs, 9 (avail), 10 terminate, 11 valid, 12 joint_valid,
      13 exp_valid
  Field meanings (docs/MACROMARL.md §2.2): obs[i] agent i's observation before the step (held while busy);
  mac_start[i] 1 on the first primitive step of agent i's macro-action; action[i] the executed
  macro-action (info['cur_mac']); reward[i] acc_i, agent i's macro-reward discounted inside the
  macro-action, as accumulated so far; joint_reward accJ, the same for the joint macro-action
  with the mean team reward; next_obs[i] the observation after the step; terminate 0/1 (the
  env's flag; OSD-F-v0 sets it at its horizon too); valid[i] v_i (macro-action ended at this
  step); joint_valid max_i v_i; exp_valid[i] always 1 in stored records; state/next_state
  env.get_state() before/after the step. The avail slots are checked to be all ones (every
  domain) and omitted.

  learner.critics[<critic name>] (from the learner's locals; padded squeezed tensors of shape
  [B][K] = [episodes][longest squeezed sequence], the learner's trailing singleton dim dropped;
  valid positions are where mask = exp_valid is 1, padding has mask 0):
    epi_len        squeezed lengths per episode (the learner's epi_len);
    reward         squeezed r (acc_i or accJ at the end record), padding 0;
    terminate      squeezed terminate, padding 1;
    discount       gamma^t_end (t_end = primitive index of the end record), padding 0;
    mac_discount   the learner's mac_discount (gamma^duration; NaN->0 at padding);
    bootstrap      the target-critic value each return bootstraps from, as the learner indexes
                   it: history critics critic_tgt(cat[seq_0, next_seq])[:, 1:]; state critics
                   critic_tgt(next_state at the end record); MacIAICC the learner's `bootstrap`
                   (critic_tgt over the joint-squeezed sequence, picked at agent i's ends).
                   Values at padding are whatever the net outputs there (unused);
    G              the returns Gt (n_step_TD 0/1: r + mac_discount*B*(1-term); >=2: the
                   learner's n-step recursion), padding 0;
    V              the online critic's values used in the critic loss (before its step);
    loss           the critic loss (float);
    V_updated      the online critic's values after its step (used for the advantage);
    adv            G - V_updated (the joint advantage for shared critics);
    stepped        whether the critic's optimizer stepped.
   shared critics of NaiveMacIACC/IASC also: joint_record_agent_valid [B][K][n_agent] (the
   squeezed per-agent v at joint records, which picks each actor's advantage).
   MacIAICC also: a_st_filtered and ja_st_filtered [B][T] (agent/joint start flags over the
   padded primitive batch after `_mac_start_filter`), joint_epi_len (joint squeezed lengths),
   mac_st [B][Kj] (agent i starts at joint record j), joint_K.
   MacIAISC also: a_st_filtered [B][T]. NaiveMacIASC also: ja_st_filtered [B][T].
  learner.actors[<actor name>]:
    epi_len, mask (exp_valid), action (squeezed executed action; MacCAC the ravelled joint
    action, C order, agent 0 most significant), adv (the advantage this actor uses), discount
    (the policy-gradient weight gamma^t_end, quirk P2), log_pi_a (log of the eps-mixture
    probability of the action, P3), loss (float), stepped.
"""

import argparse
import copy
import importlib
import json
import linecache
import os
import random
import shutil
import subprocess
import sys
import tempfile
import types
import warnings

import numpy as np
import torch
from safetensors.torch import save_file

from reference_stand_ins import install_ipython

NOISE_STD = 0.05
MAX_SEED_TRIES = 400
KNOWN_COMMIT = "f5899cd7b96bb3dbf7b265494a3ba8a15b2e3fe2"

# ---------------------------------------------------------------- algorithms and families

ALGS = {
    # alg: (module under macro_marl.algs.pg_based, class, record family, critic layout,
    #       actor layout, learner description)
    "MacIAC": ("mac_iac", "MacIAC", "iac", "per_agent", "per_agent",
               "cores/pg_based/mac_iac/learner.py: Learner"),
    "MacCAC": ("mac_cac", "MacCAC", "cac", "shared", "central",
               "cores/pg_based/mac_cac/learner.py: Learner"),
    "NaiveMacIACC": ("mac_niacc_V", "NaiveMacIACC", "niacc", "shared", "per_agent",
                     "cores/pg_based/mac_niacc/learner.py: Learner"),
    "NaiveMacIASC": ("mac_niacc_sV", "NaiveMacIASC", "niasc", "shared", "per_agent",
                     "cores/pg_based/mac_niasc/learner.py: Learner"),
    "MacIAICC": ("mac_iaicc_V", "MacIAICC", "niacc", "per_agent", "per_agent",
                 "cores/pg_based/mac_iaicc/learner_1.py: Learner_1"),
    "MacIAISC": ("mac_iaicc_sV", "MacIAISC", "niasc", "per_agent", "per_agent",
                 "cores/pg_based/mac_iaisc/learner.py: Learner"),
}

# Record tuple slots per family (EnvsRunner._exp_to_tensor); None = avail slot (omitted).
RECORD_SLOTS = {
    "iac": ["obs", None, "action", "reward", "next_obs", None, "terminate", "valid",
            "exp_valid"],
    "cac": ["obs", None, "action", "reward", "joint_reward", "next_obs", None, "terminate",
            "valid", "joint_valid", "exp_valid"],
    "niacc": ["obs", "mac_start", None, "action", "reward", "joint_reward", "next_obs", None,
              "terminate", "valid", "joint_valid", "exp_valid"],
    "niasc": ["state", "obs", "mac_start", None, "action", "reward", "joint_reward",
              "next_state", "next_obs", None, "terminate", "valid", "joint_valid",
              "exp_valid"],
}

# The online value in the critic-loss line `TD = Gt - <expr>` (evaluated on the frame's locals).
V_EXPR = {
    "MacIAC": "agent.critic_net(obs)[0]",
    "MacCAC": "self.controller.agent.critic_net(jobs)[0]",
    "NaiveMacIACC": "self.joint_critic_net(jobs)[0]",
    "NaiveMacIASC": "self.joint_critic_net(state)",
    "MacIAICC": "V_value",
    "MacIAISC": "agent.critic_net(state)",
}
# The bootstrap tensor inside `_get_bootstrap_return` (as the n>=2 branch names it).
BOOT_EXPR = {
    "MacIAC": "critic_net(n_state)[0][:,1:,:]",
    "MacCAC": "critic_net(n_state)[0][:,1:,:]",
    "NaiveMacIACC": "critic_net(n_state)[0][:,1:,:]",
    "NaiveMacIASC": "critic_net(n_state)",
    "MacIAICC": "bootstrap",
    "MacIAISC": "critic_net(n_state)",
}

# ---------------------------------------------------------------- cases

def bp_params(grid, horizon):
    return {"grid_dim": list(grid), "big_box_reward": 300.0, "small_box_reward": 20.0,
            "penalty": -10.0, "n_agent": 2, "terminate_step": horizon, "TB_move_speed": 0.6,
            "TB_move_noisy": 0.0, "TB_move_cost": 0.0, "fetch_pass_obj_tc": 4,
            "fetch_look_for_obj_tc": 6, "fetch_manip_noisy": 0.0,
            "delay_delivery_penalty": 0.0, "obs_human_wait": False,
            "human_speed_per_step": [[18, 18, 18, 18]]}


def osd_params(n_human, n_agent, horizon):
    p = bp_params((6, 6), horizon)
    p["n_agent"] = n_agent
    p["human_speed_per_step"] = [[18, 18, 18, 18]] * n_human
    return p


ENVS = {
    "BP-MA-v0": ("macro_marl.my_env.box_pushing_MA", "BoxPushing_harder"),
    "OSD-D-v7": ("macro_marl.my_env.osd_ma_double_room", "ObjSearchDelivery_v7"),
    "OSD-F-v0": ("macro_marl.my_env.osd_ma_four_room", "ObjSearchDelivery_v0"),
}

SMALL = dict(a_mlp_layer_size=[16, 16], a_rnn_layer_size=16, c_mlp_layer_size=[16, 16],
             c_rnn_layer_size=16, c_mid_layer_size=16)

CASES = [
    dict(name="mac_iac_bp4_g098_n0", alg="MacIAC", env="BP-MA-v0",
         env_params=bp_params((4, 4), 12), gamma=0.98, n_step_TD=0, a_lr=0.003, c_lr=0.01,
         train_freq=3, n_env=2, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["time_limit_cut", "env_terminal_before_horizon", "truncated_macro_at_end",
                "episode_lengths_differ", "macro_longer_than_one_step",
                "last_kept_record_bootstraps", "last_kept_record_terminal",
                "actor_grads_nonzero"]),
    dict(name="mac_iac_osdf_g1_n5_sync", alg="MacIAC", env="OSD-F-v0",
         env_params=osd_params(4, 4, 18), gamma=1.0, n_step_TD=5, a_lr=0.003, c_lr=0.01,
         train_freq=2, n_env=2, eps=[0.5, 0.4], c_target_update_freq=2,
         wants=["env_terminal_at_horizon", "truncated_macro_at_end", "n_step_bootstrap_mid",
                "n_step_full_return_tail", "squeezed_lengths_differ",
                "terminal_episode_agent_bootstraps",
                "target_sync_between_updates", "actor_grads_nonzero"]),
    dict(name="mac_cac_osdd_g1_n0", alg="MacCAC", env="OSD-D-v7",
         env_params=osd_params(2, 3, 20), gamma=1.0, n_step_TD=0, a_lr=0.003, c_lr=0.01,
         train_freq=2, n_env=2, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["time_limit_cut", "busy_agent_at_joint_decision", "truncated_macro_at_end",
                "last_kept_record_bootstraps", "actor_grads_nonzero"]),
    dict(name="mac_cac_bp4_g098_n3", alg="MacCAC", env="BP-MA-v0",
         env_params=bp_params((4, 4), 14), gamma=0.98, n_step_TD=3, a_lr=0.003, c_lr=0.01,
         train_freq=3, n_env=3, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["busy_agent_at_joint_decision", "n_step_bootstrap_mid", "time_limit_cut",
                "env_terminal_before_horizon", "macro_longer_than_one_step",
                "actor_grads_nonzero"]),
    dict(name="naive_mac_iacc_osdf_g1_n3", alg="NaiveMacIACC", env="OSD-F-v0",
         env_params=osd_params(4, 4, 18), gamma=1.0, n_step_TD=3, a_lr=0.003, c_lr=0.01,
         train_freq=2, n_env=2, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["env_terminal_at_horizon", "truncated_macro_at_end", "n_step_bootstrap_mid",
                "naive_adv_at_joint_record", "actor_grads_nonzero"]),
    dict(name="naive_mac_iasc_bp4_g098_n1", alg="NaiveMacIASC", env="BP-MA-v0",
         env_params=bp_params((4, 4), 12), gamma=0.98, n_step_TD=1, a_lr=0.003, c_lr=0.01,
         train_freq=3, n_env=2, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["time_limit_cut", "joint_macro_truncated_at_end", "naive_adv_at_joint_record",
                "macro_longer_than_one_step", "env_terminal_before_horizon",
                "actor_grads_nonzero"]),
    dict(name="mac_iaicc_osdd_g098_n4", alg="MacIAICC", env="OSD-D-v7",
         env_params=osd_params(2, 3, 22), gamma=0.98, n_step_TD=4, a_lr=0.003, c_lr=0.01,
         train_freq=2, n_env=2, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["time_limit_cut", "truncated_macro_at_end", "mac_start_filter_applied",
                "n_step_bootstrap_mid", "agent_start_not_every_joint_record",
                "macro_longer_than_one_step", "actor_grads_nonzero"]),
    dict(name="mac_iaicc_bp4_g1_n0", alg="MacIAICC", env="BP-MA-v0",
         env_params=bp_params((4, 4), 12), gamma=1.0, n_step_TD=0, a_lr=0.003, c_lr=0.01,
         train_freq=3, n_env=2, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["time_limit_cut", "env_terminal_before_horizon", "joint_macro_truncated_at_end",
                "mac_start_filter_applied", "agent_start_not_every_joint_record",
                "actor_grads_nonzero"]),
    dict(name="mac_iaisc_bp6_g098_n3", alg="MacIAISC", env="BP-MA-v0",
         env_params=bp_params((6, 6), 15), gamma=0.98, n_step_TD=3, a_lr=0.003, c_lr=0.01,
         train_freq=2, n_env=2, eps=[0.5, 0.4], c_target_update_freq=1000,
         wants=["time_limit_cut", "truncated_macro_at_end", "mac_start_filter_applied",
                "n_step_bootstrap_mid", "macro_longer_than_one_step", "actor_grads_nonzero"]),
]

# ---------------------------------------------------------------- importing the reference


def import_reference(ref):
    """Import the reference's pg_based algorithms and the three environment classes."""
    install_ipython()
    src = os.path.join(ref, "src")
    sys.path.insert(0, src)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import gym  # noqa: F401  (the envs subclass gym.Env)
    # mac_cac/utils.py get_conditional_logits: `.where(uint8 mask, ...)` still works in torch 2.x
    # but warns that uint8 conditions are deprecated.
    warnings.filterwarnings("ignore", message="where received a uint8 condition")
    importlib.import_module("macro_marl")
    # macro_marl/algs/__init__.py also imports the value-based methods (matplotlib, ...).
    algs_pkg = types.ModuleType("macro_marl.algs")
    algs_pkg.__path__ = [os.path.join(src, "macro_marl", "algs")]
    sys.modules["macro_marl.algs"] = algs_pkg
    ns = types.SimpleNamespace(algs={}, envs={})
    for alg, (mod, cls, *_rest) in ALGS.items():
        ns.algs[alg] = getattr(importlib.import_module("macro_marl.algs.pg_based." + mod), cls)
    for env_id, (mod, cls) in ENVS.items():
        ns.envs[env_id] = getattr(importlib.import_module(mod), cls)
    return ns


def alg_kwargs(case, seed):
    """Every argument of scripts/pg_based_main.py, at its default unless the case sets it."""
    kw = dict(env_id=case["env"], env_terminate_step=case["env_params"]["terminate_step"],
              n_env=case["n_env"], n_agent=case["env_params"]["n_agent"], l_mode=0, seed=seed,
              run_id=0, save_dir="golden_ac", resume=False, device="cpu", total_epi=40000,
              gamma=case["gamma"], a_lr=case["a_lr"], c_lr=case["c_lr"], c_train_iteration=1,
              eps_start=1.0, eps_end=0.01, eps_stable_at=4000, c_hys_start=1.0, c_hys_end=1.0,
              adv_hys_start=1.0, adv_hys_end=1.0, hys_stable_at=4000, critic_hys=False,
              adv_hys=False, etrpy_w_start=0.0, etrpy_w_end=0.0, etrpy_w_stable_at=4000,
              train_freq=case["train_freq"], c_target_update_freq=case["c_target_update_freq"],
              c_target_soft_update=False, tau=0.01, n_step_TD=case["n_step_TD"],
              TD_lambda=0.0, grad_clip_value=0.0, grad_clip_norm=0.0, obs_last_action=False,
              eval_policy=False, eval_freq=100, eval_num_epi=10, sample_epi=True, trace_len=10)
    kw.update(copy.deepcopy(SMALL))
    return kw


def build_env(ref, case):
    p = dict(case["env_params"])
    p["grid_dim"] = tuple(p["grid_dim"])
    return ref.envs[case["env"]](**p)

# ---------------------------------------------------------------- nets


def nets_of(model, alg):
    """[(name, module, role, online name)] for every net that is written."""
    _, _, _, critic_layout, actor_layout, _ = ALGS[alg]
    c = model.controller
    out = []
    if actor_layout == "central":
        out.append(("actor", c.agent.actor_net, "actor", None))
    else:
        for a in c.agents:
            out.append((f"actor{a.idx}", a.actor_net, "actor", None))
    if alg == "MacCAC":
        out.append(("critic", c.agent.critic_net, "critic", None))
        out.append(("critic_tgt", c.agent.critic_tgt_net, "critic_target", "critic"))
    elif critic_layout == "shared":
        out.append(("critic", model.learner.joint_critic_net, "critic", None))
        out.append(("critic_tgt", model.learner.joint_critic_tgt_net, "critic_target",
                    "critic"))
    else:
        for a in c.agents:
            out.append((f"critic{a.idx}", a.critic_net, "critic", None))
        for a in c.agents:
            out.append((f"critic{a.idx}_tgt", a.critic_tgt_net, "critic_target",
                        f"critic{a.idx}"))
    return out


def weights(model, alg):
    out = {}
    for name, net, _, _ in nets_of(model, alg):
        for k, v in net.state_dict().items():
            out[f"{name}.{k}"] = v.detach().clone().contiguous()
    return out


def grads_of(name, net):
    out = {}
    for k, p in net.named_parameters():
        g = torch.zeros_like(p) if p.grad is None else p.grad
        out[f"{name}.{k}"] = g.detach().clone().contiguous()
    return out


def perturb_targets(model, alg, seed):
    gen = torch.Generator().manual_seed(seed + 1)
    nets = {n: net for n, net, _, _ in nets_of(model, alg)}
    with torch.no_grad():
        for name, net, role, online in nets_of(model, alg):
            if role != "critic_target":
                continue
            for (_, tp), (_, op) in zip(net.named_parameters(), nets[online].named_parameters()):
                tp.copy_(op + NOISE_STD * torch.randn(op.shape, generator=gen))

# ---------------------------------------------------------------- tensors -> JSON


def tolist(t, squeeze_last=True):
    t = t.detach()
    if squeeze_last and t.dim() >= 2 and t.shape[-1] == 1:
        t = t[..., 0]
    if t.dtype == torch.bool:
        return t.to(torch.int64).tolist()
    if t.is_floating_point():
        return t.to(torch.float64).tolist()
    return t.tolist()


def scalar(t):
    t = t.detach().reshape(-1)
    assert t.numel() == 1, t.shape
    v = t[0]
    if v.dtype == torch.bool:
        return int(v.item())
    if v.is_floating_point():
        return float(v.item())
    return int(v.item())


def record_to_json(rec, family):
    slots = RECORD_SLOTS[family]
    assert len(rec) == len(slots), (family, len(rec))
    out = {}
    for value, field in zip(rec, slots):
        if field is None:
            for av in value:
                assert bool((av == 1.0).all()), "avail actions are not all ones"
            continue
        if isinstance(value, (list, tuple)):
            if field in ("obs", "next_obs"):
                out[field] = [tolist(v.view(-1), squeeze_last=False) for v in value]
            elif field in ("action", "mac_start", "valid"):
                out[field] = [int(scalar(v)) for v in value]
            else:
                out[field] = [scalar(v) for v in value]
        else:
            if field in ("state", "next_state"):
                out[field] = tolist(value.view(-1), squeeze_last=False)
            elif field in ("terminate", "joint_valid"):
                out[field] = int(scalar(value))
            else:
                out[field] = scalar(value)
    return out

# ---------------------------------------------------------------- capturing inside the learner


class Capture:
    """Reads the learner's locals at chosen lines (a line event fires before its line runs)."""

    def __init__(self, model, alg):
        self.model, self.alg = model, alg
        _, _, _, self.critic_layout, self.actor_layout, _ = ALGS[alg]
        cls = type(model.learner)
        self.codes = {cls.train.__code__: "train",
                      cls._get_bootstrap_return.__code__: "boot"}
        for fn in ("_squeeze_dec_exp", "_squeeze_cen_exp"):
            if hasattr(cls, fn):
                self.codes[getattr(cls, fn).__code__] = fn
        self.critics, self.actors, self.grads = {}, {}, {}
        self.pending_boot = None
        self.squeeze = {}

    def critic_name(self, f):
        if self.critic_layout == "shared":
            return "critic"
        return f"critic{f['agent'].idx}"

    def actor_name(self, f):
        if self.actor_layout == "central":
            return "actor"
        return f"actor{f['agent'].idx}"

    def ev(self, frame, expr):
        with torch.no_grad():
            return eval(expr, frame.f_globals, dict(frame.f_locals))

    def on_line(self, frame, where):
        line = linecache.getline(frame.f_code.co_filename, frame.f_lineno).strip()
        f = frame.f_locals
        if where == "boot":
            if line == "return Gt":
                self.pending_boot = {
                    "mac_discount": tolist(f["mac_discount"]),
                    "bootstrap": tolist(self.ev(frame, BOOT_EXPR[self.alg])),
                    "G": tolist(f["Gt"]),
                }
            return
        if where == "_squeeze_dec_exp" and self.alg == "MacIAICC":
            if line == "squ_j_epi_len = j_mac_v_b.sum(1)":
                self.squeeze[f"critic{f['agent'].idx}"] = {
                    "a_st_filtered": tolist(f["a_st_b"], squeeze_last=False),
                    "ja_st_filtered": tolist(f["ja_st_b"], squeeze_last=False)}
            elif line.startswith("squ_jo_b = torch.split_with_sizes(jo_b[j_mac_v_b]"):
                self.squeeze[f"critic{f['agent'].idx}"]["joint_epi_len"] = \
                    tolist(f["squ_j_epi_len"])
            return
        if where == "_squeeze_dec_exp" and self.alg == "MacIAISC":
            if line == "squ_epi_len = mac_v_b.sum(1)":
                self.squeeze[f"critic{f['idx']}"] = {
                    "a_st_filtered": tolist(f["a_st_b"], squeeze_last=False)}
            return
        if where == "_squeeze_cen_exp" and self.alg == "NaiveMacIASC":
            if line == "squ_epi_len = j_mac_v_b.sum(1)":
                self.squeeze["critic"] = {
                    "ja_st_filtered": tolist(f["ja_st_b"], squeeze_last=False)}
            return
        if where != "train":
            return
        if line.startswith("TD = Gt - "):
            name = self.critic_name(f)
            boot = self.pending_boot
            self.pending_boot = None
            assert boot is not None and boot["G"] == tolist(f["Gt"]), "bootstrap call mismatch"
            rec = {
                # NaiveMacIACC/IASC: `epi_len` is still the raw one from sample() here.
                "epi_len": tolist(f["cen_epi_len"] if self.critic_layout == "shared"
                                  and self.alg != "MacCAC" else f["epi_len"]),
                "mask": tolist(f["exp_valid"]),
                "reward": tolist(f["reward"]),
                "terminate": tolist(f["terminate"]),
                "discount": tolist(f["discount"]),
                "mac_discount": boot["mac_discount"],
                "bootstrap": boot["bootstrap"],
                "G": tolist(f["Gt"]),
                "V": tolist(self.ev(frame, V_EXPR[self.alg])),
                "stepped": False,
            }
            if self.alg in ("NaiveMacIACC", "NaiveMacIASC"):
                rec["joint_record_agent_valid"] = tolist(f["mac_v_b"], squeeze_last=False)
            if self.alg == "MacIAICC":
                rec["mac_st"] = tolist(f["mac_st"], squeeze_last=False)
                rec["joint_K"] = int(f["jobs"].shape[1])
            rec.update(self.squeeze.get(name, {}))
            self.critics[name] = rec
        elif line.endswith("critic_optimizer.zero_grad()"):
            name = self.critic_name(f)
            if self.alg in ("NaiveMacIACC", "NaiveMacIASC"):
                loss = f["joint_critic_loss"]
            elif self.alg == "MacCAC":
                loss = f["self"].controller.agent.critic_loss
            else:
                loss = f["agent"].critic_loss
            self.critics[name]["loss"] = float(loss.item())
        elif line.endswith("critic_optimizer.step()"):
            name = self.critic_name(f)
            net = {n: m for n, m, _, _ in nets_of(self.model, self.alg)}[name]
            self.grads.update(grads_of(name, net))
            self.critics[name]["stepped"] = True
        elif line.startswith("assert adv_value.shape[0:2] == mac_v_b.shape[0:2]"):
            self.critics["critic"]["V_updated"] = tolist(f["V_value"])
            self.critics["critic"]["adv"] = tolist(f["adv_value"])
        elif line.startswith("action_logits = ") and "actor_net(" in line:
            name = self.actor_name(f)
            rec = {"stepped": False}
            if self.alg in ("NaiveMacIACC", "NaiveMacIASC"):
                rec.update(epi_len=tolist(f["epi_len"]), mask=tolist(f["exp_valid"]),
                           action=tolist(f["action"]), adv=tolist(f["adv"]),
                           discount=tolist(f["discount"]))
            else:
                cname = self.critic_name(f)
                self.critics[cname]["V_updated"] = tolist(f["V_value"])
                self.critics[cname]["adv"] = tolist(f["adv_value"])
                rec.update(epi_len=self.critics[cname]["epi_len"], mask=tolist(f["exp_valid"]),
                           action=tolist(f["action"]), adv=tolist(f["adv_value"]),
                           discount=tolist(f["discount"]))
            self.actors[name] = rec
        elif line.endswith("actor_optimizer.zero_grad()"):
            name = self.actor_name(f)
            owner = f["self"].controller.agent if self.alg == "MacCAC" else f["agent"]
            self.actors[name]["loss"] = float(owner.actor_loss.item())
            self.actors[name]["log_pi_a"] = tolist(f["log_pi_a"])
        elif line.endswith("actor_optimizer.step()"):
            name = self.actor_name(f)
            net = {n: m for n, m, _, _ in nets_of(self.model, self.alg)}[name]
            self.grads.update(grads_of(name, net))
            self.actors[name]["stepped"] = True

    def run(self, fn):
        trace_lines(self.codes, self.on_line, fn)


def trace_lines(codes, on_line, fn, on_enter=None):
    """Run `fn()` with a line tracer on the code objects of `codes` ({code: name}) only:
    `on_line(frame, name)` before each line they run, `on_enter(name)` (if given) each time
    one of them is entered. Only observes; returns what `fn` returns."""
    def local_for(where):
        def local(frame, event, arg):
            if event == "line":
                on_line(frame, where)
            return local
        return local

    def glob(frame, event, arg):
        where = codes.get(frame.f_code)
        if where and on_enter:
            on_enter(where)
        return local_for(where) if where else None

    sys.settrace(glob)
    try:
        return fn()
    finally:
        sys.settrace(None)

# ---------------------------------------------------------------- what an update exercises


def exercised_items(case, updates, init_w):
    """{key: evidence or None} over both updates; computed from the recorded data only."""
    T = case["env_params"]["terminate_step"]
    gamma = case["gamma"]
    n = case["n_step_TD"]
    ev = {}

    def note(key, text):
        if ev.get(key) is None:
            ev[key] = text

    keys = ["time_limit_cut", "env_terminal_before_horizon", "env_terminal_at_horizon",
            "truncated_macro_at_end", "joint_macro_truncated_at_end", "episode_lengths_differ",
            "macro_longer_than_one_step", "squeezed_lengths_differ",
            "last_kept_record_bootstraps", "last_kept_record_terminal",
            "n_step_bootstrap_mid", "n_step_full_return_tail", "terminal_episode_agent_bootstraps",
            "busy_agent_at_joint_decision",
            "naive_adv_at_joint_record", "mac_start_filter_applied",
            "agent_start_not_every_joint_record", "actor_grads_nonzero",
            "target_critic_differs_from_online", "target_sync_between_updates",
            "eps_below_one"]
    for k in keys:
        ev[k] = None
    grads_ok = []
    for u, upd in enumerate(updates, 1):
        eps_ = upd["episodes"]
        lens = [len(e) for e in eps_]
        if len(set(lens)) > 1:
            note("episode_lengths_differ", f"update {u}: raw episode lengths {lens} (padding)")
        for e, epi in enumerate(eps_):
            last = epi[-1]
            if len(epi) == T and last["terminate"] == 0:
                note("time_limit_cut", f"update {u} episode {e}: length {T} = "
                     "env_terminate_step with terminate 0 (bootstrapped cut)")
            if len(epi) < T and last["terminate"] == 1:
                note("env_terminal_before_horizon", f"update {u} episode {e}: terminate 1 at "
                     f"step {len(epi)} < {T}")
            if len(epi) == T and last["terminate"] == 1:
                note("env_terminal_at_horizon", f"update {u} episode {e}: terminate 1 at the "
                     f"horizon {T}")
            if min(last["valid"]) == 0:
                note("truncated_macro_at_end", f"update {u} episode {e}: last record valid "
                     f"{last['valid']} (a macro-action still running is dropped)")
            if max(last["valid"]) == 0:
                note("joint_macro_truncated_at_end", f"update {u} episode {e}: every agent busy "
                     "on the last step (joint start filtered)")
            for t in range(1, len(epi)):
                for i, v in enumerate(epi[t - 1]["valid"]):
                    if v == 0:
                        note("macro_longer_than_one_step", f"update {u} episode {e}: agent {i} "
                             f"busy at step {t - 1}->{t}")
                        break
            if case["alg"] == "MacCAC":
                for t in range(1, len(epi)):
                    prev = epi[t - 1]
                    if max(prev["valid"]) == 1 and min(prev["valid"]) == 0:
                        busy = [i for i, v in enumerate(prev["valid"]) if v == 0]
                        if all(epi[t]["action"][i] == prev["action"][i] for i in busy):
                            note("busy_agent_at_joint_decision", f"update {u} episode {e} step "
                                 f"{t}: joint decision with busy agents {busy} keeping actions "
                                 f"{[prev['action'][i] for i in busy]} (conditional mask, P4)")
        for name, c in upd["learner"]["critics"].items():
            el = c["epi_len"]
            if len(set(el)) > 1:
                note("squeezed_lengths_differ", f"update {u} {name}: squeezed lengths {el}")
            for b, k in enumerate(el):
                if k == 0:
                    continue
                if c["terminate"][b][k - 1] == 0:
                    note("last_kept_record_bootstraps", f"update {u} {name} episode {b}: last "
                         "kept record not terminal (bootstraps from the target critic)")
                    if upd["episodes"][b][-1]["terminate"] == 1:
                        note("terminal_episode_agent_bootstraps", f"update {u} {name} episode "
                             f"{b}: the episode ended with terminate 1 while this critic's "
                             "macro-action was running, so its last kept record bootstraps (P9)")
                else:
                    note("last_kept_record_terminal", f"update {u} {name} episode {b}: last kept "
                         "record terminal (no bootstrap)")
                if n >= 2 and k - 1 - n >= 0:
                    note("n_step_bootstrap_mid", f"update {u} {name} episode {b}: {k} records > "
                         f"n_step_TD {n} (n-step bootstrapped returns)")
                if n >= 2 and k >= 2:
                    note("n_step_full_return_tail", f"update {u} {name} episode {b}: full "
                         "returns over the last records")
            if "joint_record_agent_valid" in c:
                jv = c["joint_record_agent_valid"]
                for b, k in enumerate(el):
                    for i in range(len(jv[b][0]) if k else 0):
                        own = sum(jv[b][j][i] for j in range(k))
                        if own < k:
                            note("naive_adv_at_joint_record", f"update {u} episode {b}: agent {i} "
                                 f"ends at {own} of {k} joint records (its advantage is the joint "
                                 "one at its end record)")
            for key in ("a_st_filtered", "ja_st_filtered"):
                if key in c:
                    raw_field = "mac_start"
                    for b, epi in enumerate(upd["episodes"]):
                        if key == "a_st_filtered":
                            i = int(name[len("critic"):])
                            raw = [r[raw_field][i] for r in epi]
                        else:
                            raw = [max(r[raw_field]) for r in epi]
                        filt = c[key][b][:len(epi)]
                        if sum(raw) != sum(filt):
                            note("mac_start_filter_applied", f"update {u} {name} episode {b}: "
                                 f"{key} dropped the start of a truncated macro-action")
            if "mac_st" in c:
                for b, kj in enumerate(c["joint_epi_len"]):
                    if sum(c["mac_st"][b][:kj]) < kj:
                        note("agent_start_not_every_joint_record", f"update {u} {name} episode "
                             f"{b}: starts at {sum(c['mac_st'][b][:kj])} of {kj} joint records")
        actors = list(upd["learner"]["actors"])
        ok = bool(actors) and all(
            any(float(g.abs().max()) > 0 for k, g in upd["_grads"].items()
                if k.split(".", 1)[0] == a) for a in actors)
        grads_ok.append(ok)
        if upd["eps"] < 1:
            note("eps_below_one", f"update {u}: eps {upd['eps']}")
        if upd["target_sync_after"] and u < len(updates):
            note("target_sync_between_updates", f"online critics copied to the targets after "
                 f"update {u} (c_target_update_freq {case['c_target_update_freq']})")
    if all(grads_ok):
        note("actor_grads_nonzero", "every actor's gradient is non-zero in every update (eps "
             f"{[x['eps'] for x in updates]} < 1)")
    diffs = []
    for k, v in init_w.items():
        if k.split(".", 1)[0].endswith("_tgt"):
            online = k.split(".", 1)[0][:-4] + "." + k.split(".", 1)[1]
            diffs.append(float((v - init_w[online]).abs().max()))
    if diffs and min(diffs) > 0:
        note("target_critic_differs_from_online", "every target critic tensor = online + "
             f"N(0, {NOISE_STD}^2)")
    return ev

# ---------------------------------------------------------------- one case


def run_once(ref, case, seed):
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)
    torch.set_num_threads(1)
    alg = case["alg"]
    env = build_env(ref, case)
    model = ref.algs[alg](env, **alg_kwargs(case, seed))
    try:
        perturb_targets(model, alg, seed)
        init_w = weights(model, alg)
        updates = []
        family = ALGS[alg][2]
        for k, eps in enumerate(case["eps"], 1):
            model.envs_runner.run(eps=eps, n_epis=case["train_freq"])
            buf = list(model.memory.buf)
            episodes = [[record_to_json(r, family) for r in epi] for epi in buf]
            cap = Capture(model, alg)
            cap.run(lambda: model.learner.train(eps, 1.0, 1.0, 0.0, False, False))
            assert cap.pending_boot is None
            after = weights(model, alg)
            sync = (k * case["train_freq"]) % case["c_target_update_freq"] == 0
            updates.append({
                "eps": eps,
                "target_sync_after": sync,
                "epi_len": [len(e) for e in episodes],
                "padded_len": max(len(e) for e in episodes),
                "episodes": episodes,
                "learner": {"critics": cap.critics, "actors": cap.actors},
                "_grads": cap.grads,
                "_weights": after,
            })
            if sync:
                model.learner.update_critic_target_net()
                model.learner.update_actor_target_net()
        meta = dict(obs_sizes=[int(x) for x in env.obs_size],
                    n_actions=[int(x) for x in env.n_action],
                    n_agent=int(env.n_agent),
                    state_size=int(env.state_size) if family == "niasc" else None)
        return init_w, updates, meta
    finally:
        model.envs_runner.close()


def run_case(ref, case, base_seed, out_dir, ref_commit):
    for seed in range(base_seed, base_seed + MAX_SEED_TRIES):
        init_w, updates, meta = run_once(ref, case, seed)
        ev = exercised_items(case, updates, init_w)
        missing = [w for w in case["wants"] if ev.get(w) is None]
        if not missing:
            break
    else:
        raise RuntimeError(f"{case['name']}: no seed in [{base_seed}, "
                           f"{base_seed + MAX_SEED_TRIES}) shows {missing}")
    alg = case["alg"]
    mod, cls, family, critic_layout, actor_layout, learner = ALGS[alg]
    files = {"init.safetensors": init_w}
    for k, upd in enumerate(updates, 1):
        files[f"update{k}_grads.safetensors"] = upd.pop("_grads")
        files[f"update{k}_weights.safetensors"] = upd.pop("_weights")
    model_nets = {}
    for name in sorted({k.split(".", 1)[0] for k in init_w}):
        if name.endswith("_tgt"):
            model_nets[name] = {"role": "critic_target", "online": name[:-4]}
        elif name.startswith("actor"):
            model_nets[name] = {"role": "actor"}
        else:
            model_nets[name] = {"role": "critic"}
    golden = {
        "format": "macdec-ac-golden-1",
        "case": case["name"],
        "alg": alg,
        "learner": learner,
        "reference": {"repo": "yuchen-x/MacroMARL", "commit": ref_commit,
                      "torch": torch.__version__.split("+")[0]},
        "env": case["env"],
        "env_class": ENVS[case["env"]][1],
        "env_params": case["env_params"],
        "seed": seed,
        "target_noise_std": NOISE_STD,
        "hyper": {
            "gamma": case["gamma"], "n_step_TD": case["n_step_TD"], "a_lr": case["a_lr"],
            "c_lr": case["c_lr"], **copy.deepcopy(SMALL),
            "n_agent": meta["n_agent"], "obs_sizes": meta["obs_sizes"],
            "n_actions": meta["n_actions"], "state_size": meta["state_size"],
            "train_freq": case["train_freq"], "n_env": case["n_env"],
            "env_terminate_step": case["env_params"]["terminate_step"],
            "c_target_update_freq": case["c_target_update_freq"], "c_train_iteration": 1,
            "entropy_weight": 0.0, "critic_hys": False, "adv_hys": False, "grad_clip": False,
            "obs_last_action": False, "TD_lambda": 0.0,
        },
        "nets": model_nets,
        "record_fields": [f for f in RECORD_SLOTS[family] if f is not None],
        "exercised": [f"{k}: {v}" for k, v in ev.items() if v is not None],
        "updates": updates,
    }
    parent = os.path.dirname(os.path.abspath(out_dir))
    os.makedirs(parent, exist_ok=True)
    tmp = tempfile.mkdtemp(dir=parent)
    for fname, tensors in files.items():
        save_file(tensors, os.path.join(tmp, fname))
        os.chmod(os.path.join(tmp, fname), 0o644)
    with open(os.path.join(tmp, "golden.json"), "w") as fh:
        json.dump(golden, fh, indent=1)
        fh.write("\n")
    if os.path.exists(out_dir):
        shutil.rmtree(out_dir)
    os.rename(tmp, out_dir)
    os.chmod(out_dir, 0o755)
    return golden



def reference_commit(ref_dir, given=None):
    """The MacroMARL commit the fixtures come from: `given`, else the checkout's HEAD, else
    KNOWN_COMMIT (a copy that is not a git checkout)."""
    if given is not None:
        return given
    try:
        return subprocess.check_output(["git", "-C", ref_dir, "rev-parse", "HEAD"],
                                       text=True, stderr=subprocess.DEVNULL).strip()
    except Exception:
        return KNOWN_COMMIT

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ref", required=True, help="checkout of yuchen-x/MacroMARL")
    ap.add_argument("--out", default="tests/golden_ac", help="output directory")
    ap.add_argument("--cases", nargs="*", help="case names (default: all)")
    ap.add_argument("--ref-commit", default=None,
                    help=f"commit of --ref if it is not a git checkout (default {KNOWN_COMMIT})")
    args = ap.parse_args()
    ref_dir = os.path.abspath(args.ref)
    commit = reference_commit(ref_dir, args.ref_commit)
    ref = import_reference(ref_dir)
    os.makedirs(args.out, exist_ok=True)
    for k, case in enumerate(CASES):
        if args.cases and case["name"] not in args.cases:
            continue
        g = run_case(ref, case, 1 + 1000 * k, os.path.join(args.out, case["name"]), commit)
        keys = [e.split(":", 1)[0] for e in g["exercised"]]
        print(f"{case['name']}: seed {g['seed']}, exercised {', '.join(keys)}", flush=True)


if __name__ == "__main__":
    main()
