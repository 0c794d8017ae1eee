#!/bin/bash
# Regenerates tests/fixtures/macromarl with scripts/macromarl_traces.py (see its doc):
#   PY=venv/bin/python TORCH_PY=torchvenv/bin/python scripts/macromarl_fixtures.sh MACROMARL OVERCOOKED
# The greedy episodes of the authors' trained actors (*_actors) need torch in TORCH_PY's venv
# (pip install torch numpy gym==0.26.2); without TORCH_PY they are left as they are.
set -e
PY=${PY:-python3}; MM=$1; OC=$2; F=tests/fixtures/macromarl; S=scripts/macromarl_traces.py
BP='"big_box_reward": 300, "small_box_reward": 20, "penalty": -10'
for g in 6 8 10 12 14; do
  $PY $S --macromarl $MM --env BP-MA-v0 --params "{\"grid_dim\": [$g, $g], $BP}" --plan '[[2, 4], [3, 4]]' --horizon 100 --out $F/bp_ma_${g}_optimum
  for s in 0 1; do
    $PY $S --macromarl $MM --env BP-MA-v0 --params "{\"grid_dim\": [$g, $g], $BP}" --random-seed $s --horizon 100 --out $F/bp_ma_${g}_random$s
  done
done
# Longer random episodes (penalties, misses) on 6x6 and 4x4, and a horizon cut on 10x10 at step 25.
$PY $S --macromarl $MM --env BP-MA-v0 --params "{\"grid_dim\": [6, 6], $BP}" --random-seed 10 --horizon 100 --out $F/bp_ma_6_random10
$PY $S --macromarl $MM --env BP-MA-v0 --params "{\"grid_dim\": [4, 4], $BP}" --random-seed 3 --horizon 100 --out $F/bp_ma_4_random3
$PY $S --macromarl $MM --env BP-MA-v0 --params "{\"grid_dim\": [10, 10], $BP}" --random-seed 4 --horizon 25 --out $F/bp_ma_10_cut25_random4
P='"grid_dim": [6, 6], '"$BP"', "TB_move_speed": 0.6, "TB_move_noisy": 0.0, "TB_move_cost": 0.0, "fetch_pass_obj_tc": 4, "fetch_look_for_obj_tc": 6, "fetch_manip_noisy": 0.0, "delay_delivery_penalty": 0.0, "obs_human_wait": false'
$PY $S --macromarl $MM --env OSD-D-v7 --params "{$P, \"n_agent\": 3, \"terminate_step\": 200, \"human_speed_per_step\": [[27,20,20,20],[27,20,20,20]]}" --random-seed 0 --horizon 200 --out $F/osd_d_v7_a_random0
$PY $S --macromarl $MM --env OSD-D-v7 --params "{$P, \"n_agent\": 3, \"terminate_step\": 200, \"human_speed_per_step\": [[18,15,15,15],[48,18,15,15]]}" --random-seed 1 --horizon 200 --out $F/osd_d_v7_b_random1
$PY $S --macromarl $MM --env OSD-T-v0 --params "{$P, \"n_agent\": 3, \"terminate_step\": 250, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --random-seed 0 --horizon 250 --out $F/osd_t_v0_c_random0
$PY $S --macromarl $MM --env OSD-T-v1 --params "{$P, \"n_agent\": 4, \"terminate_step\": 250, \"human_speed_per_step\": [[38,38,38,38],[38,38,38,38],[27,27,27,27]]}" --random-seed 0 --horizon 250 --out $F/osd_t_v1_d_random0
$PY $S --macromarl $MM --env OSD-F-v0 --params "{$P, \"n_agent\": 4, \"terminate_step\": 300, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --random-seed 0 --horizon 300 --out $F/osd_f_v0_e_random0
R='{"subtask finished": 10, "correct delivery": 200, "wrong delivery": -5, "step penalty": -0.1}'
for m in A B C; do
  $PY $S --macromarl $MM --overcooked $OC --env Overcooked-MA-v1 --params "{\"grid_dim\": [7, 7], \"map_type\": \"$m\", \"task\": \"lettuce-onion-tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 3}" --random-seed 0 --horizon 200 --out $F/overcooked_$(echo $m | tr A-Z a-z)_n3_random0
done
# As published: the scripts never pass n_agent, so the reference builds its default, 2 agents.
# macdec's default is the paper's 3, so the file names the reference's 2 (the same kitchen).
$PY $S --macromarl $MM --overcooked $OC --env Overcooked-MA-v1 --params "{\"grid_dim\": [7, 7], \"map_type\": \"A\", \"task\": \"lettuce-onion-tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 2}" --random-seed 1 --horizon 200 --out $F/overcooked_a_n2_random1
# The authors' trained actors (visualization/policy_nns), greedy with each GRU state carried
# across its agent's decisions, under the published settings of each block (Warehouse: Turtlebot
# speed 0.8, delay penalty -20), so their episodes replay here step for step.
if [ -n "$TORCH_PY" ]; then
  N=$MM/visualization/policy_nns
  $TORCH_PY $S --macromarl $MM --env BP-MA-v0 --params "{\"grid_dim\": [14, 14], $BP}" --actors $N/BP_MA/14x14 --horizon 100 --gamma 0.98 --out $F/bp_ma_14_actors
  W='"grid_dim": [6, 6], '"$BP"', "TB_move_speed": 0.8, "TB_move_noisy": 0.0, "TB_move_cost": 0.0, "fetch_pass_obj_tc": 4, "fetch_look_for_obj_tc": 6, "fetch_manip_noisy": 0.0, "delay_delivery_penalty": -20.0, "obs_human_wait": false'
  $TORCH_PY $S --macromarl $MM --env OSD-T-v0 --params "{$W, \"n_agent\": 3, \"terminate_step\": 250, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --actors $N/OSD_T/40 --horizon 250 --out $F/osd_t_v0_c_actors
  $TORCH_PY $S --macromarl $MM --env OSD-T-v1 --params "{$W, \"n_agent\": 4, \"terminate_step\": 250, \"human_speed_per_step\": [[38,38,38,38],[38,38,38,38],[27,27,27,27]]}" --actors $N/OSD_T/4R383827 --horizon 250 --out $F/osd_t_v1_d_actors
  $TORCH_PY $S --macromarl $MM --env OSD-F-v0 --params "{$W, \"n_agent\": 4, \"terminate_step\": 300, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --actors $N/OSD_F/v040 --horizon 300 --out $F/osd_f_v0_e_actors
  for m in A B; do
    $TORCH_PY $S --macromarl $MM --overcooked $OC --env Overcooked-MA-v1 --params "{\"grid_dim\": [7, 7], \"map_type\": \"$m\", \"task\": \"lettuce-onion-tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 3}" --actors $N/Overcooked/map$m --horizon 200 --gamma 0.99 --out $F/overcooked_$(echo $m | tr A-Z a-z)_n3_actors
  done
