"""PettingZoo ``ParallelEnv`` over one macdec domain (the Rust core ``macdec._macdec.Env``)."""

from __future__ import annotations

import functools
from typing import Any, Dict, Optional, Tuple

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from . import _macdec



def _action_index(agent: str, action, n_actions: int) -> int:
    """One agent's macro-action as an int: a Python or NumPy integer (a 0-d integer array too),
    never a float, bool or string, which would be truncated or parsed into another action."""
    if isinstance(action, int) and not isinstance(action, bool):
        value = action
    else:
        a = np.asarray(action)
        if a.ndim != 0 or a.dtype.kind not in "iu":
            raise ValueError(
                f"{agent}: an action is one macro-action index, an integer in 0..{n_actions}, got {action!r}"
            )
        value = int(a)
    # Out-of-range values of a free agent are refused in Rust; ones no int64 holds, here.
    if not -(2**63) <= value < 2**63:
        raise ValueError(f"{agent}: the macro-action must be in 0..{n_actions}, got {value}")
    return value

class MacroParallelEnv(ParallelEnv):
    """A macdec domain as a PettingZoo ``ParallelEnv``; make one with :func:`macdec.parallel_env`.

    Agents are ``agent_0 .. agent_{n-1}``. One :meth:`step` is one primitive step. An agent
    whose macro-action is still running keeps it whatever it is sent (its entry may be left out
    of ``actions``); ``infos[agent]`` says ``mac_done`` (it may choose now), ``executed`` (the
    macro-action it ran in the last step) and ``action_mask`` (int8: every macro-action of a free
    agent, only the running one of a busy agent). The reward is the shared team reward, given to
    every agent. The episode ends for all agents at once: a terminal state is a termination, the
    horizon a truncation; after it ``agents`` is empty until :meth:`reset`.
    """

    metadata = {"name": "macdec", "render_modes": ["rgb_array", "ansi"], "is_parallelizable": True}

    def __init__(self, env_id: str, render_mode: Optional[str] = None, **params: Any) -> None:
        if render_mode not in (None, "rgb_array", "ansi"):
            raise ValueError(f"render_mode must be None, 'rgb_array' or 'ansi', got {render_mode!r}")
        self._env = _macdec.Env(env_id, params)
        self.env_id = env_id
        self.render_mode = render_mode
        self.possible_agents = [f"agent_{i}" for i in range(self._env.n_agents)]
        self.agents: list = []
        self._started = False
        self._index = {a: i for i, a in enumerate(self.possible_agents)}
        self._team_return = 0.0
        self.metadata = dict(self.metadata, name=f"macdec/{self._env.env_name}")
        n = self._env.state_size
        self.state_space = (
            spaces.Box(-np.inf, np.inf, shape=(n,), dtype=np.float32) if n > 0 else None
        )

    @property
    def params(self) -> Dict[str, Any]:
        """Every key of the domain with its value (the given ones and the defaults)."""
        return self._env.params

    @property
    def horizon(self) -> int:
        """The horizon in primitive steps."""
        return self._env.horizon

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent: str) -> spaces.Box:
        """The agent's macro-observation: a float32 vector."""
        size = self._env.obs_sizes[self._agent_index(agent)]
        return spaces.Box(-np.inf, np.inf, shape=(size,), dtype=np.float32)

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent: str) -> spaces.Discrete:
        """The agent's macro-actions, by index (names: :meth:`action_names`)."""
        return spaces.Discrete(self._env.n_actions[self._agent_index(agent)])

    def action_names(self, agent: str) -> list:
        """The names of the agent's macro-actions, by index."""
        return self._env.action_names(self._agent_index(agent))

    def obs_names(self, agent: str) -> list:
        """The names of the agent's observation entries, in order."""
        return self._env.obs_names(self._agent_index(agent))

    def reset(
        self, seed: Optional[int] = None, options: Optional[dict] = None
    ) -> Tuple[Dict[str, np.ndarray], Dict[str, dict]]:
        """Start an episode. ``seed`` restarts the environment's random stream (``None``
        continues it; the first reset without a seed draws one). ``options`` is not used."""
        self._env.reset(seed)
        self._started = True
        self.agents = list(self.possible_agents)
        self._team_return = 0.0
        return self._observations(), self._infos()

    def step(self, actions: Dict[str, int]):
        """One primitive step: ``(obs, rewards, terminations, truncations, infos)``, dicts by agent."""
        if not self._started:
            raise RuntimeError("step called before reset(): call reset() to start an episode")
        if not self.agents:
            raise RuntimeError("step called after the episode ended; call reset() first")
        row = [-1] * len(self.possible_agents)
        for agent, action in actions.items():
            i = self._agent_index(agent)
            row[i] = _action_index(agent, action, self.action_space(agent).n)
        mac_done = self._env.mac_done()
        missing = [a for a, i in self._index.items() if mac_done[i] and a not in actions]
        if missing:
            raise ValueError(f"{', '.join(missing)} may choose now (mac_done) but got no action")
        reward, terminated, truncated = self._env.step(row)
        self._team_return += reward
        live = self.agents
        obs, infos = self._observations(), self._infos()
        rewards = {a: reward for a in live}
        terminations = {a: terminated for a in live}
        truncations = {a: truncated for a in live}
        if terminated or truncated:
            self.agents = []
        return obs, rewards, terminations, truncations, infos

    def state(self) -> np.ndarray:
        """The global state (MacroMARL's ``get_state()``); an error for a domain without one."""
        s = self._env.state()
        if s is None:
            raise NotImplementedError(f"{self._env.env_name} has no global state")
        return s

    def render(self):
        """``rgb_array``: the picture ``macdec render`` draws ([H, W, 3] uint8, ``None`` for a
        domain that draws none); ``ansi``: a text picture; no render mode: ``None``."""
        if self.render_mode == "rgb_array":
            return self._env.render_rgb(self._team_return)
        if self.render_mode == "ansi":
            return self._env.render_ascii()
        return None

    def close(self) -> None:
        """Nothing to release."""

    def _agent_index(self, agent: str) -> int:
        try:
            return self._index[agent]
        except (KeyError, TypeError):
            raise ValueError(
                f"unknown agent {agent!r}: this domain has {', '.join(self.possible_agents)}"
            ) from None

    def _observations(self) -> Dict[str, np.ndarray]:
        return {a: self._env.obs(i) for i, a in enumerate(self.possible_agents)}

    def _infos(self) -> Dict[str, dict]:
        mac_done = self._env.mac_done()
        executed = self._env.executed()
        return {
            a: {
                "mac_done": mac_done[i],
                "executed": executed[i],
                "action_mask": self._env.action_mask(i),
            }
            for i, a in enumerate(self.possible_agents)
        }

    def __repr__(self) -> str:
        return f"macdec.parallel_env({self.env_id!r}, **{self.params!r})"
