"""Type stubs of the Rust core ``macdec._macdec`` (the public API is in ``macdec``)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

def env_ids() -> List[str]:
    """The ids of the built-in domains."""

def train(
    config: str,
    is_path: bool,
    methods: Optional[List[str]],
    seeds: Optional[str],
    set: List[str],
    out: Union[str, PathLike],
    jobs: Optional[int],
    force: bool,
    quiet: bool,
) -> List[Tuple[str, str]]:
    """Train an experiment's runs; ``(run directory, status)`` per run."""

def read_results(root: Union[str, PathLike]) -> Dict[str, Any]:
    """Every run below ``root``: ``runs``, ``run_index``, ``columns`` and one array per column."""

class Env:
    """One environment of a domain and its random stream."""

    env_name: str
    params: Dict[str, Any]
    n_agents: int
    obs_sizes: List[int]
    n_actions: List[int]
    horizon: int
    state_size: int
    t: int
    def __init__(self, env_id: str, params: Optional[Dict[str, Any]] = None) -> None: ...
    def describe(self) -> str: ...
    def action_names(self, agent: int) -> List[str]: ...
    def obs_names(self, agent: int) -> List[str]: ...
    def reset(self, seed: Optional[int] = None) -> None: ...
    def step(self, actions: List[int]) -> Tuple[float, bool, bool]:
        """``(reward, terminated, truncated)``; a busy agent's entry is ignored."""
    def obs(self, agent: int) -> npt.NDArray[np.float32]: ...
    def mac_done(self) -> List[bool]: ...
    def executed(self) -> List[int]: ...
    def action_mask(self, agent: int) -> npt.NDArray[np.int8]: ...
    def state(self) -> Optional[npt.NDArray[np.float32]]: ...
    def render_rgb(self, team_return: float = 0.0) -> Optional[npt.NDArray[np.uint8]]: ...
    def render_ascii(self) -> str: ...

class VectorEnv:
    """N copies of a domain stepped in one call."""

    num_envs: int
    env_name: str
    params: Dict[str, Any]
    n_agents: int
    obs_sizes: List[int]
    n_actions: List[int]
    horizon: int
    def __init__(self, env_id: str, num_envs: int, params: Optional[Dict[str, Any]] = None) -> None: ...
    def reset(self, seed: Optional[int] = None) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.bool_]]: ...
    def step(
        self, actions: npt.NDArray[np.int64]
    ) -> Tuple[
        npt.NDArray[np.float32],
        npt.NDArray[np.float64],
        npt.NDArray[np.bool_],
        npt.NDArray[np.bool_],
        Dict[str, np.ndarray],
    ]: ...

class Policy:
    """A loaded policy directory."""

    dir: str
    n_agents: int
    obs_sizes: List[int]
    n_actions: List[int]
    kinds: List[str]
    centralized: bool
    discount: float
    run: Dict[str, Any]
    @staticmethod
    def load(dir: Union[str, PathLike]) -> "Policy": ...
    def env_spec(self) -> Optional[Tuple[str, Dict[str, Any]]]: ...
    def action_names(self) -> List[List[str]]: ...
    def reset(self) -> None: ...
    def act(
        self,
        obs: Sequence[npt.NDArray[np.float32]],
        mac_done: Sequence[bool],
        sample: bool = False,
    ) -> Tuple[List[Optional[int]], List[Optional[npt.NDArray[np.float32]]]]: ...
