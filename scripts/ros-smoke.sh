#!/usr/bin/env bash
# End-to-end check of the ROS nodes (issue 14) against a real ROS 1 master on loopback.
#
#   scripts/ros-smoke.sh [POLICY_DIR ...]
#
# For each policy directory (default: a tiny Box Pushing 10x10 Our-1 run trained and exported
# here): start the team's robot nodes with roslaunch (ros/team_launch.py), play EPISODES episodes
# with seed SEED through ros/macdec_domain_node.py (the environment is macdec's, stepped by
# `macdec domain`; every observation and macro-action travels over ROS topics), run `macdec eval`
# of the same policy and seed, and print one line per policy: identical, or where it first
# differed. Exit status 0 only if every policy is identical.
#
# Needs Debian's ROS 1, the README's line (ros-core brings neither std_srvs nor diagnostic_msgs,
# and procps's pgrep only by chance): apt-get install ros-core python3-rospy python3-std-srvs
# python3-diagnostic-msgs procps. Environment: MACDEC (default target/release/macdec, built if
# missing), ROS_PORT (default 11311; must be free), EPISODES (3), SEED (0); EVAL_SEED (default
# SEED) seeds only the `macdec eval` side, so a test can show that a real difference is reported.
# Everything it starts (roscore, roslaunch and the nodes) is stopped when it exits.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
port=${ROS_PORT:-11311}
episodes=${EPISODES:-3}
seed=${SEED:-0}
eval_seed=${EVAL_SEED:-$seed}
macdec=${MACDEC:-$repo/target/release/macdec}
py=/usr/bin/python3

# What is missing, by the Debian package that brings it; all of it named in one message.
missing=()
for need in roscore:ros-core roslaunch:ros-core pgrep:procps setsid:util-linux "$py:python3"; do
    command -v "${need%:*}" >/dev/null || missing+=("${need##*:}")
done
if [ -x "$py" ]; then
    for need in rospy:python3-rospy std_msgs.msg:python3-std-msgs std_srvs.srv:python3-std-srvs \
        diagnostic_msgs.msg:python3-diagnostic-msgs rosgraph:python3-rosgraph roslaunch:python3-roslaunch; do
        "$py" -c "import ${need%:*}" 2>/dev/null || missing+=("${need##*:}")
    done
fi
if [ ${#missing[@]} -gt 0 ]; then
    echo "ros-smoke: missing: $(printf '%s\n' "${missing[@]}" | sort -u | paste -sd ' '); as root:" >&2
    echo "  apt-get install -y ros-core python3-rospy python3-std-srvs python3-diagnostic-msgs procps" >&2
    exit 2
fi
if [ ! -x "$macdec" ]; then
    (cd "$repo" && cargo build --release --quiet)
fi
macdec=$(cd "$(dirname "$macdec")" && pwd)/$(basename "$macdec")
if "$py" -c "import socket,sys; s=socket.socket(); sys.exit(s.connect_ex(('127.0.0.1', $port)) != 0)"; then
    echo "ros-smoke: 127.0.0.1:$port is in use (another ROS master?); set ROS_PORT" >&2
    exit 2
fi

work=$(mktemp -d /tmp/macdec-ros-smoke.XXXXXX)
export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1 ROS_HOME=$work/ros_home
export ROS_LOG_DIR=$work/ros_home/log ROS_PACKAGE_PATH=$repo/ros PYTHONUNBUFFERED=1
unset ROS_HOSTNAME
core_pid="" team_pid="" fg_pid=""

# Every process below $1 (roscore and roslaunch put their children in new process groups).
descendants() {
    local child
    for child in $(pgrep -P "$1" 2>/dev/null); do
        echo "$child"
        descendants "$child"
    done
}
# Stop a process this script started and everything it started: SIGINT to its process group
# (roslaunch and roscore then stop their nodes), SIGKILL after 20 s, then any descendant left.
stop_tree() {
    local pid=$1 i rest
    [ -n "$pid" ] || return 0
    rest=$(descendants "$pid")
    kill -INT -- "-$pid" 2>/dev/null || kill -INT "$pid" 2>/dev/null || true
    for i in $(seq 200); do
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
    done
    kill -KILL -- "-$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    for i in $rest; do kill -TERM "$i" 2>/dev/null || true; done
    sleep 0.2
    for i in $rest; do kill -KILL "$i" 2>/dev/null || true; done
}
# Run a command in its own process group and wait for it, so a signal to this script stops it
# at once (bash runs traps only between commands, and `wait` is interruptible).
run() {
    setsid "$@" &
    fg_pid=$!
    local code=0
    wait "$fg_pid" || code=$?
    fg_pid=""
    return $code
}
cleanup() {
    stop_tree "$fg_pid"
    stop_tree "$team_pid"
    stop_tree "$core_pid"
    rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

if [ $# -eq 0 ]; then
    echo "ros-smoke: training a tiny Box Pushing run to get a policy" >&2
    run "$macdec" train --set total_epi=200 --seeds 0..1 --out "$work/run" --no-plot --quiet >&2
    run "$macdec" export --run "$work/run/quickstart_bp10/our1/seed-0" --out "$work/policy-bp10" >&2
    set -- "$work/policy-bp10"
fi

setsid roscore -p "$port" >"$work/roscore.log" 2>&1 &
core_pid=$!
for i in $(seq 300); do
    "$py" -c 'import rosgraph,sys; sys.exit(not rosgraph.is_master_online())' 2>/dev/null && break
    kill -0 "$core_pid" 2>/dev/null || { cat "$work/roscore.log" >&2; exit 1; }
    sleep 0.1
done

status=0
for policy in "$@"; do
    policy=$(cd "$policy" && pwd)
    "$py" "$repo/ros/team_launch.py" --policy "$policy" --macdec "$macdec" >"$work/team.launch"
    setsid roslaunch --no-summary "$work/team.launch" >"$work/roslaunch.log" 2>&1 &
    team_pid=$!
    run "$macdec" eval --policy "$policy" --episodes "$episodes" --seed "$eval_seed" --trajectories \
        >"$work/eval.jsonl" 2>/dev/null
    if ! run "$py" "$repo/ros/macdec_domain_node.py" --policy "$policy" --episodes "$episodes" \
        --seed "$seed" --trajectories --macdec "$macdec" --check-diagnostics \
        >"$work/ros.jsonl" 2>"$work/domain.log"; then
        cat "$work/domain.log" >&2
        echo "ros-smoke: $policy: the domain node failed; the end of the roslaunch log follows" >&2
        tail -20 "$work/roslaunch.log" >&2
        status=1
    else
        grep -E '^(diagnostics check|ROS round trip)' "$work/domain.log" | sed "s|^|ros-smoke: |" >&2
        "$py" "$repo/ros/compare_episodes.py" "$work/eval.jsonl" "$work/ros.jsonl" \
            | sed "s|^ROS smoke: |ROS smoke ($(basename "$policy")): |" || status=1
    fi
    stop_tree "$team_pid"
    team_pid=""
done
exit $status
