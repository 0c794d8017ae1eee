"""load_results: the rows and values of `macdec results`, metrics.csv and metrics.csv.gz, and
the README's final-return tables from the committed reproduction/ tree."""

import gzip
import io
import math
import re
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import macdec

VALUE_RUN = "episode,env_steps,updates,eval_return,epsilon,hysteresis,loss,wall_seconds\n"
AC_RUN = "episode,env_steps,updates,eval_return,eval_return_undiscounted,critic_loss,wall_seconds\n"


def write_tree(root):
    """Three runs: two value-based (one gzip-compressed, both in the form of runs trained before
    the undiscounted return was recorded) and an actor-critic sweep point."""
    a = root / "fig" / "our1" / "seed-0"
    a.mkdir(parents=True)
    (a / "metrics.csv").write_text(VALUE_RUN + "0,0,0,1.5,1.0,0.2,,0.1\n10,400,8,2.25,0.5,0.2,0.125,1.5\n")
    b = root / "fig" / "our1" / "seed-3"
    b.mkdir(parents=True)
    (b / "metrics.csv.gz").write_bytes(gzip.compress((VALUE_RUN + "0,0,0,-3.0,1.0,0.2,,0.2\n").encode()))
    c = root / "group" / "ac" / "mac-iac@lr=0.01" / "seed-1"
    c.mkdir(parents=True)
    (c / "metrics.csv").write_text(AC_RUN + "0,0,0,7.0,9.0,0.75,0.3\n5,100,1,8.5,10.5,0.5,0.9\n")
    (root / "fig" / "our1" / "seed-9").mkdir()  # no metrics: not a run


def test_a_fixture_tree_loads_as_a_tidy_frame(tmp_path):
    write_tree(tmp_path)
    df = macdec.load_results(tmp_path)
    assert list(df.columns) == [
        "experiment", "method", "variant", "seed", "episode", "env_steps", "updates",
        "eval_return", "eval_return_undiscounted", "epsilon", "hysteresis", "loss", "critic_loss",
        "wall_seconds",
    ]
    assert len(df) == 5
    assert df["experiment"].tolist() == ["fig", "fig", "fig", "group/ac", "group/ac"]
    assert df["method"].tolist() == ["our1", "our1", "our1", "mac-iac", "mac-iac"]
    assert df["variant"].tolist() == ["", "", "", "lr=0.01", "lr=0.01"]
    assert df["seed"].tolist() == [0, 0, 3, 1, 1]
    assert df["eval_return"].tolist() == [1.5, 2.25, -3.0, 7.0, 8.5]
    assert df["episode"].dtype == np.int64
    assert math.isnan(df["loss"][0]) and df["loss"][1] == 0.125
    assert df["eval_return_undiscounted"][:3].isna().all()
    assert df["eval_return_undiscounted"][3:].tolist() == [9.0, 10.5]
    assert df["critic_loss"][:3].isna().all() and df["critic_loss"][3] == 0.75
    d = macdec.load_results(tmp_path, as_dict=True)
    assert isinstance(d["eval_return"], np.ndarray) and d["method"].tolist() == df["method"].tolist()


def test_without_pandas_it_is_a_dict_of_numpy_arrays(tmp_path, monkeypatch):
    write_tree(tmp_path)
    monkeypatch.setitem(sys.modules, "pandas", None)  # `import pandas` now fails
    d = macdec.load_results(tmp_path)
    assert isinstance(d, dict) and list(d)[:5] == ["experiment", "method", "variant", "seed", "episode"]
    assert d["eval_return"].tolist() == [1.5, 2.25, -3.0, 7.0, 8.5]
    assert d["seed"].dtype == np.int64 and d["variant"].tolist()[-1] == "lr=0.01"


def test_it_reads_what_macdec_results_writes(tmp_path, run_cli):
    write_tree(tmp_path)
    ours = macdec.load_results(tmp_path)
    cli = pd.read_csv(io.StringIO(run_cli("results", "--results", tmp_path)), keep_default_na=False,
                      na_values={c: [""] for c in ours.columns[4:]})
    assert list(cli.columns) == list(ours.columns)
    for c in ours.columns:
        assert ours[c].astype(object).tolist() == cli[c].astype(object).tolist() or np.allclose(
            ours[c].to_numpy(float), cli[c].to_numpy(float), equal_nan=True, rtol=0, atol=0
        ), c


