#!/usr/bin/python3
"""Print the roslaunch XML that starts the whole team of a policy directory: one
macdec_robot_node.py per agent of its manifest, agent i in namespace <namespace>/robot_<i>.

    python3 ros/team_launch.py --policy DIR [--macdec PATH] | roslaunch -

(ros/ must be on ROS_PACKAGE_PATH: it is the package `macdec_ros`.) Each node respawns if it
exits, so a crash costs that robot its hidden state, never the team. --timeout-secs and
--max-line-bytes, when given, are passed to every node (see macdec_robot_node.py).
"""

import argparse
import os
import shutil
import sys
from xml.sax.saxutils import quoteattr

from macdec_io import read_manifest


def launch_xml(policy, macdec, namespace, agents, extra=""):
    lines = ["<launch>", "  <!-- macdec team of %s -->" % policy.replace("--", "- -")]
    for a in agents:
        i = a["index"]
        args = "--policy %s --agent %d --macdec %s%s" % (policy, i, macdec, extra)
        lines.append(
            '  <node pkg="macdec_ros" type="macdec_robot_node.py" name="policy" ns=%s args=%s'
            ' respawn="true" respawn_delay="1" output="log"/>'
            % (quoteattr("%s/robot_%d" % (namespace.rstrip("/"), i)), quoteattr(args))
        )
    lines.append("</launch>")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", required=True, help="policy directory (macdec export/import)")
    parser.add_argument(
        "--macdec",
        default=os.environ.get("MACDEC") or shutil.which("macdec") or "macdec",
        help="the macdec executable (default: $MACDEC, else macdec on PATH)",
    )
    parser.add_argument("--namespace", default="/macdec", help="the robots' namespaces' parent")
    parser.add_argument("--timeout-secs", type=float, help="each node's --timeout-secs")
    parser.add_argument("--max-line-bytes", type=int, help="each node's --max-line-bytes")
    args = parser.parse_args()
    if args.timeout_secs is not None and not 0 < args.timeout_secs <= 86400:
        parser.error("--timeout-secs must be more than 0 and at most 86400")
    if args.max_line_bytes is not None and args.max_line_bytes < 1:
        parser.error("--max-line-bytes must be at least 1")
    extra = ""
    if args.timeout_secs is not None:
        extra += " --timeout-secs %r" % args.timeout_secs
    if args.max_line_bytes is not None:
        extra += " --max-line-bytes %d" % args.max_line_bytes
    policy = os.path.abspath(args.policy)
    for path in (policy, os.path.abspath(args.macdec)):
        if any(c.isspace() for c in path):
            sys.exit("team_launch.py: paths with spaces cannot go into node args: %r" % path)
    # policy.json (or an older export's manifest.json) lists the agents' layouts under "agents";
    # read as macdec reads it: a regular file of at most 1 MiB.
    try:
        agents = read_manifest(policy)["agents"]
    except ValueError as e:
        sys.exit("team_launch.py: %s" % e)
    macdec = os.path.abspath(args.macdec) if os.sep in args.macdec else args.macdec
    sys.stdout.write(launch_xml(policy, macdec, args.namespace, agents, extra))


if __name__ == "__main__":
    main()
