"""`macdec report`'s marl-eval JSON: the schema marl-eval documents (env -> task -> algorithm ->
run -> step_k / absolute_metrics), read the way marl-eval's `create_matrices_for_rliable` reads
it, and, when marl-eval is installed, by marl-eval itself."""

import csv
import json

import pytest

ROOT_CONFIG = "reproduction/macromarl/bp6/mac-iac/seed-0/config.toml"
HEADER = "episode,env_steps,updates,eval_return,eps,critic_loss,actor_loss,train_return,wall_seconds\n"


def write_tree(root, config):
    """Two methods of three runs, 12 evaluations each; Mac-CAC evaluated 13 times (thinned)."""
    finals = {"mac-iac": [10.0, 20.0, 30.0], "mac-cac": [100.0, 90.0, 120.0]}
    for method, lasts in finals.items():
        n = 13 if method == "mac-cac" else 12
        for seed, last in enumerate(lasts):
            d = root / "bp" / method / f"seed-{seed}"
            d.mkdir(parents=True)
            rows = [
                f"{i * 100},{i * 1000 + seed},{i},{last if i >= n - 2 else float(i)},1.0,,,,{i}.5\n"
                for i in range(n)
            ]
            (d / "metrics.csv").write_text(HEADER + "".join(rows))
            (d / "config.toml").write_text(config)
            (d / "finished").write_text("")
    return finals


@pytest.fixture
def report(tmp_path, root, run_cli):
    finals = write_tree(tmp_path / "results", (root / ROOT_CONFIG).read_text())
    out = tmp_path / "out"
    run_cli("report", "--results", tmp_path / "results", "--out", out, "--resamples", "200")
    with open(out / "bp_marl_eval.json") as f:
        raw = json.load(f)
    with open(out / "bp_aggregate.csv") as f:
        rows = list(csv.DictReader(f))
    return raw, rows, finals


def test_the_json_has_marl_evals_documented_structure(report):
    raw, _, finals = report
    assert len(raw) == 1
    (env, tasks), = raw.items()
    assert list(tasks) == ["bp"]
    algos = tasks["bp"]
    assert list(algos) == ["mac-iac", "mac-cac"]
    assert all("," not in a for a in algos)
    run_names = [list(runs) for runs in algos.values()]
    assert run_names == [["seed_0", "seed_1", "seed_2"]] * 2
    step_names = {tuple(run) for runs in algos.values() for run in runs.values()}
    # Every run: the same steps in order, absolute_metrics last (12 evaluations; Mac-CAC's 13 thinned).
    assert step_names == {tuple(f"step_{k}" for k in range(12)) + ("absolute_metrics",)}
    for algo, runs in algos.items():
        for seed, run in enumerate(runs.values()):
            counts = [run[f"step_{k}"]["step_count"] for k in range(12)]
            assert all(isinstance(c, int) for c in counts) and counts == sorted(counts)
            assert counts[0] == seed
            for k in range(12):
                assert set(run[f"step_{k}"]) == {"step_count", "return"}
                assert len(run[f"step_{k}"]["return"]) == 1
            # The final return: the mean of the last ceil(12 / 10) = 2 (or 13 / 10 -> 2) evaluations.
            assert run["absolute_metrics"] == {"return": [finals[algo][seed]]}


def test_it_reads_as_create_matrices_for_rliable_reads_it(report):
    """marl-eval's access pattern without marl-eval: algorithms, runs and steps taken from the
    first task, algorithm and run, then looked up in every other (a KeyError there is marl-eval
    failing), the absolute metric found by name."""
    raw, rows, finals = report
    (env, data_env), = raw.items()
    tasks = list(data_env)
    algorithms = list(data_env[tasks[0]])
    runs = list(data_env[tasks[0]][algorithms[0]])
    steps = list(data_env[tasks[0]][algorithms[0]][runs[0]])
    absolute = [s for s in steps if "absolute" in s]
    assert absolute == ["absolute_metrics"]
    steps.remove("absolute_metrics")
    matrix = {
        a: [[sum(data_env[t][a][r]["absolute_metrics"]["return"]) for t in tasks] for r in runs]
        for a in algorithms
    }
    curves = {
        a: [[[data_env[t][a][r][s]["return"][0] for s in steps] for t in tasks] for r in runs]
        for a in algorithms
    }
    for a in algorithms:
        assert [row[0] for row in matrix[a]] == finals[a]
        assert len(curves[a]) == 3 and len(curves[a][0][0]) == 12
        # The mean over runs of the absolute metric is the report's `mean`.
        mean = next(float(r["value"]) for r in rows if r["method"] == a and r["metric"] == "mean")
        assert mean == pytest.approx(sum(finals[a]) / 3, abs=1e-12)


def test_marl_eval_itself_reads_it(report):
    pytest.importorskip("marl_eval")
    from marl_eval.utils.data_processing_utils import create_matrices_for_rliable, data_process_pipeline

    raw, _, finals = report
    env = next(iter(raw))
    processed = data_process_pipeline(raw_data=raw, metrics_to_normalize=[])
    scores, sample_efficiency = create_matrices_for_rliable(
        data_dictionary=processed, environment_name=env, metrics_to_normalize=[]
    )
    for algo, values in finals.items():
        assert scores["mean_return"][algo][:, 0].tolist() == values
        assert sample_efficiency["mean_return"][algo].shape == (3, 1, 12)
