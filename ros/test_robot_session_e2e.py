"""A robot node's step count against macdec's own clock, without ROS (macdec issue 41).

`macdec domain` plays a policy's domain against one bridge per robot, as
ros/macdec_domain_node.py does; each bridge here drops the `"step"` macdec sends, as a ROS
message does, and asks its `macdec robot` child through `RobotSession`, which counts the step
back, as ros/macdec_robot_node.py does. Every observation's count must equal the step macdec
sent, and the episodes must equal `macdec deploy`'s, where macdec sends the step itself.

Needs a macdec binary and a policy that reads the time (an ACAC run's `policy/`), named by the
environment variables MACDEC and MACDEC_TIMED_POLICY; skipped without them.
`cargo test --release --test every_method_outputs` trains one and runs this file.
"""

import json
import os
import socket
import subprocess
import sys
import threading
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from macdec_io import LineChannel, PolicyProcess, RobotSession, read_manifest  # noqa: E402

EPISODES = "3"
SEED = "7"


class Bridge:
    """One robot's end of `macdec domain`'s connection, answered through a RobotSession."""

    def __init__(self, macdec, policy, agent):
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(1)
        self.address = "127.0.0.1:%d" % self.listener.getsockname()[1]
        command = [macdec, "robot", "--policy", policy, "--agent", str(agent)]
        self.session = RobotSession(PolicyProcess(command, 30))
        self.observations = 0
        self.mismatches = []
        self.failure = None
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def answer(self, request):
        kind = request["type"]
        if kind == "info":
            return self.session.info()
        if kind == "reset":
            return self.session.reset()
        # What ROS carries of an observation: the values and which topic, not the step.
        if request["step"] != self.session.step:
            self.mismatches.append((request["step"], self.session.step))
        self.observations += 1
        return self.session.observe(request["obs"], request["macro_action_done"])

    def serve(self):
        try:
            self.listener.settimeout(60)
            conn, _ = self.listener.accept()
            with conn:
                lines = LineChannel(conn.fileno(), 1 << 20)
                while True:
                    line = lines.read_line()
                    if line is None:
                        return
                    reply = self.answer(json.loads(line))
                    conn.sendall((json.dumps(reply) + "\n").encode())
        except Exception as e:  # reported by the test, not lost in the thread
            self.failure = e
        finally:
            self.listener.close()
            self.session.policy.stop()


class RobotSessionAgainstMacdec(unittest.TestCase):
    def test_counted_steps_are_macdecs_and_episodes_equal_deploys(self):
        macdec = os.environ.get("MACDEC")
        policy = os.environ.get("MACDEC_TIMED_POLICY")
        if not macdec or not policy:
            self.skipTest("set MACDEC and MACDEC_TIMED_POLICY (an ACAC run's policy/)")
        agents = read_manifest(policy)["agents"]
        bridges = [Bridge(macdec, policy, a["index"]) for a in agents]
        robots = ",".join(b.address for b in bridges)
        common = ["--policy", policy, "--episodes", EPISODES, "--seed", SEED, "--trajectories"]
        over_bridges = subprocess.run(
            [macdec, "domain", "--robots", robots] + common,
            capture_output=True,
            text=True,
            timeout=120,
        )
        for b in bridges:
            b.thread.join(timeout=30)
        self.assertEqual(over_bridges.returncode, 0, over_bridges.stderr)
        for agent, b in enumerate(bridges):
            self.assertIsNone(b.failure, "bridge of agent %d" % agent)
            self.assertEqual(b.mismatches, [], "agent %d: (macdec's step, counted)" % agent)
            # Every primitive step of every episode reached the robot, so the counts mean
            # something: more observations than episodes.
            self.assertGreater(b.observations, int(EPISODES), "agent %d" % agent)
        direct = subprocess.run(
            [macdec, "deploy"] + common, capture_output=True, text=True, timeout=120
        )
        self.assertEqual(direct.returncode, 0, direct.stderr)
        self.assertEqual(over_bridges.stdout.splitlines(), direct.stdout.splitlines())
        self.assertEqual(len(direct.stdout.splitlines()), int(EPISODES))


if __name__ == "__main__":
    unittest.main()
