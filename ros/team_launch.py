#!/usr/bin/python3
"""Print the roslaunch XML that starts the whole team of a policy directory: one
macdec_robot_node.py per agent of its manifest, agent i in namespace <namespace>/robot_<i>.

    python3 ros/team_launch.py --policy DIR [--macdec PATH] | roslaunch -

(ros/ must be on ROS_PACKAGE_PATH: it is the package `macdec_ros`.) Each node respawns if it
exits, so a crash costs that robot its hidden state, never the team.
"""

import argparse
import json
import os
import shutil
import sys
from xml.sax.saxutils import quoteattr


def launch_xml(policy, macdec, namespace, agents):
    lines = ["<launch>", "  <!-- macdec team of %s -->" % policy.replace("--", "- -")]
    for a in agents:
        i = a["index"]
        args = "--policy %s --agent %d --macdec %s" % (policy, i, macdec)
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
    args = parser.parse_args()
    policy = os.path.abspath(args.policy)
    for path in (policy, os.path.abspath(args.macdec)):
        if any(c.isspace() for c in path):
            sys.exit("team_launch.py: paths with spaces cannot go into node args: %r" % path)
    # policy.json since format_version 2; manifest.json in exports written before. Both list
    # the agents' layouts under "agents".
    name = "policy.json" if os.path.exists(os.path.join(policy, "policy.json")) else "manifest.json"
    try:
        with open(os.path.join(policy, name)) as f:
            agents = json.load(f)["agents"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit("team_launch.py: reading %s/%s: %s" % (policy, name, e))
    macdec = os.path.abspath(args.macdec) if os.sep in args.macdec else args.macdec
    sys.stdout.write(launch_xml(policy, macdec, args.namespace, agents))


if __name__ == "__main__":
    main()
