"""N copies of a domain stepped inside Rust per call (the core ``macdec._macdec.VectorEnv``)."""

from __future__ import annotations

from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _macdec


class VectorEnv:
    """``num_envs`` copies of one domain, NumPy arrays in and out; make one with
    :func:`macdec.vector_env`.

    Observations are ``[num_envs, n_agents, max_obs]`` float32, each agent's zero-padded to the
    longest (``obs_sizes`` has the real lengths); actions ``[num_envs, n_agents]`` integers, a
    busy agent's entry ignored (pass -1). A copy whose episode ends is reset in the same call:
    the returned observations are its new episode's, ``infos["final_obs"]`` the last ones.
    Copy k draws from the random stream of seed ``seed + k``.
    """

    def __init__(self, env_id: str, num_envs: int, **params: Any) -> None:
        self._core = _macdec.VectorEnv(env_id, int(num_envs), params)
        self.env_id = env_id
        self.num_envs: int = self._core.num_envs
        self.n_agents: int = self._core.n_agents
        self.obs_sizes: list = self._core.obs_sizes
        self.n_actions: list = self._core.n_actions
        self.horizon: int = self._core.horizon

    @property
    def params(self) -> Dict[str, Any]:
        """Every key of the domain with its value."""
        return self._core.params

    def reset(self, seed: Optional[int] = None) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
        """Reset every copy: ``(obs, infos)``, ``infos`` with ``action_mask``
        ``[num_envs, n_agents, max_actions]`` bool and ``mac_done`` (all true)."""
        obs, mask = self._core.reset(seed)
        return obs, {
            "action_mask": mask,
            "mac_done": np.ones((self.num_envs, self.n_agents), dtype=bool),
        }

    def step(self, actions) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Dict[str, np.ndarray]]:
        """One primitive step of every copy: ``(obs, rewards [N] float64, terminations [N] bool,
        truncations [N] bool, infos)``; ``infos`` holds ``mac_done`` (who chooses at the next
        step: every agent of a copy that ended and was reset), ``final_mac_done`` (the step's own
        flags, before any reset) and ``executed`` ``[N, n_agents]``, ``action_mask`` and
        ``final_obs``."""
        expected = (self.num_envs, self.n_agents)
        try:
            a = np.asarray(actions)
        except ValueError:
            raise ValueError(f"actions must be an integer array of shape (num_envs, n_agents) = {expected}, got a ragged sequence") from None
        if a.shape != expected:
            raise ValueError(f"actions must be an integer array of shape (num_envs, n_agents) = {expected}, got shape {a.shape}")
        if a.dtype.kind not in "iu":
            env, agent = self._first_non_index(a)
            value = a[env, agent]
            value = value.item() if isinstance(value, np.generic) else value
            raise ValueError(
                f"env {env}, agent {agent}: an action is one macro-action index, an integer in "
                f"0..{self.n_actions[agent]}, got {value!r} (actions must be integers, got dtype {a.dtype})"
            )
        if a.dtype.kind == "u" and a.size and a.max() > np.iinfo(np.int64).max:
            env, agent = np.unravel_index(int(a.argmax()), expected)
            raise ValueError(f"env {env}, agent {agent}: the macro-action must be in 0..{self.n_actions[agent]}, got {a.max()}")
        return self._core.step(np.ascontiguousarray(a, dtype=np.int64))

    def _first_non_index(self, a: np.ndarray) -> Tuple[int, int]:
        """The first (env, agent) of a non-integer array whose entry is no macro-action index
        (a string, a bool, NaN, infinite, fractional or out of its agent's range), else the first
        entry: all are refused, but the message names the one most likely meant."""
        for k, i in np.ndindex(*a.shape):
            v = a[k, i]
            if isinstance(v, (str, bytes, bool, np.bool_)):
                return k, i
            try:
                f = float(v)
            except (TypeError, ValueError):
                return k, i
            if not (np.isfinite(f) and f == int(f) and 0 <= f < self.n_actions[i]):
                return k, i
        return 0, 0

    def close(self) -> None:
        """Nothing to release."""

    def __repr__(self) -> str:
        return f"macdec.vector_env({self.env_id!r}, {self.num_envs}, **{self.params!r})"
