#!/usr/bin/env python3
"""Where ACAC's own training time goes: its main process's CPU seconds inside the PPO update
(`Learner_ACAC.train`), acting for training and evaluation (`EnvsRunner.run`, split by
`test_mode`), printed at exit beside `scripts/acac_reference_speed.py`'s totals (issue 41 item 6).

Wraps those two methods with `time.process_time()` (about 75 calls per 400 episodes, nothing
inside ACAC's code changes), then runs `acac_reference_speed.py` with the same arguments. The
environment workers' time is that script's "children". Run as acac_reference_speed.py, e.g.:
  OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 nice -n 5 /usr/bin/time -f '%U %S' \\
      /tmp/torchenv/bin/python scripts/acac_reference_phases.py --acac /tmp/acac \\
      --data /tmp/acac-phases -- --alg_name acac --env_name ovcA7 --device cpu --seed 1 --total_epi 50
"""

import atexit
import builtins
import collections
import os
import runpy
import time

seconds = collections.defaultdict(float)
calls = collections.defaultdict(int)


def timed(cls, name, key):
    inner = getattr(cls, name)

    def wrapper(self, *args, **kwargs):
        start = time.process_time()
        try:
            return inner(self, *args, **kwargs)
        finally:
            k = key(kwargs)
            seconds[k] += time.process_time() - start
            calls[k] += 1

    setattr(cls, name, wrapper)


installed = []
real_import = builtins.__import__


def importing(name, *args, **kwargs):
    module = real_import(name, *args, **kwargs)
    if not installed and name.startswith("acac.acac_marl.algs"):
        # ACAC's modules are importable once acac_reference_speed.py has set its path.
        import acac.acac_marl.cores.acac.envs_runner as runner
        import acac.acac_marl.cores.acac.learner_acac as learner

        timed(learner.Learner_ACAC, "train", lambda kw: "update")
        timed(runner.EnvsRunner, "run", lambda kw: "evaluation" if kw.get("test_mode") else "acting")
        installed.append(True)
    return module


@atexit.register
def report():
    parts = " | ".join("%s %.2f s (%d calls)" % (k, seconds[k], calls[k]) for k in sorted(seconds))
    print("acac_reference_phases: main-process CPU: %s | all of it %.2f s" % (parts, time.process_time()), flush=True)


builtins.__import__ = importing
here = os.path.dirname(os.path.abspath(__file__))
runpy.run_path(os.path.join(here, "acac_reference_speed.py"), run_name="__main__")
