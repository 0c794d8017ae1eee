#!/bin/bash
# Whole-training speed, macdec against MacroMARL's own code (issues 42 item 1, 44 item 4): the same
# configuration and number of episodes on both sides, one run at a time, the two sides alternating
# (ours, the reference, ours, ...) so both see the same load. CPU seconds are user + system of the
# whole process tree (/usr/bin/time; the reference's --n_env worker processes are its children),
# which a busy neighbour core changes little; the reference's include its start-up imports.
#
#   PY=/tmp/torchenv/bin/python MACDEC=target/release/macdec \
#       scripts/macromarl_train_speed.sh MACROMARL OVERCOOKED OUT.csv [SETTING ...]
#
# MACROMARL and OVERCOOKED are checkouts of yuchen-x/MacroMARL and WeihaoTan/gym-macro-overcooked
# (the reference runs unchanged through scripts/macromarl_reference_curve.py). OUT.csv gets one
# row per run: setting, side, seed, episodes, cpu_s, wall_s. Settings (default: all) are the
# published rows of experiments/{BoxPushing,Warehouse,Overcooked}/mac_*.sh, verbatim but for
# --total_epi, with an explicit --seed. ROUNDS (default 1) reference runs per setting, each between
# OURS (default 1) runs of ours in a row; ROUNDS=0 times ours alone. Optional tool: tests and CI
# never run it.
set -euo pipefail
MM=$1; OC=$2; CSV=$3; shift 3
PY=${PY:-python3}; MACDEC=${MACDEC:-target/release/macdec}; ROUNDS=${ROUNDS:-1}; SEED=${SEED:-1}
OURS=${OURS:-1}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cd "$(dirname "$0")/.."

OC_COMMON="--env_id=Overcooked-MA-v1 --n_agent=3 --env_terminate_step=200 --c_lr=0.003
    --train_freq=8 --n_env=8 --c_target_update_freq=32 --n_step_TD=5 --grad_clip_norm=0
    --eps_start=1.0 --eps_end=0.05 --eps_stable_at=20_000 --grid_dim 7 7 --gamma=0.99
    --eval_policy --sample_epi --run_id=0 --task=6 --map_type=A --step_penalty=-0.1
    --c_mlp_layer_size 128 64 --c_rnn_layer_size=64"
WH="--l_mode=0 --n_step_TD=5 --grad_clip_norm=0 --eps_start=1.0
    --gamma=1.0 --a_rnn_layer_size=32 --c_rnn_layer_size=64 --d_pen=-20.0 --tb_m_speed=0.8
    --sample_epi --eval_policy --run_id=0"
BP8_VALUE="--env_id=BP-MA-v0 --grid_dim 8 8 --n_agent=2 --env_terminate_step=100 --batch_size=64
    --train_freq=10 --replay_buffer_size=100_000 --trace_len=10 --l_rate=0.001 --h_stable_at=4_000
    --eps_l_d_steps=4_000 --eps_end=0.05 --discount=0.98 --start_train=500 --dynamic_h --eps_l_d
    --run_id=0"
# One line each, for the table below.
OC_COMMON=$(echo $OC_COMMON)
WH=$(echo $WH)
BP8_VALUE=$(echo $BP8_VALUE)

