"""Tests of ros/macdec_io.py, the ROS nodes' deadlines and bounds (macdec issue 29 class 7).
No ROS needed:

    python3 -m unittest discover -s ros -p 'test_*.py'

(`cargo test --release --test deadlines` runs them too when python3 is on PATH.)
"""

import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from macdec_io import (  # noqa: E402
    LineChannel,
    LineTimeout,
    LineTooLong,
    PolicyProcess,
    RobotSession,
    owns_connection,
    read_manifest,
)

# A stand-in for `macdec robot`: answers {"n": k} to its k-th request; to a request holding
# "hang" it says nothing, to one holding "trickle" it sends spaces forever, never a newline.
FAKE_ROBOT = r"""
import sys, time
n = 0
for line in sys.stdin:
    n += 1
    if "hang" in line:
        time.sleep(3600)
    if "trickle" in line:
        while True:
            sys.stdout.write(" "); sys.stdout.flush(); time.sleep(0.05)
    sys.stdout.write('{"n": %d}\n' % n); sys.stdout.flush()
"""


# A stand-in for `macdec robot` that echoes each observation's "step" and refuses one holding
# a NaN.
ECHO_ROBOT = r"""
import json, math, sys
for line in sys.stdin:
    m = json.loads(line)
    if m["type"] == "observe" and any(math.isnan(v) for v in m["obs"]):
        reply = {"error": "obs: values must be finite"}
    elif m["type"] == "observe":
        reply = {"step": m.get("step"), "done": m["macro_action_done"]}
    else:
        reply = {"ok": m["type"]}
    sys.stdout.write(json.dumps(reply) + "\n"); sys.stdout.flush()
"""


class LineChannelTest(unittest.TestCase):
    def pipe(self):
        """(read fd, write file): the write end is a file object, so closing it twice is safe."""
        r, w = os.pipe()
        self.addCleanup(os.close, r)
        writer = os.fdopen(w, "wb", buffering=0)
        self.addCleanup(writer.close)
        return r, writer.fileno(), writer

    def test_lines_crlf_and_end_of_input(self):
        r, w, writer = self.pipe()
        os.write(w, b"ab\r\n\ncd\ntail")
        writer.close()
        lines = LineChannel(r, 8)
        self.assertEqual([lines.read_line() for _ in range(4)], [b"ab", b"", b"cd", None])

    def test_a_trickled_line_fails_at_its_deadline(self):
        r, w, _ = self.pipe()
        stop = threading.Event()

        def trickle():
            while not stop.is_set():
                os.write(w, b" ")
                time.sleep(0.05)

        thread = threading.Thread(target=trickle)
        thread.start()
        self.addCleanup(thread.join)
        self.addCleanup(stop.set)
        t0 = time.monotonic()
        with self.assertRaises(LineTimeout):
            LineChannel(r, 1 << 20).read_line(time.monotonic() + 0.3)
        took = time.monotonic() - t0
        self.assertTrue(0.25 <= took < 1.0, "failed after %.2f s, the deadline was 0.3 s" % took)

    def test_a_line_over_the_limit_is_refused_before_its_newline(self):
        r, w, _ = self.pipe()
        os.write(w, b"x" * 100)
        with self.assertRaises(LineTooLong):
            LineChannel(r, 10).read_line(time.monotonic() + 5)
        os.write(w, b"\n")
        r2, w2, _ = self.pipe()
        os.write(w2, b"12345\n123456\n")
        lines = LineChannel(r2, 5)
        self.assertEqual(lines.read_line(), b"12345")
        with self.assertRaises(LineTooLong):
            lines.read_line()


class PolicyProcessTest(unittest.TestCase):
    def process(self, timeout):
        p = PolicyProcess([sys.executable, "-c", FAKE_ROBOT], timeout)
        self.addCleanup(p.stop, True)
        return p

    def test_a_silent_child_is_reported_killed_and_restarted(self):
        p = self.process(0.5)
        self.assertEqual(p.request({"type": "a"}), {"n": 1})
        first = p.child
        t0 = time.monotonic()
        with self.assertRaises(RuntimeError) as e:
            p.request({"type": "hang"})
        took = time.monotonic() - t0
        self.assertIn("gave no complete reply within 0.5 s; restarted it", str(e.exception))
        self.assertTrue(took < 2.0, "failed after %.2f s" % took)
        self.assertIsNotNone(first.poll(), "the hung child was left running")
        # A fresh child: its count starts again, so no late reply is taken for a new request.
        self.assertEqual(p.request({"type": "b"}), {"n": 1})

    def test_a_trickled_reply_fails_at_the_deadline(self):
        p = self.process(0.5)
        t0 = time.monotonic()
        with self.assertRaises(RuntimeError) as e:
            p.request({"type": "trickle"}, restart=False)
        self.assertIn("gave no complete reply within 0.5 s", str(e.exception))
        self.assertTrue(time.monotonic() - t0 < 2.0)

    def test_a_child_that_exits_is_named_with_its_status(self):
        p = PolicyProcess([sys.executable, "-c", "import sys; sys.exit(3)"], 5)
        self.addCleanup(p.stop, True)
        with self.assertRaises(RuntimeError) as e:
            p.request({"type": "info"}, restart=False)
        self.assertIn("exited (status 3)", str(e.exception))


