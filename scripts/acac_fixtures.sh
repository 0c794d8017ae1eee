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
# Random starts: numpy's draws after np.random.seed(S), and the grid they produced.
$PY $S --acac $A --setting ovcAR7 --np-seed 3 --random-seed 3 --out $F/ovc_ar7_np3_random3
$PY $S --acac $A --setting ovcBR7 --np-seed 4 --random-seed 4 --out $F/ovc_br7_np4_random4
$PY $S --acac $A --setting ovcCR7 --np-seed 5 --random-seed 5 --out $F/ovc_cr7_np5_random5
$PY $S --acac $A --setting ovcBR7 --np-seed 123456789 --random-seed 6 --horizon 60 --out $F/ovc_br7_np123456789_random6
# Box Pushing as ACAC's runner passes it (MacroMARL's env).
$PY $S --acac $A --setting bp6 --np-seed 0 --random-seed 7 --out $F/bp6_random7
