"""Trained policies: a policy directory loaded and acted with as ``macdec eval`` does."""

from __future__ import annotations

import os
from typing import Any, Dict, Mapping, Optional, Sequence, Union

import numpy as np

from . import _macdec


class Policy:
    """A policy directory's nets (Q-nets or actors) with their hidden states, acting as
    ``macdec eval`` runs them.

    Load one with :meth:`Policy.load`. Most policies are one net per agent: each agent acts on
    its own macro-observation only, and only when its macro-action is done: its hidden state then
    advances one macro-step and it picks the highest score (ties to the lowest index), exactly
    as ``macdec eval`` and robots do. A policy that acts only centrally (Cen-DDRQN's Q-net,
    Mac-CAC's actor; :attr:`centralized`) is one net for the whole team: whenever an agent is
    done it reads every agent's observation and picks a joint macro-action that keeps the busy
    agents' running ones, as ``macdec eval`` runs it (no robot can serve it).
    """

    def __init__(self, core: "_macdec.Policy") -> None:
        self._core = core
        self.agents = [f"agent_{i}" for i in range(core.n_agents)]
        self.scores: Dict[str, np.ndarray] = {}

    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> "Policy":
        """Load a policy directory: a run's ``policy/`` (or the run directory itself) of any
        method, a ``macdec export`` or ``macdec import`` output. The nets loaded are the ones the
        run's evaluations used (each agent's own, or the team's centralized net). Every weight
        file is checked (SHA-256, shapes, domain layout); a problem raises ValueError naming
        it."""
        return cls(_macdec.Policy.load(os.fspath(path)))

    @property
    def dir(self) -> str:
        """The policy directory read."""
        return str(self._core.dir)

    @property
    def kinds(self) -> list:
        """Each agent's net: ``"q"`` (scores are Q-values) or ``"actor"`` (log-probabilities)."""
        return self._core.kinds

    @property
    def centralized(self) -> bool:
        """Whether the policy is one centralized net acting for the whole team."""
        return self._core.centralized

    @property
    def discount(self) -> float:
        """The discount per primitive step the policy was trained under."""
        return self._core.discount

    @property
    def run(self) -> Dict[str, Any]:
        """The run it came from: experiment, method, variant, seed, episodes_trained."""
        return self._core.run

    @property
    def env_id(self) -> Optional[str]:
        """The domain's ``env_name`` (``None`` for a domain this build does not have)."""
        spec = self._core.env_spec()
        return None if spec is None else spec[0]

    @property
    def env_params(self) -> Dict[str, Any]:
        """The domain's keys, as recorded with the policy."""
        spec = self._core.env_spec()
        return {} if spec is None else spec[1]

    def make_env(self, **kwargs: Any):
        """The policy's domain as a PettingZoo env (:func:`macdec.parallel_env`)."""
        from ._parallel import MacroParallelEnv

        if self.env_id is None:
            raise ValueError(f"{self.dir}: its domain is not built into this package")
        return MacroParallelEnv(self.env_id, **{**self.env_params, **kwargs})

    def reset(self) -> None:
        """Zero every agent's hidden state, as at the start of an episode."""
        self._core.reset()
        self.scores = {}

    def act(
        self,
        obs: Union[Mapping[str, Any], Sequence[Any]],
        mac_done: Union[Mapping[str, Any], Sequence[bool]],
        return_scores: bool = False,
        sample: bool = False,
    ):
        """Each agent's macro-action for one primitive step: ``{agent: action}``.

        ``obs`` and ``mac_done`` are dicts by agent (as ``parallel_env`` gives them; ``mac_done``
        may also be the ``infos`` dict) or lists in agent order. Agents whose ``mac_done`` is
        true decide (their hidden state advances); the others keep their running macro-action.
        Call it once per primitive step from :meth:`reset` on: ACAC's actors read the number
        of calls since :meth:`reset` as the primitive step the observation was made at (their
        time embedding), as ``macdec eval`` and robots pass it. Greedy by default; ``sample=True`` draws each decision from the actors' distributions
        as MacroMARL evaluates (the streams ``macdec eval --sample`` draws from, seeded by the
        run's seed and continuing across :meth:`reset`); a Q-net policy refuses it with
        ValueError, since Q-values are not probabilities. The raw scores of the decision
        (Q-values or log-probabilities) are in ``self.scores`` and also returned with
        ``return_scores=True`` as ``(actions, scores)``: by deciding agent, or for a centralized
        policy as ``{"team": scores}`` over joint macro-actions (C order, agent 0 most
        significant).
        """
        obs_list = [self._pick(obs, i, a) for i, a in enumerate(self.agents)]
        done_list = []
        for i, a in enumerate(self.agents):
            d = self._pick(mac_done, i, a)
            if isinstance(d, Mapping):
                d = d["mac_done"]
            done_list.append(bool(d))
        obs_arrays = [np.ascontiguousarray(o, dtype=np.float32).reshape(-1) for o in obs_list]
        actions, scores = self._core.act(obs_arrays, done_list, sample)
        names = ["team"] if self.centralized else self.agents
        self.scores = {a: s for a, s in zip(names, scores) if s is not None}
        acts = {a: int(x) for a, x in zip(self.agents, actions) if x is not None}
        return (acts, dict(self.scores)) if return_scores else acts

    def _pick(self, values, i: int, agent: str):
        if isinstance(values, Mapping):
            try:
                return values[agent]
            except KeyError:
                raise ValueError(f"no entry for {agent}") from None
        if len(values) != len(self.agents):
            raise ValueError(f"expected {len(self.agents)} entries (one per agent), got {len(values)}")
        return values[i]

    def __repr__(self) -> str:
        r = self.run
        return f"macdec.Policy({self.dir!r}: {r['method']} seed {r['seed']} on {self.env_id})"
