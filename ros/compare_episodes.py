#!/usr/bin/python3
"""Compare two files of macdec episode lines (`macdec eval --trajectories` and the same policy and
seed played over ROS) and print one line: identical, or where they first differ.

    compare_episodes.py EXPECTED.jsonl GOT.jsonl     exit 0 if identical, 1 if not
"""

import json
import sys


def load(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def first_difference(expected, got):
    if len(expected) != len(got):
        return "%d episodes expected, %d played over ROS" % (len(expected), len(got))
    for e, g in zip(expected, got):
        k = e.get("episode")
        for key in ("return", "undiscounted_return", "steps"):
            if e.get(key) != g.get(key):
                return "episode %s: %s %r expected, %r over ROS" % (k, key, e.get(key), g.get(key))
        te, tg = e.get("trajectory", []), g.get("trajectory", [])
        for s, (a, b) in enumerate(zip(te, tg)):
            for key in ("executed", "reward", "mac_done", "done", "t"):
                if a.get(key) != b.get(key):
                    return "episode %s step %d: %s %r expected, %r over ROS" % (
                        k, s, key, a.get(key), b.get(key))
        if len(te) != len(tg):
            return "episode %s: %d steps expected, %d over ROS" % (k, len(te), len(tg))
        if e != g:
            return "episode %s: lines differ: %s vs %s" % (k, json.dumps(e), json.dumps(g))
    return None


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    expected, got = load(sys.argv[1]), load(sys.argv[2])
    diff = first_difference(expected, got)
    if diff is not None:
        print("ROS smoke: DIFFERENT: " + diff)
        sys.exit(1)
    if not expected:
        print("ROS smoke: DIFFERENT: no episodes were played")
        sys.exit(1)
    steps = sum(e["steps"] for e in expected)
    actions = sorted({a for e in expected for s in e["trajectory"] for a in s["executed"]})
    distinct = sorted({e["return"] for e in expected})
    returns = ", ".join("%.6g" % r for r in distinct[:5]) + (", ..." if len(distinct) > 5 else "")
    print("ROS smoke: identical: %d episode(s), %d steps, executed macro-actions and returns "
          "(%s) equal macdec eval's; macro-action indices used: %s" % (
              len(expected), steps, returns, actions))


if __name__ == "__main__":
    main()