# name | episodes | our experiment file | our extra flags | the reference's flags
# [| the reference's entry: pg (default, scripts/pg_based_main.py) or value (value_based_main.py)]
# (The reference's Overcooked `--n_agent=3` never reaches its environment, which trains 2 agents:
# the 3-agent row times ours with the paper's 3 against a second run of the 2-agent command.)
# The value-based rows (issue 44) are experiments/BoxPushing/mac_{dec,cen}_q.sh's 8x8 rows.
settings() {
    cat <<EOF
oc_a_mac_iaicc_2agents|400|experiments/macromarl/overcooked_a.toml|--methods mac-iaicc --set n_agent=2|--save_dir=iaicc_overcooked_A --alg=MacIAICC --l_mode=0 --a_lr=0.0003 $OC_COMMON
oc_a_mac_iaicc_3agents|400|experiments/macromarl/overcooked_a.toml|--methods mac-iaicc|--save_dir=iaicc_overcooked_A --alg=MacIAICC --l_mode=0 --a_lr=0.0003 $OC_COMMON
oc_a_mac_cac_2agents|400|experiments/macromarl/overcooked_a.toml|--methods mac-cac --set n_agent=2|--save_dir=mac_cac_overcooked_A --alg=MacCAC --a_lr=0.0001 $OC_COMMON
wh_a_mac_iaicc|400|experiments/macromarl/wh_a.toml|--methods mac-iaicc|--save_dir=ma_iaicc_warehouse_A --alg=MacIAICC --env_id=OSD-D-v7 --n_agent=3 --env_terminate_step=200 --train_freq=4 --n_env=4 --c_target_update_freq=32 --eps_end=0.05 --eps_stable_at=10_000 --h0_speed_ps 27 20 20 20 --h1_speed_ps 27 20 20 20 --a_lr=0.0005 --c_lr=0.0005 $WH
wh_c_mac_iaicc|400|experiments/macromarl/wh_c.toml|--methods mac-iaicc|--save_dir=ma_iaicc_warehouse_C --alg=MacIAICC --env_id=OSD-T-v1 --n_agent=4 --env_terminate_step=250 --train_freq=4 --n_env=4 --c_target_update_freq=64 --eps_end=0.01 --eps_stable_at=10_000 --h0_speed_ps 40 40 40 40 --h1_speed_ps 40 40 40 40 --h2_speed_ps 40 40 40 40 --a_lr=0.0003 --c_lr=0.003 $WH
bp10_mac_iaisc|4000|experiments/macromarl/bp10.toml|--methods mac-iaisc|--save_dir=ma_iaicc_bp10 --alg=MacIAISC --env_id=BP-MA-v0 --n_agent=2 --env_terminate_step=100 --big_box_reward=300 --a_lr=0.0003 --c_lr=0.003 --train_freq=32 --n_env=32 --c_target_update_freq=64 --n_step_TD=0 --grad_clip_norm=0 --eps_start=1.0 --eps_end=0.01 --eps_stable_at=6_000 --grid_dim 10 10 --gamma=0.98 --eval_policy --sample_epi --run_id=0
bp8_mac_dec_q|3000|experiments/macromarl_value/bp8.toml|--methods mac-dec-q|--save_dir=ma_hddrqn_bp8 --alg=MacDecQ $BP8_VALUE|value
bp8_mac_cen_q|3000|experiments/macromarl_value/bp8.toml|--methods mac-cen-q|--save_dir=ma_cen_condi_ddrqn_bp8 --alg=MacCenQ $BP8_VALUE --rnn_h_size=64 --init_h=1.0 --end_h=1.0|value
EOF
}

[[ -f $CSV ]] || echo "setting,side,seed,episodes,cpu_s,wall_s" >"$CSV"

timed() { # side name seed episodes command...
    local side=$1 name=$2 seed=$3 episodes=$4
    shift 4
    /usr/bin/time -f '%U %S %e' -o "$TMP/time" "$@" >"$TMP/log" 2>&1 ||
        { echo "$side $name failed:" >&2; tail -5 "$TMP/log" >&2; exit 1; }
    read -r user sys wall <"$TMP/time"
    printf '%s,%s,%s,%s,%.2f,%s\n' "$name" "$side" "$seed" "$episodes" \
        "$(awk "BEGIN { print $user + $sys }")" "$wall" | tee -a "$CSV"
}

ours() { # name episodes config flags; OURS runs in a row
    for _ in $(seq "$OURS"); do
        # shellcheck disable=SC2086
        timed macdec "$1" "$SEED" "$2" "$MACDEC" train --config "$3" $4 --set "total_epi=$2" \
            --seeds "$SEED" --out "$TMP/ours" --jobs 1 --quiet --no-plot --force
    done
}

settings | while IFS='|' read -r name episodes config our_flags ref_flags entry; do
    if [[ $# -gt 0 ]] && ! [[ " $* " == *" $name "* ]]; then continue; fi
    ours "$name" "$episodes" "$config" "$our_flags"
    for _ in $(seq "$ROUNDS"); do
        # shellcheck disable=SC2086
        OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 timed reference "$name" "$SEED" "$episodes" \
            "$PY" scripts/macromarl_reference_curve.py --main "${entry:-pg}" --ref "$MM" \
            --overcooked "$OC" --out "$TMP/ref-$name" -- $ref_flags "--total_epi=$episodes" "--seed=$SEED"
        ours "$name" "$episodes" "$config" "$our_flags"
    done
done
