#!/usr/bin/env bash
# The reproduction campaign (issue 15): every curve of the paper's four figures, 40 seeds, full
# length, into reproduction/. Resumable: finished runs are skipped and unfinished ones resume from
# their checkpoints, so run it again at the start of every session.
#
#   scripts/campaign.sh run       # train, in the order Fig 4a; Fig 5/6 seeds 0..10; Fig 4b; then
#                                 # Fig 5/6 seeds 10..40 in blocks of 5
#   scripts/campaign.sh macromarl # MacroMARL's actor-critic campaign (issue 28) into
#                                 # reproduction/macromarl: Box Pushing 6..14 at 20 seeds, then
#                                 # Warehouse A and B seeds 0..5, then their seeds 5..20
#   scripts/campaign.sh macromarl-rest # the rest of MacroMARL's actor-critic figure set (issue
#                                 # 42) into reproduction/macromarl: Warehouse C, D, E and the
#                                 # ablation, then Overcooked A, B, C, all 20 seeds, five seeds at
#                                 # a time so every block fills evenly
#   scripts/campaign.sh macromarl-value # MacroMARL's value-based blocks (issue 44) into
#                                 # reproduction/macromarl_value: Box Pushing 8, 10, 12, 20, 30
#                                 # at 20 seeds, then seeds 0..5 of Overcooked A, B MacDec-Q,
#                                 # Warehouse A, B, C, Overcooked A, B MacCen-Q
#   scripts/campaign.sh acac      # ACAC's own method on its settings (issue 41) into
#                                 # reproduction/acac: Box Pushing 6, 8, 10 at 5 seeds, then
#                                 # Overcooked A, B, C one seed at a time, then their random-start
#                                 # variants, at ACAC's budgets (a run left with a checkpoint first)
#   scripts/campaign.sh acac-baselines # ACAC's Mac-IAICC / Naive Mac-IACC baselines (issue 42
#                                 # item 5) into reproduction/acac_baselines: Box Pushing under
#                                 # every assumption, then Overcooked A, B, C under ACAC's keys
#   scripts/campaign.sh collect   # gzip each finished run's metrics and stage it (and each
#                                 # experiment's shared_curves.toml) for a commit
#   scripts/campaign.sh status    # finished seeds per curve
#
# MACDEC names the binary (default target/release/macdec; copy it elsewhere before a long run so
# rebuilding the tree does not touch the running binary). JOBS (default 2) lanes each go through
# the whole sequence one run at a time; a run another lane is training is left to it (every
# training process holds its run's lock), so no core waits for the last run of an experiment
# before the next experiment starts. The same works across machines sharing reproduction/.
set -euo pipefail
cd "$(dirname "$0")/.."
MACDEC=${MACDEC:-target/release/macdec}
JOBS=${JOBS:-2}
OUT=reproduction

train() {
    "$MACDEC" train --config "experiments/$1.toml" --out "$OUT" --jobs 1 --quiet --no-plot "${@:2}"
}

train_macromarl() {
    "$MACDEC" train --config "experiments/macromarl/$1.toml" --out "$OUT/macromarl" --jobs 1 \
        --quiet --no-plot "${@:2}"
}

macromarl_lane() {
    set -e
    for block in bp6 bp8 bp10 bp12 bp14; do
        train_macromarl "$block"
    done
    train_macromarl wh_a --seeds 0..5
    train_macromarl wh_b --seeds 0..5
    # Then the rest of Warehouse A and B's 20 published seeds, five at a time.
    for first in 5 10 15; do
        train_macromarl wh_a --seeds "$first..$((first + 5))"
        train_macromarl wh_b --seeds "$first..$((first + 5))"
    done
}

macromarl_rest_lane() {
    set -e
    for first in 0 5 10 15; do
        for block in wh_c wh_d wh_e wh_ablation; do
            train_macromarl "$block" --seeds "$first..$((first + 5))"
        done
    done
    for first in 0 5 10 15; do
        for block in overcooked_a overcooked_b overcooked_c; do
            train_macromarl "$block" --seeds "$first..$((first + 5))"
        done
    done
}

train_macromarl_value() {
    "$MACDEC" train --config "experiments/macromarl_value/$1.toml" --out "$OUT/macromarl_value" \
        --jobs 1 --quiet --no-plot "${@:2}"
}

