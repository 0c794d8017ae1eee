"""macdec from Python: macro-action multi-agent deep RL in Rust.

- :func:`parallel_env`: every macdec domain as a PettingZoo ``ParallelEnv``.
- :func:`vector_env`: N copies stepped inside Rust per call, NumPy arrays in and out.
- :func:`train`: the ``macdec train`` runner in-process (Ctrl-C stops it resumably).
- :func:`load_results`: every run of a results tree as a tidy pandas DataFrame.
- :class:`Policy`: a trained policy directory acting as ``macdec eval`` does.
"""

from __future__ import annotations

from typing import Any, Optional

from . import _macdec
from ._policy import Policy
from ._results import load_results
from ._train import train
from ._vector import VectorEnv

__version__: str = _macdec.__version__

__all__ = [
    "__version__",
    "env_ids",
    "parallel_env",
    "vector_env",
    "train",
    "load_results",
    "Policy",
    "VectorEnv",
]


def env_ids() -> list:
    """The ids of the built-in domains (``BP_MA``, ``BP-MA-v0``, ``OSD_S_4``, ``OSD-D-v7``, ...);
    each also answers to its aliases (``box-pushing``, ``warehouse``, ``overcooked``)."""
    return list(_macdec.env_ids())


def parallel_env(env_id: str, render_mode: Optional[str] = None, **params: Any):
    """The domain ``env_id`` with its keys ``params`` as a PettingZoo ``ParallelEnv``.

    Ids and keys are the configs' and the references': ``parallel_env("BP_MA", grid_dim=10,
    env_terminate_step=100)``, ``parallel_env("OSD_S_4")``, ``parallel_env("BP-MA-v0",
    grid_dim=[6, 6])``, ``parallel_env("OSD-D-v7")``, ``parallel_env("Overcooked-MA-v1")``.
    An unknown id or a bad key raises ValueError naming it. ``render_mode``: ``"rgb_array"``
    or ``"ansi"``. See :class:`macdec._parallel.MacroParallelEnv`.
    """
    from ._parallel import MacroParallelEnv

    return MacroParallelEnv(env_id, render_mode=render_mode, **params)


def vector_env(env_id: str, num_envs: int, **params: Any) -> VectorEnv:
    """``num_envs`` copies of the domain ``env_id``, stepped inside Rust per call with NumPy
    arrays in and out (see :class:`VectorEnv`)."""
    return VectorEnv(env_id, num_envs, **params)
