"""train: the same files as `macdec train` (metrics.csv byte for byte, wall-clock column
aside) from a path or a dict; overrides; errors; Ctrl-C stops resumably."""

import os
import signal
import subprocess
import sys
import textwrap
import time
import tomllib

import pytest

import macdec
from conftest import TINY, metrics_without_time


def test_train_equals_macdec_train_byte_for_byte(tmp_path, run_cli):
    config = tmp_path / "tiny.toml"
    config.write_text(TINY)
    run_cli("train", "--config", config, "--out", tmp_path / "cli", "--quiet", "--no-plot", "--jobs", "2")
    dirs = macdec.train(config, out=tmp_path / "py", jobs=2)
    assert [d.relative_to(tmp_path / "py").as_posix() for d in dirs] == [
        "tiny/dec-hddrqn/seed-0", "tiny/dec-hddrqn/seed-1", "tiny/our1/seed-0", "tiny/our1/seed-1",
    ]
    for d in dirs:
        rel = d.relative_to(tmp_path / "py")
        ours = metrics_without_time(d / "metrics.csv")
        assert len(ours) == 1 + 60 // 5 + 1
        assert ours == metrics_without_time(tmp_path / "cli" / rel / "metrics.csv"), rel
        assert (d / "finished").exists() and (d / "policy" / "policy.json").exists()
    assert metrics_without_time(dirs[2] / "metrics.csv") != metrics_without_time(dirs[3] / "metrics.csv")
    # Finished runs are skipped: nothing is rewritten.
    before = (dirs[0] / "metrics.csv").read_bytes()
    macdec.train(config, out=tmp_path / "py")
    assert (dirs[0] / "metrics.csv").read_bytes() == before


ACAC = """
name = "acac_tiny"
methods = ["acac", "acac-vanilla", "acac-micro-gae"]
seeds = "0"

[params]
env_name = "BP-MA-v0"
grid_dim = [6, 6]
env_terminate_step = 30
total_epi = 24
n_env = 4
train_freq = 4
c_target_update_freq = 8
eval_freq = 8
eval_num_epi = 2
"""


def test_acacs_three_methods_train_from_python_as_from_the_cli(tmp_path, run_cli):
    """Issue 41 item 7: macdec.train runs ACAC's methods like the others (metrics equal to the
    CLI's), and their runs write their actors' policy files as every method does."""
    config = tmp_path / "acac.toml"
    config.write_text(ACAC)
    run_cli("train", "--config", config, "--out", tmp_path / "cli", "--quiet", "--no-plot")
    as_dict = tomllib.loads(ACAC)
    dirs = macdec.train(as_dict, out=tmp_path / "py")
    assert [d.parent.name for d in dirs] == as_dict["methods"]
    for d in dirs:
        rel = d.relative_to(tmp_path / "py")
        ours = metrics_without_time(d / "metrics.csv")
        assert "acac_timesteps" in ours[0]
        assert len(ours) > 2
        assert ours == metrics_without_time(tmp_path / "cli" / rel / "metrics.csv"), rel
        assert (d / "finished").exists() and (d / "policy" / "policy.json").exists()
    # The three methods differ (PPO with GAE, with lambda per primitive step, vanilla PG).
    m = [metrics_without_time(d / "metrics.csv") for d in dirs]
    assert m[0] != m[1] and m[0] != m[2]


def test_a_dict_config_with_methods_seeds_and_overrides(tmp_path, run_cli):
    config = tmp_path / "tiny.toml"
    config.write_text(TINY)
    run_cli("train", "--config", config, "--out", tmp_path / "cli", "--quiet", "--no-plot",
            "--methods", "our1", "--seeds", "1", "--set", "total_epi=30", "--set", "our1.l_rate=0.002")
    as_dict = tomllib.loads(TINY)
    dirs = macdec.train(as_dict, methods="our1", seeds=[1], out=tmp_path / "py",
                        overrides={"total_epi": 30, "our1.l_rate": 0.002})
    assert len(dirs) == 1
    rel = "tiny/our1/seed-1/metrics.csv"
    assert metrics_without_time(tmp_path / "py" / rel) == metrics_without_time(tmp_path / "cli" / rel)
    assert len(metrics_without_time(tmp_path / "py" / rel)) == 1 + 30 // 5 + 1


def test_numpy_scalars_work_wherever_python_numbers_do(tmp_path, run_cli):
    """np.int64 / np.float64 / np.bool_ in overrides, seeds and a config dict give the run that
    the same Python numbers give (numpy's own reprs are no TOML; np.bool_ is no bool)."""
    import numpy as np

    as_dict = tomllib.loads(TINY)
    plain = macdec.train(as_dict, methods="our1", seeds=[1], out=tmp_path / "plain",
                         overrides={"total_epi": 30, "our1.l_rate": 0.002})
    as_dict["params"]["grid_dim"] = np.int64(8)
    as_dict["params"]["eval_freq"] = np.int32(5)
    scalars = macdec.train(as_dict, methods="our1", seeds=np.array([1])[0], out=tmp_path / "np",
                           overrides={"total_epi": np.int64(30), "our1.l_rate": np.float64(0.002)})
    rel = "tiny/our1/seed-1/metrics.csv"
    assert [d.relative_to(tmp_path / "np").as_posix() for d in scalars] == ["tiny/our1/seed-1"]
    assert metrics_without_time(tmp_path / "np" / rel) == metrics_without_time(plain[0] / "metrics.csv")
    with pytest.raises(ValueError, match="seeds must be integers"):
        macdec.train(as_dict, seeds=[0.5], out=tmp_path / "bad")
    # A NumPy bool reads as a bool, not as the number 1.0 (a bool key refuses a number).
    env = macdec.parallel_env("OSD-D-v7", obs_human_wait=np.True_, TB_move_noisy=np.float32(0.5))
    assert env.params["obs_human_wait"] is True
    assert env.params["TB_move_noisy"] == 0.5