fi
# Warehouse at the published settings (tb_m_speed 0.8, d_pen -20). The *_scripted steps are macdec's
# scripted team that serves every human (OSD_STEPS_DIR=DIR cargo test --release --lib
# write_scripted_steps -- --ignored writes them); here they are read back from the fixtures.
WP='"TB_move_speed": 0.8, "delay_delivery_penalty": -20.0'
steps() { $PY -c 'import json, sys; print(json.dumps(json.load(open(sys.argv[1]))["steps"]))' $F/$1.actions.json > /tmp/$1.steps.json; echo /tmp/$1.steps.json; }
$PY $S --macromarl $MM --env OSD-D-v7 --params "{$WP, \"human_speed_per_step\": [[27,20,20,20],[27,20,20,20]]}" --steps $(steps osd_d_v7_a_scripted) --out $F/osd_d_v7_a_scripted
$PY $S --macromarl $MM --env OSD-D-v7 --params "{$WP, \"obs_human_wait\": true, \"human_speed_per_step\": [[18,15,15,15],[48,18,15,15]]}" --steps $(steps osd_d_v7_b_scripted) --out $F/osd_d_v7_b_scripted
$PY $S --macromarl $MM --env OSD-T-v0 --params "{$WP, \"obs_human_wait\": true, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --steps $(steps osd_t_v0_c_scripted) --out $F/osd_t_v0_c_scripted
$PY $S --macromarl $MM --env OSD-T-v1 --params "{$WP, \"human_speed_per_step\": [[38,38,38,38],[38,38,38,38],[27,27,27,27]]}" --steps $(steps osd_t_v1_d_scripted) --out $F/osd_t_v1_d_scripted
$PY $S --macromarl $MM --env OSD-F-v0 --params "{$WP, \"obs_human_wait\": true, \"terminate_step\": 300, \"human_speed_per_step\": [[40,40,40,40],[40,40,40,40],[40,40,40,40],[40,40,40,40]]}" --steps $(steps osd_f_v0_e_scripted) --out $F/osd_f_v0_e_scripted
C="$WP"', "TB_move_cost": -0.5, "fetch_drop_obj_penalty": -5.0, "obs_human_wait": true'
$PY $S --macromarl $MM --env OSD-D-v7 --params "{$C, \"human_speed_per_step\": [[18,15,15,15],[48,18,15,15]]}" --random-seed 2 --horizon 200 --out $F/osd_d_v7_costs_random2
$PY $S --macromarl $MM --env OSD-T-v1 --params "{$C, \"human_speed_per_step\": [[8,8,8,8],[38,38,38,38],[27,27,27,27]]}" --random-seed 1 --horizon 250 --out $F/osd_t_v1_costs_random1
# Overcooked episodes that reach the correct delivery (terminal) from scripted plans: map A's
# full salad with 3 agents (chops, plate gathering, delivery), and a 2-agent tomato salad with a
# wrong delivery first; then random episodes on the 9 x 9 map C and on map B with another task.
$PY $S --macromarl $MM --overcooked $OC --env Overcooked-MA-v1 --params "{\"grid_dim\": [7, 7], \"map_type\": \"A\", \"task\": \"lettuce-onion-tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 3}" --plan '[[1,6,9,4,6,7,0,0,0,0,0,0,0,0,0,0,0,0,6,8],[2,7,9,11,10,10,0],[3,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,6,9,10,10,0]]' --horizon 200 --out $F/overcooked_a_n3_salad_plan
$PY $S --macromarl $MM --overcooked $OC --env Overcooked-MA-v1 --params "{\"grid_dim\": [7, 7], \"map_type\": \"A\", \"task\": \"tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 2}" --plan '[[1,6,9,4,6,8],[2,8,10,10,0]]' --horizon 200 --out $F/overcooked_a_n2_tomato_plan
$PY $S --macromarl $MM --overcooked $OC --env Overcooked-MA-v1 --params "{\"grid_dim\": [9, 9], \"map_type\": \"C\", \"task\": \"lettuce-onion-tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 3}" --random-seed 2 --horizon 200 --out $F/overcooked_c9_n3_random2
$PY $S --macromarl $MM --overcooked $OC --env Overcooked-MA-v1 --params "{\"grid_dim\": [7, 7], \"map_type\": \"B\", \"task\": \"onion-tomato salad\", \"rewardList\": $R, \"debug\": false, \"n_agent\": 2}" --random-seed 3 --horizon 200 --out $F/overcooked_b_n2_random3
