#!/usr/bin/env python3
"""PyTorch side of `macdec bench gru`: nn.GRU beside nn.LSTM, one forward and backward.

The same shapes as src/bench/gru.rs (the recurrent layer of the paper's nets: input = hidden,
`batch` full-length sequences of `seq` steps): x [batch, seq, in] with requires_grad (the Q-net
needs the input's gradient), y = rnn(x) from a zero state, then y.backward(dy) for a fixed
random dy. Parameter gradients are zeroed between passes (set_to_none). One thread, as ours.
Modeled on shared/bench/pytorch_qnet_update.py. Prints one JSON line per (shape, rnn).

Usage (as recorded in docs/PERFORMANCE.md, beside `macdec bench gru` on another core):
    taskset -c 1 /tmp/torchenv/bin/python scripts/pytorch_gru_bench.py [--steps 200]
"""
import argparse
import json
import statistics
import time

import torch

SHAPES = {
    "bp10x10-dec": dict(input=32, hidden=32, batch=128, seq=15),
    "bp10x10-cen": dict(input=64, hidden=64, batch=128, seq=15),
    "wtd-dec": dict(input=64, hidden=64, batch=16, seq=150),
}


def bench(name, cfg, rnn, steps, warmup, seed=0):
    torch.manual_seed(seed)
    cls = {"lstm": torch.nn.LSTM, "gru": torch.nn.GRU}[rnn]
    net = cls(cfg["input"], cfg["hidden"], batch_first=True)
    x = torch.randn(cfg["batch"], cfg["seq"], cfg["input"], requires_grad=True)
    dy = torch.randn(cfg["batch"], cfg["seq"], cfg["hidden"])
    times = []
    for i in range(warmup + steps):
        t0 = time.perf_counter()
        net.zero_grad(set_to_none=True)
        x.grad = None
        y, _ = net(x)
        y.backward(dy)
        t1 = time.perf_counter()
        if i >= warmup:
            times.append((t1 - t0) * 1e3)
    times.sort()
    med = statistics.median(times)
    return dict(
        shape=name,
        rnn=rnn,
        **cfg,
        steps=steps,
        median_ms=round(med, 3),
        p10_ms=round(times[len(times) // 10], 3),
        p90_ms=round(times[(9 * len(times)) // 10], 3),
        us_per_step=round(med * 1e3 / cfg["seq"], 2),
        threads=torch.get_num_threads(),
        torch=torch.__version__,
    )


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--only", choices=list(SHAPES))
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--warmup", type=int, default=20)
    args = p.parse_args()
    torch.set_num_threads(1)
    for name, cfg in SHAPES.items():
        if args.only and args.only != name:
            continue
        for rnn in ("lstm", "gru"):
            print(json.dumps(bench(name, cfg, rnn, args.steps, args.warmup)), flush=True)
