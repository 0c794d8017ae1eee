#!/bin/bash
# Environment speed, macdec against MacroMARL's Python environments, side by side: `macdec bench
# envs` pinned to CPU 0 while scripts/macromarl_traces.py --speed steps each reference environment
# (published settings, random macro-actions) pinned to CPU 1, at the same time.
#   PY=venv/bin/python MACDEC=target/release/macdec scripts/macromarl_speed.sh MACROMARL OVERCOOKED
set -e
MM=$1; OC=$2; PY=${PY:-python3}; MACDEC=${MACDEC:-target/release/macdec}; S=scripts/macromarl_traces.py
SECONDS_EACH=${SECONDS_EACH:-10}
taskset -c 0 $MACDEC bench envs > /tmp/macdec_speed.txt &
ours=$!
BP='"big_box_reward": 300, "small_box_reward": 20, "penalty": -10'
W='"grid_dim": [6, 6], '"$BP"', "TB_move_speed": 0.8, "TB_move_noisy": 0.0, "TB_move_cost": 0.0, "fetch_pass_obj_tc": 4, "fetch_look_for_obj_tc": 6, "fetch_manip_noisy": 0.0, "delay_delivery_penalty": -20.0, "obs_human_wait": false'
R='{"subtask finished": 10, "correct delivery": 200, "wrong delivery": -5, "step penalty": -0.1}'
ref() { taskset -c 1 $PY $S --macromarl $MM --overcooked $OC --speed $SECONDS_EACH "$@" 2> /dev/null; }
for g in 6 10 14; do ref --env BP-MA-v0 --params "{\"grid_dim\": [$g, $g], $BP}" --horizon 100; done
ref --env OSD-D-v7 --params "{$W, \"n_agent\": 3, \"terminate_step\": 200, \"human_speed_per_step\": [[27,20,20,20],[27,20,20,20]]}" --horizon 200
ref --env OSD-T-v0 --params "{$W, \"n_agent\": 3, \"terminate_step\": 250, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --horizon 250
ref --env OSD-T-v1 --params "{$W, \"n_agent\": 4, \"terminate_step\": 250, \"human_speed_per_step\": [[38,38,38,38],[38,38,38,38],[27,27,27,27]]}" --horizon 250
ref --env OSD-F-v0 --params "{$W, \"n_agent\": 4, \"terminate_step\": 300, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --horizon 300
for m in A B C; do
  ref --env Overcooked-MA-v1 --params "{\"grid_dim\": [7, 7], \"map_type\": \"$m\", \"task\": \"lettuce-onion-tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 3}" --horizon 200
done
wait $ours
cat /tmp/macdec_speed.txt
