"""Training: the same runner as ``macdec train``, called in-process."""

from __future__ import annotations

import json
import numbers
import operator
import os
from pathlib import Path
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _macdec


def _toml_value(key: str, value: Any) -> str:
    """A ``--set`` value in TOML: strings quoted, bools lower case, lists bracketed."""
    # NumPy scalars count as the Python values they stand for (np.int64 is no int, and
    # repr(np.float64(0.5)) is "np.float64(0.5)", which is no TOML).
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(operator.index(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(key, v) for v in value) + "]"
    raise ValueError(f"override `{key}`: {type(value).__name__} is not a config value")


def _json_scalar(value: Any) -> Any:
    """A NumPy scalar or array in a config dict as the Python value it stands for."""
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return operator.index(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not a config value")


def train(
    config: Union[str, os.PathLike, Mapping[str, Any]],
    methods: Optional[Union[str, Sequence[str]]] = None,
    seeds: Optional[Union[str, int, Iterable[int]]] = None,
    out: Union[str, os.PathLike] = "results",
    jobs: Optional[int] = None,
    overrides: Optional[Union[Mapping[str, Any], Sequence[str]]] = None,
    force: bool = False,
    quiet: bool = True,
) -> List[Path]:
    """Train every run (method x variant x seed) of an experiment, as ``macdec train`` does.

    ``config`` is an experiment TOML's path, or a dict in the TOML's shape (``{"methods":
    ["our1"], "seeds": "0..2", "params": {"env_name": "BP_MA", ...}}``; ``name`` defaults to
    ``experiment``). ``methods`` (``"our1,dec-hddrqn"`` or a list), ``seeds`` (``"0..3"``,
    ``"0,3,7"``, an int or a list) and ``overrides`` (``{"total_epi": 300,
    "dec-hddrqn.init_h": 0.3}`` or ``["total_epi=300"]``) are ``--methods``, ``--seeds`` and
    ``--set``. Runs go to ``out/<experiment>/<curve>/seed-<k>/`` with the same files as the
    CLI's (``metrics.csv`` equal byte for byte, wall-clock column aside); ``jobs`` runs at once
    (default: the number of cores). Finished runs are skipped unless ``force``. Figures are not
    drawn (``macdec plot --results out`` draws them).

    Training runs in Rust threads with the GIL released. Ctrl-C (KeyboardInterrupt) stops every
    run at its next episode boundary, saving its checkpoint, and is raised again once they have
    stopped: calling ``train`` again with the same arguments resumes them. A failed run raises
    RuntimeError naming it. Returns the run directories, in the experiment's run order.
    """
    if isinstance(config, Mapping):
        text, is_path = json.dumps(dict(config), default=_json_scalar), False
    else:
        text, is_path = os.fspath(config), True
        if not os.path.isfile(text):
            raise FileNotFoundError(f"{text}: no such experiment file")
    if isinstance(methods, str):
        methods = [m for m in methods.split(",") if m.strip()]
    elif methods is not None:
        methods = [str(m) for m in methods]
    if seeds is not None and not isinstance(seeds, str):
        try:
            if isinstance(seeds, numbers.Integral):
                seeds = str(operator.index(seeds))
            else:
                seeds = ",".join(str(operator.index(s)) for s in seeds)
        except TypeError:
            raise ValueError(f"seeds must be integers, got {seeds!r}") from None
    if overrides is None:
        sets: List[str] = []
    elif isinstance(overrides, Mapping):
        sets = [f"{k}={_toml_value(k, v)}" for k, v in overrides.items()]
    else:
        sets = [str(s) for s in overrides]
    if jobs is not None and int(jobs) < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    runs = _macdec.train(
        text, is_path, methods, seeds, sets, os.fspath(out),
        None if jobs is None else int(jobs), bool(force), bool(quiet),
    )
    busy = [str(d) for d, status in runs if status == "busy"]
    if busy:
        import warnings

        warnings.warn(f"left to another process training them: {', '.join(busy)}", stacklevel=2)
    return [Path(d) for d, _ in runs]