macromarl_value_lane() {
    set -e
    for block in bp8 bp10 bp12 bp20 bp30; do
        train_macromarl_value "$block" --seeds 0..5
    done
    # Box Pushing's published 20 seeds, five at a time (minutes a run), before Overcooked and
    # the Warehouse.
    for first in 5 10 15; do
        for block in bp8 bp10 bp12 bp20 bp30; do
            train_macromarl_value "$block" --seeds "$first..$((first + 5))"
        done
    done
    # A run a previous session left with a checkpoint (the machine outlived it) goes first.
    for dir in "$OUT"/macromarl_value/*/*/seed-*; do
        if [[ -f $dir/checkpoint.bin && ! -f $dir/finished ]]; then
            seed=${dir##*/seed-}
            method=$(basename "$(dirname "$dir")")
            block=$(basename "$(dirname "$(dirname "$dir")")")
            train_macromarl_value "$block" --seeds "$seed" --methods "$method" </dev/null
        fi
    done
    # MacDec-Q on Overcooked next (about an hour of a core a run: it finishes within a session
    # on a fresh machine), then the Warehouse blocks (both methods; Warehouse A MacDec-Q's first
    # 10 000 episodes took 180 CPU s for 12 494 updates on a Zen 3, so about a quarter of an
    # hour of a core a run), and MacCen-Q on Overcooked last (some 310 000 updates of its
    # 225-wide joint net: about six hours of a core a run).
    for block in overcooked_a overcooked_b; do
        train_macromarl_value "$block" --seeds 0..5 --methods mac-dec-q
    done
    for block in wh_a wh_b wh_c overcooked_a overcooked_b; do
        train_macromarl_value "$block" --seeds 0..5
    done
}

train_acac() {
    "$MACDEC" train --config "experiments/acac/$1.toml" --out "$OUT/acac" --methods acac \
        --jobs 1 --quiet --no-plot "${@:2}"
}

# ACAC's Overcooked runs in campaign order, one "<env> <seed>" a line: the fixed-start maps
# (20M counted steps, 52-78 minutes of a core at seed 4 on the Zen 3) at every seed, then the
# random-start maps (40M: about two hours of a core on the Zen 3, ovcAR7 seed 0 122 minutes, so
# one fits in a session only when it starts near the session's beginning).
acac_overcooked_runs() {
    for envs in "ovcA7 ovcB7 ovcC7" "ovcAR7 ovcBR7 ovcCR7"; do
        for seed in 0 1 2 3 4; do
            for env in $envs; do
                echo "$env $seed"
            done
        done
    done
}

acac_lane() {
    set -e
    for env in bp6 bp8 bp10; do
        train_acac "$env" --seeds 0..5
    done
    # A run a previous session left with a checkpoint (the machine outlived it) goes first.
    acac_overcooked_runs | while read -r env seed; do
        dir="$OUT/acac/$env/acac/seed-$seed"
        if [[ -f $dir/checkpoint.bin && ! -f $dir/finished ]]; then
            train_acac "$env" --seeds "$seed" </dev/null
        fi
    done
    acac_overcooked_runs | while read -r env seed; do
        train_acac "$env" --seeds "$seed" </dev/null
    done
}

train_acac_baselines() {
    "$MACDEC" train --config "experiments/acac_baselines/$1.toml" --out "$OUT/acac_baselines" \
        --jobs 1 --quiet --no-plot "${@:2}"
}

acac_baselines_lane() {
    set -e
    # Box Pushing: every assumption, seconds a run (all committed; skipped when finished).
    for grid in 6 8 10; do
        for assumed in "" _state _acac_keys _state_acac_keys; do
            train_acac_baselines "bp$grid$assumed"
        done
    done
    # Overcooked under ACAC's keys (about half an hour a run): every map's seed k before k + 1.
    for seed in 0 1 2 3 4; do
        for map in A B C; do
            train_acac_baselines "ovc${map}7_acac_keys" --seeds "$seed"
        done
    done
}

lanes() {
    pids=()
    for _ in $(seq "$JOBS"); do
        "$1" &
        pids+=($!)
        sleep 1
    done
    status=0
    for pid in "${pids[@]}"; do
        wait "$pid" || status=1
    done
    return "$status"
}

lane() {
    set -e
    train fig4a_bp10
    train fig5_wtd --seeds 0..10
    train fig6_wtd_ablation --seeds 0..10
    train fig4b_bp30
    # Warehouse seeds 10..40 in blocks of five, so every Warehouse curve has about the same seeds.
    for first in 10 15 20 25 30 35; do
        train fig5_wtd --seeds "$first..$((first + 5))"
        train fig6_wtd_ablation --seeds "$first..$((first + 5))"
    done
}

case "${1:-}" in
run)
    lanes lane
    ;;
macromarl)
    lanes macromarl_lane
    ;;
macromarl-rest)
    lanes macromarl_rest_lane
    ;;
macromarl-value)
    lanes macromarl_value_lane
    ;;
acac)
    lanes acac_lane
    ;;
acac-baselines)
    lanes acac_baselines_lane
    ;;
collect)
    find "$OUT" -name finished -type f | sort | while read -r marker; do
        dir=$(dirname "$marker")
        if [[ -f "$dir/metrics.csv" ]]; then
            gzip -9 -n -c "$dir/metrics.csv" >"$dir/.metrics.csv.gz.tmp"
            mv "$dir/.metrics.csv.gz.tmp" "$dir/metrics.csv.gz"
        fi
        git add -f "$dir/config.toml" "$dir/metrics.csv.gz" "$dir/finished"
    done
    # A figure that draws another experiment's runs (Figure 6's Our-2) says so here.
    find "$OUT" -maxdepth 2 -name shared_curves.toml -type f -exec git add -f {} +
    ;;
status)
    # Curves are <experiment>/<curve>/ and, for MacroMARL, macromarl/<block>/<method>/ and
    # macromarl_value/<block>/<method>/, acac/<env>/<method>/ for ACAC and
    # acac_baselines/<experiment>/<method>/.
    for curve in "$OUT"/*/*/ "$OUT"/macromarl/*/*/ "$OUT"/macromarl_value/*/*/ "$OUT"/acac/*/*/ \
        "$OUT"/acac_baselines/*/*/; do
        n=$(find "$curve" -mindepth 2 -maxdepth 2 -name finished | wc -l)
        [[ $n -gt 0 ]] && echo "${curve#"$OUT"/}: $n finished"
    done
    ;;
*)
    echo "usage: $0 run|macromarl|macromarl-rest|macromarl-value|acac|acac-baselines|collect|status" >&2
    exit 2
    ;;
esac
