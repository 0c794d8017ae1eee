#!/usr/bin/python3
"""ROS 1 domain node: plays a policy's domain (Box Pushing or Warehouse) against the team's robot
nodes over ROS (macdec issue 14).

The environment is macdec's, not Python's: this node starts `macdec domain --policy DIR --robots
ADDR0,ADDR1,...` with one loopback TCP address per robot, served here. macdec runs the domain and
the driver loop of `macdec deploy` and sends each robot only its own macro-observation in the
robot protocol; this node turns each such message into ROS traffic with that robot's node and
the node's answer back into a protocol reply:

  info                        -> the robot node's latched `info` topic (macdec checks agent and
                                 manifest, exactly as `deploy` checks its robot processes)
  reset                       -> the robot node's `reset` service (std_srvs/Trigger)
  observe, macro-action done  -> publish on `macro_action_done`, wait for `macro_action` (Int32)
                                 and `macro_action_name` (String), reply with them
  observe, still running      -> publish on `macro_obs`, reply "continue"
  an ERROR on /diagnostics from that robot while waiting -> an error reply (macdec stops, naming it)

macdec's episode lines (the same as `macdec eval`/`deploy` print) go to stdout; the time from
publishing a macro-observation to receiving its macro-action is summarised on stderr.

Each robot's address is served only to the `macdec domain` process this node started: a
connection from any other process (another local user's included) is refused and closed with a
log line, and the listener keeps waiting for the expected one. Request lines are read up to
--max-line-bytes (default 65536; raise it for observations of more than a few thousand numbers).
The policy's policy.json (or manifest.json) is read only as a regular file of at most 1 MiB.

Usage: macdec_domain_node.py --policy DIR [--episodes K] [--seed S] [--trajectories]
       [--macdec PATH] [--namespace /macdec] [--timeout SECS] [--max-line-bytes N]
       [--check-diagnostics]
"""

import argparse
import json
import math
import os
import queue
import shutil
import socket
import statistics
import subprocess
import sys
import threading
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from std_msgs.msg import Float32MultiArray, Int32, String
from std_srvs.srv import Trigger

from macdec_io import DEFAULT_MAX_LINE_BYTES, LineChannel, LineTooLong, owns_connection, read_manifest