def test_the_readmes_pandas_recipe_for_macdec_results_keeps_every_curve(tmp_path, run_cli):
    """README "Results as a table": the recipe's lines as printed, on `macdec results --out`."""
    write_tree(tmp_path / "tree")
    run_cli("results", "--results", tmp_path / "tree", "--out", tmp_path / "runs.csv")
    runs = pd.read_csv(tmp_path / "runs.csv")
    means = runs.groupby(["experiment", "method", "variant"], dropna=False).eval_return.mean()
    assert len(means) == 2
    by_curve = {(e, m, "" if pd.isna(v) else v): x for (e, m, v), x in means.items()}
    assert by_curve[("group/ac", "mac-iac", "lr=0.01")] == 7.75
    assert by_curve[("fig", "our1", "")] == pytest.approx((1.5 + 2.25 - 3.0) / 3)
    # Why the recipe says dropna=False: pandas reads the empty variant as NaN and drops it.
    assert len(runs.groupby(["experiment", "method", "variant"]).eval_return.mean()) == 1


def test_hostile_column_names_and_huge_seeds(tmp_path, macdec_bin):
    """A family column may be called `runs` or `columns`; one named like a run column is refused
    by both readers; a seed needing all 64 bits keeps its value."""
    run = tmp_path / "ok" / "e" / "m" / "seed-18446744073709551615"
    run.mkdir(parents=True)
    (run / "metrics.csv").write_text(
        "episode,env_steps,updates,eval_return,runs,columns,wall_seconds\n0,0,0,1.5,8,9,0.1\n"
    )
    df = macdec.load_results(tmp_path / "ok")
    assert df["runs"].tolist() == [8.0] and df["columns"].tolist() == [9.0]
    assert df["seed"].tolist() == [2**64 - 1] and df["eval_return"].tolist() == [1.5]
    for name in ["seed", "experiment", "episode", "eval_return"]:
        bad = tmp_path / name / "e" / "m" / "seed-0"
        bad.mkdir(parents=True)
        (bad / "metrics.csv").write_text(
            f"episode,env_steps,updates,eval_return,{name},wall_seconds\n0,0,0,1.5,7,0.1\n"
        )
        with pytest.raises(ValueError, match=f"`{name}`") as e:
            macdec.load_results(tmp_path / name)
        assert "metrics.csv" in str(e.value)
        p = subprocess.run([str(macdec_bin), "results", "--results", str(tmp_path / name)],
                           capture_output=True, text=True)
        assert p.returncode != 0 and f"`{name}`" in p.stderr


def test_a_missing_or_empty_tree_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere"):
        macdec.load_results(tmp_path / "nowhere")
    with pytest.raises(ValueError, match="no runs found"):
        macdec.load_results(tmp_path)


CURVES = {"Dec-HDDRQN": "dec-hddrqn", "Cen-DDRQN": "cen-ddrqn", "Our-1": "our1", "Our-1-R": "our1-r", "Our-2": "our2"}


def readme_tables(text):
    """{experiment: {curve: "mean ± SE"}} of each 'Figure ... from reproduction/' table."""
    tables = {}
    for m in re.finditer(r"!\[Figure [^\]]* from reproduction/[^\]]*\]\(plots/([a-z0-9_]+)\.png\)", text):
        table = re.search(r"(?:^\|.*\n)+", text[m.end():], re.M).group(0)
        lines = table.splitlines()
        header = [h.strip() for h in lines[0].strip("|").split("|")]
        col = header.index("final return (mean ± SE)")
        rows = {}
        for line in lines[2:]:
            cells = [c.strip() for c in line.strip("|").split("|")]
            rows[CURVES[cells[0]]] = cells[col]
        tables[m.group(1)] = rows
    return tables


def test_the_reproduction_tree_gives_the_readmes_final_return_tables(root):
    tables = readme_tables((root / "README.md").read_text())
    assert set(tables) == {"fig4a_bp10", "fig4b_bp30", "fig5_wtd", "fig6_wtd_ablation"}
    df = macdec.load_results(root / "reproduction")
    # A run's final return: the mean of its last ceil(n / 10) evaluations.
    def final(g):
        r = g.sort_values("episode")["eval_return"].to_numpy()
        return r[-math.ceil(len(r) / 10):].mean()

    finals = df.groupby(["experiment", "method", "seed"], observed=True).apply(final, include_groups=False)
    checked = 0
    for experiment, rows in tables.items():
        for curve, shown in rows.items():
            # Figure 6's Our-2 is Figure 5's runs (shared_curves.toml).
            home = "fig5_wtd" if (experiment, curve) == ("fig6_wtd_ablation", "our2") else experiment
            f = finals.loc[(home, curve)].to_numpy()
            assert len(f) == 40, (experiment, curve)
            mean, se = f.mean(), f.std(ddof=1) / math.sqrt(len(f))
            assert f"{mean:.2f} ± {se:.2f}" == shown, (experiment, curve)
            checked += 1
    assert checked == 12
