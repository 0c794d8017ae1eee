"""Shared fixtures: the repository root and the `macdec` binary the Python results are checked
against (`cargo build --release` builds it; `MACDEC_BIN` overrides where it is)."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# A tiny Box Pushing experiment: a few seconds per run, several checkpoints.
TINY = """
name = "tiny"
methods = ["dec-hddrqn", "our1"]
seeds = "0..2"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 60
eps_l_d_steps = 20
batch_size = 8
replay_buffer_size = 500
eval_freq = 5
checkpoint_freq = 20
"""


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def macdec_bin() -> Path:
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    path = Path(os.environ.get("MACDEC_BIN", target / "release" / "macdec"))
    if not path.is_file():
        pytest.fail(f"{path}: no macdec binary; run `cargo build --release` first (or set MACDEC_BIN)")
    return path


@pytest.fixture(scope="session")
def run_cli(macdec_bin):
    """Run `macdec ARGS...`, failing the test with its stderr when it fails."""

    def run(*args, cwd=None):
        p = subprocess.run([str(macdec_bin), *map(str, args)], capture_output=True, text=True, cwd=cwd)
        assert p.returncode == 0, f"macdec {' '.join(map(str, args))}: {p.stderr}"
        return p.stdout

    return run


def metrics_without_time(path: Path) -> list:
    """A metrics.csv's lines without the wall-clock column (the one that is not reproducible)."""
    return [line.rsplit(",", 1)[0] for line in path.read_text().splitlines()]