class RobotBridge:
    """One robot node seen through ROS, answering the robot protocol for macdec."""

    def __init__(self, agent, namespace, action_names, timeout):
        self.agent = agent
        self.ns = "%s/robot_%d" % (namespace.rstrip("/"), agent)
        self.action_names = action_names
        self.timeout = timeout
        self.events = queue.Queue()
        self.info = None
        self.info_ready = threading.Event()
        self.round_trips = []
        self.done_pub = rospy.Publisher(
            self.ns + "/macro_action_done", Float32MultiArray, queue_size=100
        )
        self.obs_pub = rospy.Publisher(self.ns + "/macro_obs", Float32MultiArray, queue_size=100)
        self.subs = [
            rospy.Subscriber(
                self.ns + "/macro_action",
                Int32,
                lambda m: self.events.put(("action", m.data)),
                queue_size=None,
                tcp_nodelay=True,
            ),
            rospy.Subscriber(
                self.ns + "/macro_action_name",
                String,
                lambda m: self.events.put(("name", m.data)),
                queue_size=None,
                tcp_nodelay=True,
            ),
        ]
        rospy.Subscriber(self.ns + "/info", String, self.on_info, queue_size=1)
        self.reset_srv = None

    def on_info(self, msg):
        self.info = msg.data
        self.info_ready.set()

    def on_diagnostic(self, status):
        if status.level != DiagnosticStatus.OK:
            self.events.put(("error", status.message))

    def wait_ready(self, deadline):
        """Block until the robot node's topics, service and info are connected, so no message
        published afterwards is lost to a connection still being set up."""
        rospy.wait_for_service(self.ns + "/reset", timeout=max(0.1, deadline - time.time()))
        self.reset_srv = rospy.ServiceProxy(self.ns + "/reset", Trigger, persistent=True)
        while time.time() < deadline and not rospy.is_shutdown():
            connected = (
                self.info_ready.is_set()
                and self.done_pub.get_num_connections() > 0
                and self.obs_pub.get_num_connections() > 0
                and all(s.get_num_connections() > 0 for s in self.subs)
            )
            if connected:
                return
            time.sleep(0.02)
        raise TimeoutError("robot %d (%s) did not connect in time" % (self.agent, self.ns))

    def drain(self):
        while True:
            try:
                self.events.get_nowait()
            except queue.Empty:
                return

    def decide(self, obs):
        """Publish a macro-observation with the macro-action done; the reply for macdec."""
        start = time.perf_counter()
        self.done_pub.publish(Float32MultiArray(data=obs))
        got = {}
        deadline = time.time() + self.timeout
        while "action" not in got or "name" not in got:
            left = deadline - time.time()
            if left <= 0:
                return {"error": "no macro-action from %s within %ss" % (self.ns, self.timeout)}
            try:
                kind, value = self.events.get(timeout=left)
            except queue.Empty:
                continue
            if kind == "error":
                return {"error": "%s reported: %s" % (self.ns, value)}
            got[kind] = value
        self.round_trips.append(time.perf_counter() - start)
        action, name = got["action"], got["name"]
        if not 0 <= action < len(self.action_names) or self.action_names[action] != name:
            return {"error": "%s sent macro-action %d named %r" % (self.ns, action, name)}
        return {"action": action, "name": name, "q": []}

    def handle(self, request):
        kind = request.get("type")
        if kind == "info":
            return json.loads(self.info)
        if kind == "reset":
            self.drain()
            answer = self.reset_srv()
            return {"ok": "reset"} if answer.success else {"error": answer.message}
        if kind == "observe" and request.get("macro_action_done"):
            return self.decide(request["obs"])
        if kind == "observe":
            self.obs_pub.publish(Float32MultiArray(data=request["obs"]))
            return {"ok": "continue"}
        return {"error": "the ROS bridge does not know request %r" % kind}

    def serve(self, listener, child, max_line_bytes):
        """Answer macdec's one connection for this robot, line by line. `child` is an Event whose
        `pid` is the `macdec domain` process: connections from any other process are refused."""
        while True:
            conn, peer = listener.accept()
            child.wait()
            if owns_connection(child.pid, conn):
                break
            rospy.logwarn(
                "ROS bridge for %s: refused a connection from %s:%d: not the macdec domain "
                "process this node started (pid %d)", self.ns, peer[0], peer[1], child.pid
            )
            conn.close()
        listener.close()
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        lines = LineChannel(conn.fileno(), max_line_bytes)
        with conn:
            while True:
                try:
                    line = lines.read_line()
                except LineTooLong:
                    reply = {
                        "error": "ROS bridge for %s: request line longer than %d bytes; start "
                        "the domain node with a larger --max-line-bytes" % (self.ns, max_line_bytes)
                    }
                    conn.sendall((json.dumps(reply, separators=(",", ":")) + "\n").encode())
                    return
                if line is None:
                    return
                if not line.strip():
                    continue
                try:
                    reply = self.handle(json.loads(line))
                except Exception as e:  # a bridge failure becomes macdec's named error
                    reply = {"error": "ROS bridge for %s: %s" % (self.ns, e)}
                conn.sendall((json.dumps(reply, separators=(",", ":")) + "\n").encode())


def check_diagnostics(bridge, obs_size):
    """Bad macro-observations (one value too many; a NaN) must each come back as an ERROR on
    /diagnostics naming the problem, with no macro-action, and the node must keep serving (the
    episodes that follow need it)."""
    bad = [
        ([0.0] * (obs_size + 1), "expects %d" % obs_size),
        ([float("nan")] + [0.0] * (obs_size - 1), "finite"),
    ]
    for obs, needle in bad:
        bridge.drain()
        bridge.done_pub.publish(Float32MultiArray(data=obs))
        try:
            kind, value = bridge.events.get(timeout=bridge.timeout)
        except queue.Empty:
            raise SystemExit("diagnostics check: %s did not answer a bad observation" % bridge.ns)
        if kind != "error" or needle not in value:
            raise SystemExit(
                "diagnostics check: %s answered a bad observation with %s %r" % (bridge.ns, kind, value)
            )
        print("diagnostics check: %s reported: %s" % (bridge.ns, value), file=sys.stderr)


