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
  service     reset              std_srvs/Trigger            zero the LSTM state and the step count
              (new episode)
  published   /diagnostics       diagnostic_msgs/DiagnosticArray  OK when serving, ERROR for any
              refused message (wrong length, non-finite values), a reply not complete within
              --timeout-secs (the child is killed and restarted) or a restarted child; the node
              keeps running and its state is unchanged by a refused message

Policies that read the time (ACAC's actors) get the primitive step each observation was made at:
the node counts the observations the policy accepted since the last reset (`RobotSession` in
macdec_io.py), so the robot's side must publish one message per primitive step, on
`macro_action_done` or `macro_obs`, from the reset on.

Usage: macdec_robot_node.py --policy DIR --agent I [--macdec PATH] [--timeout-secs S]
       [--max-line-bytes N] [ROS remappings]

--timeout-secs (or the private parameter ~timeout_secs; default 30): writing one request to
`macdec robot` and reading its whole reply must take at most this long. --max-line-bytes (or
~max_line_bytes; default 65536): passed to `macdec robot --max-line-bytes`, the longest request
line it reads; raise it for observations of more than a few thousand numbers. Replies are read up
to 16 MiB.
"""

import argparse
import json
import os
import shutil

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from std_msgs.msg import Float32MultiArray, Int32, String
from std_srvs.srv import Trigger, TriggerResponse

from macdec_io import DEFAULT_MAX_LINE_BYTES, MAX_REPLY_BYTES, PolicyProcess, RobotSession


class RobotNode:
    def __init__(self, policy_dir, agent, macdec, timeout_secs, max_line_bytes):
        self.agent = agent
        self.name = "macdec robot %d" % agent
        command = [macdec, "robot", "--policy", policy_dir, "--agent", str(agent)]
        command += ["--max-line-bytes", str(max_line_bytes)]
        self.process = PolicyProcess(command, timeout_secs, MAX_REPLY_BYTES)
        self.policy = RobotSession(self.process)
        try:
            info = self.policy.info(restart=False)
        except RuntimeError as e:  # e.g. a bad policy directory: macdec said why on stderr
            rospy.logfatal("%s: cannot serve %s: %s", self.name, policy_dir, e)
            self.process.stop()
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
        if level == DiagnosticStatus.ERROR:
            rospy.logerr("%s: %s", self.name, message)
        elif level != DiagnosticStatus.OK:
            rospy.logwarn("%s: %s", self.name, message)

    def ask(self, call, what, shown):
        """The reply of `call()` (a RobotSession request), or None after reporting why there is
        none; `shown` is what the report quotes of the request."""
        try:
            reply = call()
        except RuntimeError as e:
            self.report(DiagnosticStatus.ERROR, "%s: %s" % (what, e))
            return None
        if "error" in reply:
            text = json.dumps(shown)[:500]
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
            lambda: self.policy.observe(obs, macro_action_done),
            what,
            {"obs": obs, "step": self.policy.step},
        )
        if reply is None or not macro_action_done:
            return
        # Index first, then its name: a consumer pairing the two sees them in this order.
        self.action_pub.publish(Int32(data=reply["action"]))
        self.name_pub.publish(String(data=reply["name"]))

    def on_reset(self, _request):
        reply = self.ask(self.policy.reset, "reset", {"type": "reset"})
        if reply is None:
            return TriggerResponse(success=False, message="reset failed; see /diagnostics")
        return TriggerResponse(success=True, message="hidden state and step count zeroed")

    def shutdown(self):
        self.process.stop()


def positive_seconds(text):
    """A timeout flag: seconds, more than 0 and at most a day."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError("timeout %r: expected seconds" % (text,))
    if not 0 < value <= 86400:
        raise argparse.ArgumentTypeError("timeout %r: must be more than 0 and at most 86400" % (text,))
    return value


def positive_int(text):
    """A byte-count flag: a whole number, at least 1."""
    try:
        value = int(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError("%r: expected a whole number of bytes" % (text,))
    if value < 1:
        raise argparse.ArgumentTypeError("%r: must be at least 1" % (text,))
    return value


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", required=True, help="policy directory (macdec export/import)")
    parser.add_argument("--agent", required=True, type=int, help="agent index, from 0")
    parser.add_argument(
        "--macdec",
        default=os.environ.get("MACDEC") or shutil.which("macdec") or "macdec",
        help="the macdec executable (default: $MACDEC, else macdec on PATH)",
    )
    parser.add_argument(
        "--timeout-secs",
        type=positive_seconds,
        help="longest wait for one reply of macdec robot (default: ~timeout_secs, else 30)",
    )
    parser.add_argument(
        "--max-line-bytes",
        type=positive_int,
        help="macdec robot's longest request line (default: ~max_line_bytes, else %d)"
        % DEFAULT_MAX_LINE_BYTES,
    )
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("policy_%d" % args.agent, disable_signals=False)
    try:
        timeout_secs = args.timeout_secs or positive_seconds(rospy.get_param("~timeout_secs", 30))
        max_line_bytes = args.max_line_bytes or positive_int(
            rospy.get_param("~max_line_bytes", DEFAULT_MAX_LINE_BYTES)
        )
    except argparse.ArgumentTypeError as e:
        rospy.logfatal("macdec robot %d: %s", args.agent, e)
        raise SystemExit(1)
    node = RobotNode(
        os.path.abspath(args.policy), args.agent, args.macdec, timeout_secs, max_line_bytes
    )
    rospy.on_shutdown(node.shutdown)
    rospy.spin()


if __name__ == "__main__":
    main()
