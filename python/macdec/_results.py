"""Every run of a results tree as one tidy table (the reader behind ``macdec results``)."""

from __future__ import annotations

import os
from typing import Dict, Union

import numpy as np

from . import _macdec

RUN_COLUMNS = ["experiment", "method", "variant", "seed"]


def load_results(root: Union[str, os.PathLike] = "results", as_dict: bool = False):
    """One row per evaluation of every run below ``root``.

    Columns: ``experiment`` (its path below the root, ``fig4a_bp10`` or ``macromarl/bp6``),
    ``method`` and ``variant`` (the curve directory split at ``@``; empty without a sweep),
    ``seed``, then every ``metrics.csv`` column (``episode, env_steps, updates, eval_return,
    eval_return_undiscounted`` (NaN for runs trained before it was recorded), the method
    families' own columns, NaN where a run's family has none, ``wall_seconds``).
    Reads ``metrics.csv`` or ``metrics.csv.gz``, the same rows and values as
    ``macdec results``; a metrics column named like another column (``seed``, ``episode``, a
    second ``loss``) is refused with a ``ValueError`` naming the file. ``seed`` is int64, or
    uint64 when a seed needs all 64 bits. Returns a pandas DataFrame when pandas is installed (the three name
    columns categorical), else (or with ``as_dict=True``) a dict of NumPy arrays.
    """
    raw = _macdec.read_results(os.fspath(root))
    runs = raw["runs"]
    index = raw["run_index"]
    names = {}
    for k, col in enumerate(RUN_COLUMNS[:3]):
        values = [r[k] for r in runs]
        uniques = sorted(set(values))
        at = {v: i for i, v in enumerate(uniques)}
        codes = np.array([at[v] for v in values], dtype=np.int64)
        names[col] = (uniques, codes[index] if len(index) else np.zeros(0, dtype=np.int64))
    # int64 like the other counts, unless a seed needs all 64 bits (seed-<k> takes any u64).
    seed_type = np.uint64 if any(r[3] > np.iinfo(np.int64).max for r in runs) else np.int64
    seeds = np.array([r[3] for r in runs], dtype=seed_type)
    seed = seeds[index] if len(index) else np.zeros(0, dtype=seed_type)
    columns = raw["columns"]
    values = raw["values"]
    if not as_dict:
        try:
            import pandas as pd
        except ImportError:
            as_dict = True
    if as_dict:
        out: Dict[str, np.ndarray] = {}
        for col, (uniques, codes) in names.items():
            out[col] = np.array(uniques, dtype=object)[codes]
        out["seed"] = seed
        for c in columns:
            out[c] = values[c]
        return out
    data = {
        col: pd.Categorical.from_codes(codes, categories=uniques)
        for col, (uniques, codes) in names.items()
    }
    data["seed"] = seed
    for c in columns:
        data[c] = values[c]
    return pd.DataFrame(data)
