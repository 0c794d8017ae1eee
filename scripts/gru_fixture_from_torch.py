#!/usr/bin/env python3
"""Write the GRU test fixture from PyTorch's nn.GRU (values our fused GRU op must reproduce).

Builds torch.nn.GRU(input_size=5, hidden_size=4, batch_first=True) with torch.manual_seed(0)
(PyTorch's default init), a fixed input batch x [2, 3, 5] and fixed loss weights c [2, 3, 4],
and for two cases runs a forward and a backward of loss = sum(output * c) over the valid steps:

- "full":   both sequences have length 3;
- "packed": lengths [3, 1] through pack_padded_sequence(enforce_sorted=False), so the
            second sequence stops after one step (our SeqPacking's variable lengths).

Writes, under tests/fixtures/:
- gru_torch.safetensors: gru.state_dict() as saved by safetensors.torch.save_file (names
  weight_ih_l0 [12, 5], weight_hh_l0 [12, 4], bias_ih_l0 [12], bias_hh_l0 [12]), the file a
  user would bring from PyTorch;
- gru_torch.json: the same tensors, x, c, and per case the lengths, the outputs (zero past a
  sequence's end), the final hidden state h_n [2, 4], and the gradients of the loss with
  respect to every parameter and to x. Floats are written with repr(), exact for float32.

The Rust test (src/nn/gru.rs, `matches_pytorch_nn_gru_values_and_gradients`) reads both files;
it never needs torch. How this was run (torch 2.15.0 CPU; the CPU-only wheel index was
unreachable, so the PyPI wheel):

    python3 -m venv /tmp/torchenv
    /tmp/torchenv/bin/pip install torch safetensors numpy
    /tmp/torchenv/bin/python scripts/gru_fixture_from_torch.py
"""

import json
import os

import torch
from safetensors.torch import save_file
from torch.nn.utils.rnn import pack_padded_sequence, pad_packed_sequence

INPUT, HIDDEN, BATCH, SEQ = 5, 4, 2, 3
OUT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures")


def tensor(t):
    t = t.detach().to(torch.float32).contiguous()
    return {"shape": list(t.shape), "data": [float(v) for v in t.reshape(-1).tolist()]}


def run_case(gru, x0, c, lengths):
    gru.zero_grad()
    x = x0.clone().requires_grad_(True)
    packed = pack_padded_sequence(x, torch.tensor(lengths), batch_first=True, enforce_sorted=False)
    out_packed, h_n = gru(packed)
    out, _ = pad_packed_sequence(out_packed, batch_first=True, total_length=SEQ)
    loss = (out * c).sum()
    loss.backward()
    grads = {name: tensor(p.grad) for name, p in gru.named_parameters()}
    grads["x"] = tensor(x.grad)
    return {
        "lengths": lengths,
        "loss": float(loss.detach()),
        "output": tensor(out),
        "h_n": tensor(h_n[0]),
        "grads": grads,
    }


def main():
    torch.manual_seed(0)
    gru = torch.nn.GRU(INPUT, HIDDEN, batch_first=True)
    x = torch.randn(BATCH, SEQ, INPUT)
    c = torch.randn(BATCH, SEQ, HIDDEN)
    fixture = {
        "generator": "scripts/gru_fixture_from_torch.py",
        "torch_version": torch.__version__,
        "input_size": INPUT,
        "hidden_size": HIDDEN,
        "state_dict": {name: tensor(t) for name, t in gru.state_dict().items()},
        "x": tensor(x),
        "loss_weights": tensor(c),
        "cases": {
            "full": run_case(gru, x, c, [SEQ, SEQ]),
            "packed": run_case(gru, x, c, [SEQ, 1]),
        },
    }
    os.makedirs(OUT_DIR, exist_ok=True)
    save_file(
        {k: v.contiguous() for k, v in gru.state_dict().items()},
        os.path.join(OUT_DIR, "gru_torch.safetensors"),
        metadata={"format": "pt"},
    )
    with open(os.path.join(OUT_DIR, "gru_torch.json"), "w") as f:
        json.dump(fixture, f, indent=1)
        f.write("\n")
    print("wrote", os.path.normpath(OUT_DIR), "gru_torch.json and gru_torch.safetensors")


if __name__ == "__main__":
    main()
