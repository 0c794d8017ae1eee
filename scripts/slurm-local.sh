#!/usr/bin/env bash
# A real scheduler test for `macdec slurm` (issue 15): stand up a single-node Slurm cluster on
# loopback from Debian's packages, submit the job array `macdec slurm` writes for a tiny
# experiment (2 methods x 2 seeds), wait for every array task, plot the union, check every run,
# then stop every daemon this script started and delete its state.
#
#   scripts/slurm-local.sh          # as root on Debian/Ubuntu; the last line says OK or FAILED
#
# MACDEC names the binary (default target/release/macdec, built by `cargo build --release`).
# SLURM_LOCAL_TIMEOUT is how long to wait for the array, in seconds (default 900).
#
# The cluster lives in a fresh `mktemp -d` directory: its own munge key, munged socket, slurm.conf
# (the machine's real CPU count and memory, from `slurmd -C`), state, spool and logs, and two free
# TCP ports bound to 127.0.0.1 only. Nothing under /etc is changed (apt-get installs
# slurm-wlm and munge if they are missing), so the script can run again at once, even
# while another copy runs. The experiment's paths contain a space, so quoting is exercised for real.
set -euo pipefail
cd "$(dirname "$0")/.."

MACDEC=${MACDEC:-target/release/macdec}
TIMEOUT=${SLURM_LOCAL_TIMEOUT:-900}
STARTED=$(date +%s)
STEP="starting"
TMP=""
JOBS=""     # ",id,id": jobs we submitted, cancelled on exit
PIDS=()      # daemons we started, in start order
NAMES=()

say() { echo "slurm-local: $*"; }