def summary(seconds):
    ms = sorted(s * 1e3 for s in seconds)
    if not ms:
        return "no decisions"
    p90 = ms[min(len(ms) - 1, int(0.9 * len(ms)))]
    return "%d decisions, median %.2f ms, mean %.2f ms, p90 %.2f ms, max %.2f ms" % (
        len(ms),
        statistics.median(ms),
        statistics.fmean(ms),
        p90,
        ms[-1],
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", required=True)
    parser.add_argument("--episodes", type=int, default=1)
    parser.add_argument("--seed", type=int)
    parser.add_argument("--trajectories", action="store_true")
    parser.add_argument(
        "--macdec", default=os.environ.get("MACDEC") or shutil.which("macdec") or "macdec"
    )
    parser.add_argument("--namespace", default="/macdec", help="the robots' namespaces' parent")
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds per ROS answer")
    parser.add_argument(
        "--max-line-bytes",
        type=int,
        default=DEFAULT_MAX_LINE_BYTES,
        help="longest request line read from macdec domain",
    )
    parser.add_argument("--check-diagnostics", action="store_true")
    args = parser.parse_args(rospy.myargv()[1:])
    if not 0 < args.timeout <= 86400:
        parser.error("--timeout must be more than 0 and at most 86400 seconds")
    if args.max_line_bytes < 1:
        parser.error("--max-line-bytes must be at least 1")
    policy = os.path.abspath(args.policy)
    try:
        agents = read_manifest(policy)["agents"]
    except ValueError as e:
        raise SystemExit("macdec_domain_node: %s" % e)

    rospy.init_node("domain", anonymous=True)
    bridges = [
        RobotBridge(a["index"], args.namespace, a["action_names"], args.timeout) for a in agents
    ]
    by_hardware = {"robot_%d" % b.agent: b for b in bridges}

    def on_diagnostics(array):
        for status in array.status:
            bridge = by_hardware.get(status.hardware_id)
            if bridge is not None:
                bridge.on_diagnostic(status)

    diagnostics = rospy.Subscriber(
        "/diagnostics", DiagnosticArray, on_diagnostics, queue_size=None, tcp_nodelay=True
    )
    deadline = time.time() + 60
    try:
        for b in bridges:
            b.wait_ready(deadline)
    except (rospy.ROSException, TimeoutError) as e:
        raise SystemExit("macdec_domain_node: the team is not up: %s" % e)
    # Errors travel on /diagnostics: be connected to every robot node's publisher first.
    while diagnostics.get_num_connections() < len(bridges):
        if time.time() > deadline:
            raise SystemExit("the robot nodes' /diagnostics publishers did not connect in time")
        time.sleep(0.02)
    if args.check_diagnostics:
        check_diagnostics(bridges[0], agents[0]["obs_size"])

    # Set once macdec domain is started: each bridge serves only a connection from that process.
    started = threading.Event()
    addresses = []
    for b in bridges:
        listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        listener.bind(("127.0.0.1", 0))
        listener.listen(8)
        addresses.append("127.0.0.1:%d" % listener.getsockname()[1])
        threading.Thread(
            target=b.serve, args=(listener, started, args.max_line_bytes), daemon=True
        ).start()
    robots = ",".join(addresses)
    command = [args.macdec, "domain", "--policy", policy, "--robots", robots]
    command += ["--episodes", str(args.episodes)]
    # macdec waits for each reply a little longer than this node waits for a ROS answer, so a
    # silent robot node is reported by name (the bridge's error reply) rather than as a timeout.
    command += ["--timeout-secs", str(min(86400, math.ceil(args.timeout) + 10))]
    if args.seed is not None:
        command += ["--seed", str(args.seed)]
    if args.trajectories:
        command.append("--trajectories")
    child = subprocess.Popen(command, stdout=subprocess.PIPE, text=True)
    started.pid = child.pid
    started.set()
    for line in child.stdout:
        sys.stdout.write(line)
        sys.stdout.flush()
    code = child.wait()
    all_trips = [t for b in bridges for t in b.round_trips]
    print("ROS round trip (publish macro-observation -> macro-action received): %s"
          % summary(all_trips), file=sys.stderr)
    rospy.signal_shutdown("done")
    sys.exit(code)


if __name__ == "__main__":
    main()