class ReadManifestTest(unittest.TestCase):
    def setUp(self):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        self.dir = tmp.name
        self.path = os.path.join(self.dir, "policy.json")

    def test_a_manifest_is_read(self):
        with open(self.path, "w") as f:
            json.dump({"agents": [{"index": 0}]}, f)
        self.assertEqual(read_manifest(self.dir)["agents"], [{"index": 0}])

    def test_older_exports_manifest_json_is_read(self):
        with open(os.path.join(self.dir, "manifest.json"), "w") as f:
            json.dump({"agents": []}, f)
        self.assertEqual(read_manifest(self.dir)["agents"], [])

    def test_a_fifo_is_refused_without_blocking(self):
        os.mkfifo(self.path)
        t0 = time.monotonic()
        with self.assertRaisesRegex(ValueError, "not a regular file"):
            read_manifest(self.dir)
        self.assertLess(time.monotonic() - t0, 1.0)

    def test_a_link_and_a_directory_are_refused(self):
        target = os.path.join(self.dir, "elsewhere.json")
        with open(target, "w") as f:
            json.dump({"agents": []}, f)
        os.symlink(target, self.path)
        with self.assertRaisesRegex(ValueError, "policy.json"):
            read_manifest(self.dir)
        os.remove(self.path)
        os.mkdir(self.path)
        with self.assertRaisesRegex(ValueError, "not a regular file"):
            read_manifest(self.dir)

    def test_a_file_over_the_bound_is_refused_before_parsing(self):
        with open(self.path, "w") as f:
            f.write('{"agents": [], "pad": "%s"}' % ("x" * 2000))
        with self.assertRaisesRegex(ValueError, "more than 1000"):
            read_manifest(self.dir, max_bytes=1000)

    def test_json_without_agents_is_refused(self):
        with open(self.path, "w") as f:
            f.write('{"agent": []}')
        with self.assertRaisesRegex(ValueError, "agents list"):
            read_manifest(self.dir)


class OwnsConnectionTest(unittest.TestCase):
    @unittest.skipUnless(os.path.exists("/proc/net/tcp"), "needs Linux /proc")
    def test_only_the_connecting_process_and_its_parents_own_the_connection(self):
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)
        self.addCleanup(listener.close)
        port = listener.getsockname()[1]
        connect = (
            "import socket,sys; s=socket.create_connection(('127.0.0.1',%d)); sys.stdin.read()"
            % port
        )
        # A wrapper that starts the connecting process as its child (does not exec it).
        wrapper = "import subprocess,sys; subprocess.run([sys.executable, '-c', %r])" % connect
        child = subprocess.Popen([sys.executable, "-c", wrapper], stdin=subprocess.PIPE)
        self.addCleanup(child.wait)
        self.addCleanup(child.stdin.close)
        from_child, _ = listener.accept()
        self.addCleanup(from_child.close)
        from_us = socket.create_connection(("127.0.0.1", port))
        self.addCleanup(from_us.close)
        accepted_us, _ = listener.accept()
        self.addCleanup(accepted_us.close)
        self.assertTrue(owns_connection(child.pid, from_child))
        self.assertFalse(owns_connection(child.pid, accepted_us))
        self.assertTrue(owns_connection(os.getpid(), accepted_us))


class RobotSessionTest(unittest.TestCase):
    """The step a robot node sends is the count of accepted observations since the last reset
    (the end-to-end check against `macdec domain` is test_robot_session_e2e.py)."""

    def session(self):
        p = PolicyProcess([sys.executable, "-c", ECHO_ROBOT], 5)
        self.addCleanup(p.stop, True)
        return RobotSession(p)

    def test_steps_count_accepted_observations_from_each_reset(self):
        s = self.session()
        sent = [s.observe([0.0], done)["step"] for done in (True, False, False, True)]
        self.assertEqual(sent, [0, 1, 2, 3])
        # A refused observation is not a step of the policy's episode.
        self.assertIn("error", s.observe([float("nan")], True))
        self.assertEqual(s.observe([0.0], False)["step"], 4)
        self.assertEqual(s.reset(), {"ok": "reset"})
        self.assertEqual(s.observe([1.0], True), {"step": 0, "done": True})
        self.assertEqual(s.info(), {"ok": "info"})
        self.assertEqual(s.observe([1.0], False)["step"], 1)


if __name__ == "__main__":
    unittest.main()
