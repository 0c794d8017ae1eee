#!/usr/bin/python3
"""ROS 1 node running one robot's decentralized macro-action policy (macdec issue 14).

The node owns a `macdec robot --policy DIR --agent I` child process and talks to it over its
documented JSON-lines protocol on stdin/stdout (README "Exporting and running a policy on
robots"), so the Q-net, its LSTM state, the greedy choice and every input check are macdec's own
code; this file only translates ROS messages to protocol lines and back.

Graph resources, relative to the node's namespace (the team launch uses /macdec/robot_<i>):

  subscribed  macro_action_done  std_msgs/Float32MultiArray  the robot's macro-observation at the
              moment its running macro-action finished (and the first one of an episode): the
              policy reads it, advances its LSTM state and a new macro-action is published
  subscribed  macro_obs          std_msgs/Float32MultiArray  a macro-observation while the running
              macro-action continues: checked, the LSTM state is untouched, nothing is published
  published   macro_action       std_msgs/Int32              index of the chosen macro-action
  published   macro_action_name  std_msgs/String             its name (published right after)
  published   info               std_msgs/String (latched)   `macdec robot`'s info reply: agent
              and the policy's manifest
  service     reset              std_srvs/Trigger            zero the LSTM state (new episode)
  published   /diagnostics       diagnostic_msgs/DiagnosticArray  OK when serving, ERROR for any
              refused message (wrong length, non-finite values) or a restarted child; the node
              keeps running and its state is unchanged by a refused message

Usage: macdec_robot_node.py --policy DIR --agent I [--macdec PATH] [ROS remappings]
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import threading

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from std_msgs.msg import Float32MultiArray, Int32, String
from std_srvs.srv import Trigger, TriggerResponse


class PolicyProcess:
    """`macdec robot` over stdin/stdout: one request line out, one reply line back, under a lock
    (rospy runs each subscription's callbacks on its own thread)."""

    def __init__(self, command):
        self.command = command
        self.lock = threading.Lock()
        self.child = None
        self.start()

    def start(self):
        self.child = subprocess.Popen(
            self.command,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=sys.stderr,
            text=True,
            bufsize=1,
        )

    def request(self, message, restart=True):
        """The reply (a dict) to `message` (a dict). If the child is gone a RuntimeError says so,
        and with `restart` the child is started again (its hidden state is then zero)."""
        line = json.dumps(message, allow_nan=True) + "\n"
        with self.lock:
            try:
                self.child.stdin.write(line)
                self.child.stdin.flush()
                reply = self.child.stdout.readline()
            except (BrokenPipeError, OSError, ValueError):
                reply = ""
            if not reply:
                self.stop()
                code = self.child.returncode
                if not restart:
                    raise RuntimeError("macdec robot exited (status %s)" % code)
                self.start()
                raise RuntimeError(
                    "macdec robot exited (status %s); restarted it, its hidden state is zero" % code
                )
        try:
            return json.loads(reply)
        except ValueError:
            raise RuntimeError("macdec robot sent an unreadable reply: %r" % reply[:200])

    def stop(self):
        if self.child is None:
            return
        try:
            self.child.stdin.close()
        except OSError:
            pass
        try:
            self.child.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.child.kill()
            self.child.wait()


class RobotNode:
    def __init__(self, policy_dir, agent, macdec):
        self.agent = agent
        self.name = "macdec robot %d" % agent
        self.policy = PolicyProcess([macdec, "robot", "--policy", policy_dir, "--agent", str(agent)])
        try:
            info = self.policy.request({"type": "info"}, restart=False)
        except RuntimeError as e:  # e.g. a bad policy directory: macdec said why on stderr
            rospy.logfatal("%s: cannot serve %s: %s", self.name, policy_dir, e)
            self.policy.stop()
            raise SystemExit(1)
        if "error" in info:
            rospy.logfatal("%s: macdec robot refused info: %s", self.name, info["error"])
            raise SystemExit(1)

        self.diagnostics = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=100)
        self.action_pub = rospy.Publisher("macro_action", Int32, queue_size=100)
        self.name_pub = rospy.Publisher("macro_action_name", String, queue_size=100)
        self.info_pub = rospy.Publisher("info", String, queue_size=1, latch=True)
        self.info_pub.publish(String(data=json.dumps(info, separators=(",", ":"))))
        rospy.Service("reset", Trigger, self.on_reset)
        rospy.Subscriber(
            "macro_action_done",
            Float32MultiArray,
            self.on_observation,
            callback_args=True,
            queue_size=None,
            tcp_nodelay=True,
        )
        rospy.Subscriber(
            "macro_obs",
            Float32MultiArray,
            self.on_observation,
            callback_args=False,
            queue_size=None,
            tcp_nodelay=True,
        )
        self.report(
            DiagnosticStatus.OK,
            "serving agent %d of %s" % (agent, policy_dir),
            [KeyValue(key="policy", value=policy_dir)],
        )

    def report(self, level, message, values=()):
        status = DiagnosticStatus(
            level=level,
            name=self.name,
            message=message,
            hardware_id="robot_%d" % self.agent,
            values=list(values),
        )
        array = DiagnosticArray(status=[status])
        array.header.stamp = rospy.Time.now()
        self.diagnostics.publish(array)
        if level != DiagnosticStatus.OK:
            rospy.logwarn("%s: %s", self.name, message)

    def ask(self, message, what):
        """The reply to `message`, or None after reporting why there is none."""
        try:
            reply = self.policy.request(message)
        except RuntimeError as e:
            self.report(DiagnosticStatus.ERROR, "%s: %s" % (what, e))
            return None
        if "error" in reply:
            text = json.dumps(message)[:500]
            self.report(
                DiagnosticStatus.ERROR,
                "%s refused: %s" % (what, reply["error"]),
                [KeyValue(key="request", value=text)],
            )
            return None
        return reply

    def on_observation(self, msg, macro_action_done):
        # Float32MultiArray values arrive as the f32 they were sent as; Python floats hold them
        # exactly, and macdec reads them back to the same f32.
        obs = [float(v) for v in msg.data]
        what = "macro_action_done" if macro_action_done else "macro_obs"
        reply = self.ask(
            {"type": "observe", "obs": obs, "macro_action_done": macro_action_done}, what
        )
        if reply is None or not macro_action_done:
            return
        # Index first, then its name: a consumer pairing the two sees them in this order.
        self.action_pub.publish(Int32(data=reply["action"]))
        self.name_pub.publish(String(data=reply["name"]))

    def on_reset(self, _request):
        reply = self.ask({"type": "reset"}, "reset")
        if reply is None:
            return TriggerResponse(success=False, message="reset failed; see /diagnostics")
        return TriggerResponse(success=True, message="hidden state zeroed")

    def shutdown(self):
        self.policy.stop()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", required=True, help="policy directory (macdec export/import)")
    parser.add_argument("--agent", required=True, type=int, help="agent index, from 0")
    parser.add_argument(
        "--macdec",
        default=os.environ.get("MACDEC") or shutil.which("macdec") or "macdec",
        help="the macdec executable (default: $MACDEC, else macdec on PATH)",
    )
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("policy_%d" % args.agent, disable_signals=False)
    node = RobotNode(os.path.abspath(args.policy), args.agent, args.macdec)
    rospy.on_shutdown(node.shutdown)
    rospy.spin()


if __name__ == "__main__":
    main()