# Stop what we started (newest first), cancel our jobs, delete our state, print the verdict.
cleanup() {
    local rc=$? verdict
    set +e
    if [[ -n "$JOBS" ]] && kill -0 "${PIDS[1]}" 2>/dev/null; then
        timeout 10 scancel "${JOBS#,}" 2>/dev/null
        for _ in $(seq 30); do
            [[ -z "$(timeout 10 squeue -h -j "${JOBS#,}" -o %i 2>/dev/null)" ]] && break
            sleep 1
        done
    fi
    for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
        stop_pid "${PIDS[i]}" "${NAMES[i]}" || { rc=1; STEP="stopping ${NAMES[i]}"; }
    done
    if [[ -n "$TMP" ]]; then
        # Any process still working inside our directory (a job step) is ours: end it by id.
        for p in $(stray_pids); do
            kill -9 "$p" 2>/dev/null
        done
        if [[ -n "$(stray_pids)" ]]; then
            rc=1
            STEP="processes still running in $TMP"
        fi
        if [[ $rc -ne 0 && -n "${KEEP_LOGS_ON_FAILURE:-}" ]]; then
            say "logs kept in $TMP"
        else
            [[ $rc -ne 0 ]] && show_logs
            rm -rf "$TMP"
        fi
    fi
    verdict="$(($(date +%s) - STARTED)) s"
    if [[ $rc -eq 0 ]]; then
        say "OK: ${SUMMARY:-done} ($verdict)"
    else
        say "FAILED: $STEP ($verdict)"
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'STEP="interrupted while $STEP"; exit 130' INT TERM

stop_pid() {
    local pid=$1 name=$2
    kill -0 "$pid" 2>/dev/null || return 0
    kill "$pid" 2>/dev/null
    for _ in $(seq 50); do
        kill -0 "$pid" 2>/dev/null || { wait "$pid" 2>/dev/null; return 0; }
        sleep 0.2
    done
    say "$name (pid $pid) ignored SIGTERM; killing it"
    kill -9 "$pid" 2>/dev/null
    sleep 0.5
    ! kill -0 "$pid" 2>/dev/null
}

# Processes (other than this shell) whose working directory is inside $TMP.
stray_pids() {
    local p cwd
    for p in /proc/[0-9]*; do
        cwd=$(readlink "$p/cwd" 2>/dev/null) || continue
        [[ "$cwd" == "$TMP" || "$cwd" == "$TMP"/* ]] || continue
        [[ "${p#/proc/}" == "$$" || "${p#/proc/}" == "$BASHPID" ]] && continue
        echo "${p#/proc/}"
    done
}

show_logs() {
    local f
    for f in "$TMP"/state/*.log "$TMP"/job/slurm-*.out; do
        [[ -f "$f" ]] || continue
        echo "----- ${f#"$TMP"/} (last 15 lines)"
        tail -n 15 "$f"
    done
}

# A TCP port nothing listens on (checked again at bind time by the daemons themselves).
free_port() {
    local port
    for _ in $(seq 100); do
        port=$((20000 + RANDOM % 30000))
        if ! ss -ltnH "sport = :$port" | grep -q . && [[ " ${USED_PORTS:-} " != *" $port "* ]]; then
            USED_PORTS="${USED_PORTS:-} $port"
            echo "$port"
            return 0
        fi
    done
    return 1
}

# Start a daemon in its foreground mode, in the background of this shell and in a session of its
# own, so a Ctrl-C reaches this script (which then cancels the jobs and stops the daemons in
# order) and not the daemons.
start() {
    local name=$1
    shift
    setsid "$@" >"$TMP/state/$name.stdout" 2>&1 &
    PIDS+=("$!")
    NAMES+=("$name")
    say "started $name (pid $!)"
}

# Slurm holds a requeued job back (BeginTime about two minutes on); once it is pending again
# (a running one must first be killed), make it eligible at once.
release() {
    for _ in $(seq 120); do
        if [[ $(squeue -h -j "$1" -o %T 2>/dev/null) == PENDING ]]; then
            scontrol update JobId="$1" StartTime=now
            return 0
        fi
        sleep 0.25
    done
    return 1
}

# Wait until "$@" succeeds, or fail the step after $1 seconds.
wait_for() {
    local seconds=$1
    shift
    for _ in $(seq $((seconds * 4))); do
        "$@" >/dev/null 2>&1 && return 0
        for ((i = 0; i < ${#PIDS[@]}; i++)); do
            kill -0 "${PIDS[i]}" 2>/dev/null || { STEP="$STEP: ${NAMES[i]} exited"; return 1; }
        done
        sleep 0.25
    done
    STEP="$STEP: timed out after $seconds s"
    return 1
}

STEP="this script must run as root (it starts slurmd and installs packages)"
[[ $(id -u) -eq 0 ]]
STEP="no macdec binary at $MACDEC (cargo build --release, or set MACDEC)"
[[ -x "$MACDEC" ]]
MACDEC=$(realpath "$MACDEC")

STEP="installing slurm-wlm and munge"
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
    ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    say "installing slurm-wlm and munge with apt-get"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

STEP="creating the cluster directory"
TMP=$(mktemp -d /tmp/macdec-slurm-local.XXXXXX)
mkdir -p "$TMP/state/ctld" "$TMP/state/spool" "$TMP/munge" "$TMP/job" "$TMP/my runs"
chmod 700 "$TMP/munge"
STATE="$TMP/state"
say "cluster state in $TMP (removed on exit)"
HOST=$(hostname -s)

STEP="starting munged"
if command -v mungekey >/dev/null; then
    mungekey --create --keyfile="$TMP/munge/munge.key"
else
    dd if=/dev/urandom of="$TMP/munge/munge.key" bs=1024 count=1 status=none
fi
chmod 400 "$TMP/munge/munge.key"
SOCKET="$TMP/munge/munge.socket"
start munged munged --foreground --force --socket="$SOCKET" --key-file="$TMP/munge/munge.key" \
    --pid-file="$TMP/munge/munged.pid" --log-file="$STATE/munged.log" \
    --seed-file="$TMP/munge/munged.seed"
wait_for 20 bash -c "munge -n -S '$SOCKET' | unmunge -S '$SOCKET'"

STEP="writing slurm.conf"
CTLD_PORT=$(free_port)
SLURMD_PORT=$(free_port)
# The machine's real resources, as slurmd itself measures them (CPUs, sockets, cores, memory).
NODE=$(slurmd -C | head -n 1 | sed -e "s/^NodeName=[^ ]* //")
export SLURM_CONF="$STATE/slurm.conf"
cat >"$SLURM_CONF" <<EOF
ClusterName=macdeclocal
SlurmctldHost=$HOST(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
CommunicationParameters=NoInAddrAny,NoCtldInAddrAny
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SOCKET
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/spool
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$STATE/jobcomp.log
MinJobAge=600
NodeName=$HOST NodeAddr=127.0.0.1 NodeHostname=$HOST $NODE State=UNKNOWN
PartitionName=local Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF

STEP="starting slurmctld"
start slurmctld slurmctld -D -i -f "$SLURM_CONF"
wait_for 30 scontrol ping
STEP="starting slurmd"
start slurmd slurmd -D -f "$SLURM_CONF"
node_idle() { sinfo -h -n "$HOST" -o %T | grep -qx idle; }
wait_for 60 node_idle

STEP="checking that the daemons listen on loopback only"
LISTEN=$(ss -ltnH | awk -v a=":$CTLD_PORT" -v b=":$SLURMD_PORT" '$4 ~ a"$" || $4 ~ b"$" {print $4}')
# (Each check is one command on its own line or an explicit `if`: `set -e` ignores a failure
# inside `a && b` or after `!`.)
if [[ $(grep -c . <<<"$LISTEN") -ne 2 ]] || grep -qv '^127\.0\.0\.1:' <<<"$LISTEN"; then
    STEP="$STEP: $(tr '\n' ' ' <<<"$LISTEN")"
    false
fi
say "cluster up: node $HOST ($NODE); listening on" $LISTEN

# The experiment lists 3 methods x 3 seeds; the command line selects 2 x 2 and lengthens the
# runs from 20 to 40 episodes, so the tasks only train the right runs if `macdec slurm` passed
# the selection through to them.
STEP="writing the job array with macdec slurm"
RUNS="$TMP/my runs"
cat >"$RUNS/tiny slurm.toml" <<'EOF'
name = "slurm_local"
methods = ["dec-hddrqn", "cen-ddrqn", "our1"]
seeds = "0..3"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 20
batch_size = 8
replay_buffer_size = 500
eval_freq = 5
EOF
"$MACDEC" slurm --config "$RUNS/tiny slurm.toml" --out "$RUNS/results" \
    --methods dec-hddrqn,our1 --seeds 0..2 --set total_epi=40 \
    --time 00:10:00 --mem 256M >"$TMP/job/job.sh"
grep -qx '#SBATCH --array=0-3' "$TMP/job/job.sh"

STEP="submitting the job array"
JOBID=$(cd "$TMP/job" && sbatch --parsable job.sh)
JOBID=${JOBID%%;*}
JOBS="$JOBS,$JOBID"
say "submitted job array $JOBID (4 tasks)"

STEP="waiting for the array (timeout $TIMEOUT s)"
deadline=$(($(date +%s) + TIMEOUT))
while [[ -n "$(squeue -h -j "$JOBID" -o %i 2>/dev/null)" ]]; do
    if [[ $(date +%s) -ge $deadline ]]; then
        STEP="$STEP: still queued or running: $(squeue -h -j "$JOBID" -o '%i %T %R' | tr '\n' ';')"
        false
    fi
    sleep 2
done

STEP="checking the array tasks' final states"
# "JobState=X ExitCode=Y;" per jobcomp record read on stdin.
states() { grep -o "JobState=[A-Z_]* .*ExitCode=[0-9:]*" | sed -e "s/ .* / /" | tr '\n' ';'; }
task_record() { grep "ArrayJobId=$JOBID ArrayTaskId=$1 " "$STATE/jobcomp.log" || true; }
# One jobcomp record per array task, each COMPLETED with exit code 0, and no other task.
for task in 0 1 2 3; do
    record=$(task_record "$task")
    if [[ $(grep -c . <<<"$record") -ne 1 ]] || ! grep -q "JobState=COMPLETED .*ExitCode=0:0" <<<"$record"; then
        STEP="$STEP: task $task: $(states <<<"$record") (want one JobState=COMPLETED ExitCode=0:0)"
        false
    fi
done
STEP="$STEP: more than the 4 array tasks ran"
[[ $(grep -c "ArrayJobId=$JOBID " "$STATE/jobcomp.log") -eq 4 ]]
for task in 0 1 2 3; do
    STEP="checking task $task's output file"
    [[ -f "$TMP/job/slurm-${JOBID}_$task.out" ]]
done

STEP="checking every run"
for run in dec-hddrqn/seed-0 dec-hddrqn/seed-1 our1/seed-0 our1/seed-1; do
    dir="$RUNS/results/slurm_local/$run"
    STEP="run $run has no finished marker"
    [[ -f "$dir/finished" ]]
    STEP="run $run has no metrics.csv ending at episode 40"
    [[ $(tail -n 1 "$dir/metrics.csv" | cut -d, -f1) == 40 ]]
done
STEP="the array trained runs it should not have"
[[ $(find "$RUNS/results/slurm_local" -name finished | wc -l) -eq 4 ]]

# `#SBATCH --requeue`: a requeued task (as after a preemption) must find its run finished and
# leave it alone. Slurm delays a requeued job's start; release it at once.
STEP="requeueing task 2"
metrics="$RUNS/results/slurm_local/our1/seed-0/metrics.csv"
before=$(sha256sum <"$metrics")
scontrol requeue "${JOBID}_2"
release "${JOBID}_2"
STEP="waiting for the requeued task 2"
deadline=$(($(date +%s) + TIMEOUT))
while [[ -n "$(squeue -h -j "$JOBID" -o %i 2>/dev/null)" ]]; do
    [[ $(date +%s) -lt $deadline ]]
    sleep 1
done
STEP="the requeued task 2 did not complete again"
[[ $(task_record 2 | grep -c "JobState=COMPLETED .*ExitCode=0:0") -eq 2 ]]
STEP="the requeued task 2 did not report its run as finished"
grep -q "1 run(s) already finished, skipped" "$TMP/job/slurm-${JOBID}_2.out"
STEP="the requeued task 2 changed its finished run's metrics"
[[ $(sha256sum <"$metrics") == "$before" ]]

# A real preemption: requeue a longer run while it trains (Slurm kills it), let it resume from
# its checkpoint, and compare its metrics with the same run trained without interruption.
STEP="submitting a longer run to requeue mid-training"
cat >"$RUNS/resume.toml" <<'EOF'
name = "slurm_local_resume"
methods = ["our1"]
seeds = "0..1"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 6000
batch_size = 8
replay_buffer_size = 500
eval_freq = 100
checkpoint_freq = 200
EOF
"$MACDEC" slurm --config "$RUNS/resume.toml" --out "$RUNS/results" \
    --time 00:10:00 --mem 256M >"$TMP/job/resume.sh"
RJOB=$(cd "$TMP/job" && sbatch --parsable resume.sh)
RJOB=${RJOB%%;*}
JOBS="$JOBS,$RJOB"
run="$RUNS/results/slurm_local_resume/our1/seed-0"
STEP="waiting for the longer run's first checkpoint"
deadline=$(($(date +%s) + TIMEOUT))
until [[ -f "$run/checkpoint.bin" ]]; do
    [[ $(date +%s) -lt $deadline ]]
    sleep 0.2
done
STEP="the longer run finished before it could be requeued"
[[ ! -f "$run/finished" ]]
scontrol requeue "${RJOB}_0"
STEP="releasing the requeued longer run"
release "${RJOB}_0"
say "requeued the longer run (job $RJOB) at episode $(tail -n 1 "$run/metrics.csv" | cut -d, -f1)"
STEP="waiting for the requeued longer run"
while [[ -n "$(squeue -h -j "$RJOB" -o %i 2>/dev/null)" ]]; do
    [[ $(date +%s) -lt $deadline ]]
    sleep 1
done
STEP="checking the requeued longer run's records"
records=$(grep "ArrayJobId=$RJOB ArrayTaskId=0 " "$STATE/jobcomp.log" | states)
STEP="$STEP: want an interrupted record then COMPLETED with exit 0, got $records"
[[ "$records" != JobState=COMPLETED* && "$records" == *"JobState=COMPLETED ExitCode=0:0;" ]]
STEP="the requeued longer run has no finished marker"
[[ -f "$run/finished" ]]
STEP="training the longer run without interruption, for reference"
"$MACDEC" train --config "$RUNS/resume.toml" --out "$TMP/reference" --jobs 1 --quiet --no-plot \
    >"$TMP/job/reference.out" 2>&1
STEP="the resumed run's metrics differ from the uninterrupted run's (wall_seconds aside)"
[[ $(head -n 1 "$run/metrics.csv" | cut -d, -f8-) == wall_seconds ]]
cmp <(cut -d, -f1-7 "$run/metrics.csv") <(cut -d, -f1-7 "$TMP/reference/slurm_local_resume/our1/seed-0/metrics.csv")

STEP="plotting the union with macdec plot"
"$MACDEC" plot --results "$RUNS/results" --out "$RUNS/plots" >"$TMP/job/plot.txt" 2>&1
[[ -s "$RUNS/plots/slurm_local.png" && -s "$RUNS/plots/slurm_local.svg" ]]
grep -q "| Dec-HDDRQN | 2 (2) | 40 |" "$TMP/job/plot.txt"
grep -q "| Our-1 | 2 (2) | 40 |" "$TMP/job/plot.txt"
cat "$TMP/job/plot.txt"

SUMMARY="4 of 4 array tasks COMPLETED on a 1-node Slurm cluster, 4 runs finished at episode 40, a requeued finished task left its run alone, a run requeued mid-training resumed to identical metrics, plot drawn"
STEP="done"