def test_bad_configs_are_named(tmp_path):
    with pytest.raises(ValueError, match="gird_dim"):
        macdec.train({"methods": ["our1"], "params": {"env_name": "BP_MA", "gird_dim": 8}}, out=tmp_path)
    with pytest.raises(ValueError, match="not-a-method"):
        macdec.train({"params": {"env_name": "BP_MA"}}, methods="not-a-method", out=tmp_path)
    with pytest.raises(FileNotFoundError, match="missing.toml"):
        macdec.train(tmp_path / "missing.toml", out=tmp_path)
    # An unknown key's hint comes from the method's own family (and names the family it is of).
    with pytest.raises(ValueError, match=r"unknown key `l_rate` for mac-iac \(`l_rate` is a key of the ICRA 2020.*a_lr, c_lr"):
        macdec.train({"methods": ["mac-iac"], "params": {"env_name": "BP-MA-v0", "l_rate": 0.01}}, out=tmp_path)
    # One key per override: a line break inside one would apply the first key and drop the rest.
    with pytest.raises(ValueError, match="line break"):
        macdec.train({"methods": ["our1"], "params": {"env_name": "BP_MA"}}, out=tmp_path,
                     overrides=["total_epi=30\neval_freq=5"])
    assert not any(tmp_path.iterdir())


def test_a_joint_action_net_beyond_the_memory_bound_is_a_value_error(tmp_path):
    # Mac-CAC on Overcooked B scores 15^3 = 3375 joint macro-actions: 200 episodes per update
    # would need more than 5 GB. It is refused by name before anything is allocated, instead of
    # aborting the interpreter.
    config = {"methods": ["mac-cac"], "params": {"env_name": "Overcooked-MA-v1", "map_type": "B"}}
    with pytest.raises(ValueError, match="widest output 3375"):
        macdec.train(config, out=tmp_path, overrides={"n_env": 200, "train_freq": 200})
    assert not any(tmp_path.iterdir())


def test_a_run_that_could_not_update_is_refused_never_finished(tmp_path):
    # Certain from the config: a ValueError naming the key before any run starts.
    ac = {"methods": ["mac-iac"], "params": {"env_name": "BP-MA-v0", "grid_dim": [6, 6], "env_terminate_step": 20,
                                            "total_epi": 16, "n_env": 4, "train_freq": 32, "eval_freq": 8}}
    with pytest.raises(ValueError, match=r"`train_freq`: must be at most total_epi \(16\)"):
        macdec.train(ac, out=tmp_path)
    for method in ("our1", "mac-dec-q"):
        with pytest.raises(ValueError, match=r"`train_freq`: must be at most total_epi x env_terminate_step"):
            macdec.train({"methods": [method], "params": {"env_name": "BP-MA-v0" if method == "mac-dec-q" else "BP_MA"}},
                         out=tmp_path, overrides={"total_epi": 40, "start_train": 2, "eval_freq": 10, "train_freq": 10**6})
    assert not any(tmp_path.iterdir())
    # Not certain (the episodes ended early): the budget is trained, then the run fails naming why.
    value = {"methods": ["our1"], "seeds": "0", "params": {"env_name": "BP_MA", "grid_dim": 8, "env_terminate_step": 30,
                                                           "total_epi": 2, "start_train": 2, "eval_freq": 1, "train_freq": 7}}
    with pytest.raises(RuntimeError, match="without a single update"):
        macdec.train(value, out=tmp_path)
    (run,) = [d for d in tmp_path.glob("*/our1/seed-0")]
    assert (run / "metrics.csv").is_file() and not (run / "finished").exists()


def test_ctrl_c_stops_cleanly_and_training_again_resumes_to_the_same_metrics(tmp_path, run_cli):
    config = tmp_path / "long.toml"
    config.write_text(TINY.replace("total_epi = 60", "total_epi = 3000").replace('seeds = "0..2"', 'seeds = "0"')
                      .replace('methods = ["dec-hddrqn", "our1"]', 'methods = ["our1"]'))
    run_cli("train", "--config", config, "--out", tmp_path / "whole", "--quiet", "--no-plot")
    # Python leaves SIGINT ignored when it started ignored (a background job of a non-interactive
    # shell, as CI may be launched): restore Ctrl-C's KeyboardInterrupt so the test sees macdec's
    # handling, not its launcher's.
    script = textwrap.dedent(f"""
        import signal
        signal.signal(signal.SIGINT, signal.default_int_handler)
        import macdec
        try:
            macdec.train({str(config)!r}, out={str(tmp_path / "py")!r})
        except KeyboardInterrupt:
            print("interrupted", flush=True)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    metrics = tmp_path / "py" / "tiny" / "our1" / "seed-0" / "metrics.csv"
    start = time.time()
    while not metrics.exists() and time.time() - start < 120:
        time.sleep(0.02)
    assert metrics.exists(), "no checkpoint was written"
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert out.strip() == "interrupted"
    run = metrics.parent
    assert not (run / "finished").exists(), "the run finished before it could be interrupted; make it longer"
    assert (run / "checkpoint.bin").exists()
    macdec.train(config, out=tmp_path / "py")
    assert (run / "finished").exists()
    assert metrics_without_time(metrics) == metrics_without_time(tmp_path / "whole" / "tiny" / "our1" / "seed-0" / "metrics.csv")
