"""`macdec train --tensorboard DIR` read by TensorBoard's own readers (issue 42 item 7): each run's
directory holds event files whose scalars, per tag and step, are its metrics.csv columns against
the episode, also after a killed run resumed."""

import csv
import struct
import subprocess
import time

import pytest

pytest.importorskip("tensorboard")
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator  # noqa: E402
from tensorboard.backend.event_processing.event_file_loader import EventFileLoader  # noqa: E402

from conftest import TINY  # noqa: E402


def f32(x: float) -> float:
    """x as TensorBoard stores it (simple_value is a 32-bit float)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def expected(metrics_csv, with_time=True):
    """Every metrics.csv column but `episode` as {tag: [(episode, f32 value), ...]}, empty cells
    left out."""
    with open(metrics_csv, newline="") as f:
        rows = list(csv.DictReader(f))
    tags = {}
    for column in rows[0]:
        if column == "episode" or (column == "wall_seconds" and not with_time):
            continue
        points = [(int(r["episode"]), f32(float(r[column]))) for r in rows if r[column] != ""]
        if points:
            tags[column] = points
    return tags


def shown(run_dir, with_time=True):
    """What TensorBoard shows of a run directory: every scalar tag's (step, value) points."""
    acc = EventAccumulator(str(run_dir))
    acc.Reload()
    return {
        tag: [(e.step, e.value) for e in acc.Scalars(tag)]
        for tag in acc.Tags()["scalars"]
        if with_time or tag != "wall_seconds"
    }


def test_every_run_is_a_tensorboard_run_with_its_metrics_as_scalars(tmp_path, run_cli):
    config = tmp_path / "tiny.toml"
    config.write_text(TINY)
    tb = tmp_path / "tb"
    run_cli("train", "--config", config, "--out", tmp_path / "results", "--quiet", "--no-plot",
            "--jobs", "2", "--tensorboard", tb)
    runs = sorted(p.parent.relative_to(tb).as_posix() for p in tb.rglob("events.out.tfevents.*"))
    assert runs == ["tiny/dec-hddrqn/seed-0", "tiny/dec-hddrqn/seed-1", "tiny/our1/seed-0", "tiny/our1/seed-1"]
    for rel in runs:
        want = expected(tmp_path / "results" / rel / "metrics.csv")
        assert set(want) >= {"eval_return", "eval_return_undiscounted", "epsilon", "loss", "env_steps"}
        assert shown(tb / rel) == want, rel
        # The raw file as TensorBoard's file loader reads it: the version, a session start at
        # step 0, then one event per metrics row.
        (path,) = (tb / rel).glob("events.out.tfevents.*")
        events = list(EventFileLoader(str(path)).Load())
        assert events[0].file_version == "brain.Event:2"
        assert events[1].HasField("session_log") and events[1].session_log.status == 1
        assert events[1].step == 0
        steps = [e.step for e in events[2:]]
        assert steps == [p[0] for p in want["eval_return"]] == list(range(0, 61, 5))
        assert all(abs(e.wall_time - time.time()) < 3600 for e in events)


def test_a_killed_run_resumed_shows_the_curve_of_its_metrics(tmp_path, macdec_bin, run_cli):
    config = tmp_path / "tiny.toml"
    config.write_text(TINY.replace("total_epi = 60", "total_epi = 300"))
    tb = tmp_path / "tb"
    out = tmp_path / "results"
    args = ["train", "--config", config, "--out", out, "--quiet", "--no-plot", "--methods", "our1",
            "--seeds", "0", "--tensorboard", tb]
    run_tb = tb / "tiny" / "our1" / "seed-0"
    run = out / "tiny" / "our1" / "seed-0"
    child = subprocess.Popen([str(macdec_bin), *map(str, args)], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)

    def logged_past_a_checkpoint():
        if not (run / "checkpoint.bin").exists():
            return False
        files = list(run_tb.glob("events.out.tfevents.*"))
        if not files:
            return False
        steps = [e.step for e in EventFileLoader(str(files[0])).Load()]
        return bool(steps) and steps[-1] % 20 != 0

    deadline = time.time() + 120
    try:
        while not logged_past_a_checkpoint() and time.time() < deadline:
            time.sleep(0.005)
    finally:
        child.kill()
        child.wait()
    assert not (run / "finished").exists(), "finished before it was killed; make it longer"
    killed = sorted(run_tb.glob("events.out.tfevents.*"))
    assert len(killed) == 1
    before = shown(run_tb)
    run_cli(*args)
    files = sorted(run_tb.glob("events.out.tfevents.*"))
    assert len(files) == 2 and files[0] == killed[0]
    want = expected(run / "metrics.csv", with_time=False)
    # What the killed process logged after its checkpoint (episode 20, 40, ...) is dropped: the
    # curve is the one metrics.csv holds, every episode once.
    assert max(p[0] for p in before["eval_return"]) % 20 != 0
    got = shown(run_tb, with_time=False)
    assert got == want
    assert [p[0] for p in shown(run_tb)["wall_seconds"]] == list(range(0, 301, 5))
