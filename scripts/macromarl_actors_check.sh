#!/bin/bash
# The authors' trained MacroMARL actors, run by macdec: converts each shipped actor set
# (visualization/policy_nns of a MacroMARL checkout) with scripts/torch_to_safetensors.py, imports
# it with `macdec import --reference macromarl`, evaluates one greedy episode with `macdec eval
# --trajectories` and compares the return, the length and every step's executed macro-actions and
# reward with the reference's own greedy episode (tests/fixtures/macromarl/*_actors, written by
# scripts/macromarl_fixtures.sh from the reference code). Needs torch for the conversion only:
#   python3.11 -m venv torchvenv && torchvenv/bin/pip install torch safetensors numpy
#   TORCH_PY=torchvenv/bin/python MACDEC=target/release/macdec scripts/macromarl_actors_check.sh MACROMARL
set -e
MM=$1; TORCH_PY=${TORCH_PY:-python3}; MACDEC=${MACDEC:-target/release/macdec}
N=$MM/visualization/policy_nns; F=tests/fixtures/macromarl; W=$(mktemp -d)
check() { # name, policy_nns subdirectory, gym id, params JSON
  local name=$1 src=$N/$2 env=$3 params=$4 i=0 agents=""
  for f in $(ls $src/*.pt | sort); do
    $TORCH_PY scripts/torch_to_safetensors.py $f $W/$name-$i.safetensors > /dev/null
    agents="$agents${agents:+,}$W/$name-$i.safetensors"; i=$((i + 1))
  done
  echo "$params" > $W/$name.json
  $MACDEC import --reference macromarl --env $env --params $W/$name.json --agents $agents --out $W/$name 2> /dev/null
  $MACDEC eval --policy $W/$name --episodes 1 --trajectories 2> /dev/null > $W/$name.eval.json
  python3 - "$W/$name.eval.json" "$F/${name}_actors.trace.jsonl.gz" "$name" <<'PY'
import gzip, json, sys
ours = json.load(open(sys.argv[1]))
theirs = [json.loads(l) for l in gzip.open(sys.argv[2], "rt")][1:]
steps = [(s["executed"], round(s["reward"], 6)) for s in ours["trajectory"]]
ref = [(l["executed"], round(l["reward"], 6)) for l in theirs]
same = steps == ref
print(f"{sys.argv[3]}: macdec {ours['return']:.3f} in {ours['steps']} steps; "
      f"the reference's episode has {len(ref)} steps; every step identical: {same}")
sys.exit(0 if same else 1)
PY
}
BP='"big_box_reward": 300, "small_box_reward": 20, "penalty": -10'
check bp_ma_14 BP_MA/14x14 BP-MA-v0 "{\"grid_dim\": [14, 14], $BP}"
check osd_t_v0_c OSD_T/40 OSD-T-v0 '{"human_speed_per_step": [[40,40,40,40],[40,40,40,40],[40,40,40,40]]}'
check osd_t_v1_d OSD_T/4R383827 OSD-T-v1 '{"human_speed_per_step": [[38,38,38,38],[38,38,38,38],[27,27,27,27]]}'
check osd_f_v0_e OSD_F/v040 OSD-F-v0 '{"human_speed_per_step": [[40,40,40,40],[40,40,40,40],[40,40,40,40],[40,40,40,40]]}'
check overcooked_a_n3 Overcooked/mapA Overcooked-MA-v1 '{"map_type": "A", "n_agent": 3}'
check overcooked_b_n3 Overcooked/mapB Overcooked-MA-v1 '{"map_type": "B", "n_agent": 3}'
rm -rf $W
