#!/bin/bash
# Regenerates tests/golden_acac (ACAC's learners, issue 41 item 4) with
# scripts/acac_golden_from_reference.py from a checkout of LGAI-Research/acac (26b94d99 was used):
#   bash scripts/acac_goldens.sh ACAC            # makes the venv below if it is missing
# where ACAC is a git checkout, or an archive extracted with COMMIT=<its full hash> set.
#   PY=/path/to/python bash scripts/acac_goldens.sh ACAC
# From a fresh machine (Python 3.11; torch's CPU wheel index, or plain PyPI where only PyPI is
# reachable):
#   python3.11 -m venv /tmp/torchenv
#   /tmp/torchenv/bin/pip install torch numpy gym==0.26.2 transformers==4.40.2 python-dateutil safetensors
# (the goldens were written with torch 2.15.0, numpy 2.4.6, transformers 4.40.2, gym 0.26.2,
# safetensors 0.8.0; each JSON records its versions). IPython, pygame and wandb are replaced
# by stand-ins inside the script. Tests never run this: they read the files.
set -e
A=${1:?usage: scripts/acac_goldens.sh ACAC_CHECKOUT}
VENV=${VENV:-/tmp/torchenv}
if [ -z "$PY" ]; then
  if [ ! -x "$VENV/bin/python" ]; then
    python3.11 -m venv "$VENV"
    "$VENV/bin/pip" install torch numpy gym==0.26.2 transformers==4.40.2 python-dateutil safetensors
  fi
  PY=$VENV/bin/python
fi
OUT=tests/golden_acac
for env in bp6 ovcA7; do
  for alg in acac acac_vanilla acac_micro_gae; do
    nice -n 15 "$PY" scripts/acac_golden_from_reference.py --acac "$A" --alg $alg --env $env \
      ${COMMIT:+--acac-commit $COMMIT} --seed 1 --n-env 2 --train-freq 2 --eps 0.5 --out $OUT 2>/dev/null
  done
done
