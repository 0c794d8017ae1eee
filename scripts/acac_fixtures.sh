#!/bin/bash
# Regenerates tests/fixtures/acac with scripts/acac_traces.py (see its doc), from a checkout of
# LGAI-Research/acac at ACAC (commit 26b94d99 was used):
#   PY=venv/bin/python scripts/acac_fixtures.sh ACAC
set -e
PY=${PY:-python3}; A=$1; F=tests/fixtures/acac; S=scripts/acac_traces.py
mkdir -p $F
# Fixed starts, maps A-C, 3 agents (ACAC's column-major numbering decides contended cells).
$PY $S --acac $A --setting ovcA7 --np-seed 0 --random-seed 0 --out $F/ovc_a7_random0
$PY $S --acac $A --setting ovcB7 --np-seed 0 --random-seed 1 --out $F/ovc_b7_random1
$PY $S --acac $A --setting ovcC7 --np-seed 0 --random-seed 2 --out $F/ovc_c7_random2
# Map C, the whole task: the macro-actions of the greedy episode of our ovcC7 seed 2 policy
# (reproduction/acac/ovcC7/acac/seed-2, `macdec eval --trajectories`: each agent's macro-actions
# in the order it started them), delivered at step 40 for 226.
$PY $S --acac $A --setting ovcC7 --np-seed 0 --plan '[[1, 7, 9, 13, 7, 7, 7, 6, 6, 6, 6, 6, 6, 6, 6, 6], [3, 13, 6, 9, 3, 9, 3, 10, 14, 9, 14, 9, 9, 14, 14, 14, 14, 9, 9], [2, 7, 9, 2, 5, 7, 3, 8]]' --out $F/ovc_c7_policy
# Random starts: numpy's draws after np.random.seed(S), and the grid they produced.
$PY $S --acac $A --setting ovcAR7 --np-seed 3 --random-seed 3 --out $F/ovc_ar7_np3_random3
$PY $S --acac $A --setting ovcBR7 --np-seed 4 --random-seed 4 --out $F/ovc_br7_np4_random4
$PY $S --acac $A --setting ovcCR7 --np-seed 5 --random-seed 5 --out $F/ovc_cr7_np5_random5
$PY $S --acac $A --setting ovcBR7 --np-seed 123456789 --random-seed 6 --horizon 60 --out $F/ovc_br7_np123456789_random6
# Box Pushing as ACAC's runner passes it (MacroMARL's env).
$PY $S --acac $A --setting bp6 --np-seed 0 --random-seed 7 --out $F/bp6_random7
for g in 8 10; do
  $PY $S --acac $A --setting bp$g --np-seed 0 --plan '[[2, 4], [3, 4]]' --out $F/bp${g}_big_box
  $PY $S --acac $A --setting bp$g --np-seed 0 --random-seed 7 --out $F/bp${g}_random7
done
# Overcooked-MA-v0 (Large: 11x11, 6 agents, objects A-F that start chopped, row-major numbering).
# Random actions: seeds chosen for many cycles of 4 or 6 agents moving at once (A 22, C 22) and for
# wrong deliveries followed by chops (B 8).
$PY $S --acac $A --setting ovcA11_N6 --np-seed 0 --random-seed 22 --out $F/ovc_a11_random22
$PY $S --acac $A --setting ovcB11_N6 --np-seed 0 --random-seed 8 --out $F/ovc_b11_random8
$PY $S --acac $A --setting ovcC11_N6 --np-seed 0 --random-seed 22 --out $F/ovc_c11_random22
# Map A planned: agent 5 hands in an empty plate, agent 1 a fresh A (both wrong, -5, refreshed);
# the refreshed A is unchopped: agent 1 puts it on knife 1 and chops it (+10), then gathers A..F
# on plate 1 and delivers the dish (+200, terminal). Agents 0, 2, 3 step out of the way.
$PY $S --acac $A --setting ovcA11_N6 --np-seed 0 --plan '[[19,19,18,0], [1,15,1,11,16,7,1,2,3,4,5,6,15], [18,18,18,18,18,0], [18,18,18,18,18,0], [0], [9,15,20,20,0]]' --out $F/ovc_a11_plan_dish
# Maps B and C planned: agent 1 gathers A..F on plate 1 right of the divider and puts it on the
# divider ("go to counter"); agent 2 waits left of it, takes the plate and delivers (+200).
for m in B C; do
  $PY $S --acac $A --setting ovc${m}11_N6 --np-seed 0 --plan '[[0], [7,1,2,3,4,5,6,17,0], [19,19,19,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,7,15,0], [19,19,19,19,19,19,0], [0], [0]]' --out $F/ovc_$(echo $m | tr BC bc)11_plan_counter
done
# Random starts (ovcAR11_N6 etc.): numpy's draws after np.random.seed(S), and the grid they made.
$PY $S --acac $A --setting ovcAR11_N6 --np-seed 7 --random-seed 7 --out $F/ovc_ar11_np7_random7
$PY $S --acac $A --setting ovcBR11_N6 --np-seed 8 --random-seed 8 --out $F/ovc_br11_np8_random8
$PY $S --acac $A --setting ovcCR11_N6 --np-seed 9 --random-seed 9 --out $F/ovc_cr11_np9_random9
