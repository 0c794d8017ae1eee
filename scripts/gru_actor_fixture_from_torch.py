#!/usr/bin/env python3
"""Write the GRU-actor test fixture from PyTorch (values macdec's GruActor must reproduce).

Builds, with torch.manual_seed(0) and PyTorch's default initialisation, a module of MacroMARL's
actor shape (spec macromarl.md 2.4: fc1 Linear(5, 6) -> leaky_relu -> fc2 Linear(6, 6) ->
leaky_relu -> GRU(6 -> 3, batch_first) -> fc3 Linear(3, 4) -> leaky_relu -> fc4 Linear(4, 8) ->
log_softmax; m0 = 6 and m1 = 4 differ on purpose), feeds it 5 observations one step at a time
with the hidden state carried (as the reference acts), and writes under tests/fixtures/:

- gru_actor_torch.safetensors: the module's state_dict (fc1.weight, ..., gru.weight_ih_l0, ...),
  as `scripts/torch_to_safetensors.py` would give for a shipped actor;
- gru_actor_torch.json: the observations and, per step, the log-probabilities and the hidden
  state. Floats are written with repr(), exact for float32.

The Rust test (src/nn/gru_actor.rs) reads both; it never needs torch. Run with:

    /tmp/torchenv/bin/python scripts/gru_actor_fixture_from_torch.py
"""

import json
import os

import torch
import torch.nn.functional as F
from safetensors.torch import save_file

OUT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures")


class Actor(torch.nn.Module):
    def __init__(self, obs, m0, m1, hidden, actions):
        super().__init__()
        self.fc1 = torch.nn.Linear(obs, m0)
        self.fc2 = torch.nn.Linear(m0, m0)
        self.gru = torch.nn.GRU(m0, hidden, num_layers=1, batch_first=True)
        self.fc3 = torch.nn.Linear(hidden, m1)
        self.fc4 = torch.nn.Linear(m1, actions)

    def forward(self, x, h=None):
        x = F.leaky_relu(self.fc1(x))
        x = F.leaky_relu(self.fc2(x))
        x, h = self.gru(x, h)
        x = F.leaky_relu(self.fc3(x))
        return F.log_softmax(self.fc4(x), dim=-1), h


def main():
    torch.manual_seed(0)
    actor = Actor(5, 6, 4, 3, 8)
    obs = torch.rand(5, 5) * 2 - 1
    steps, h = [], None
    with torch.no_grad():
        for o in obs:
            logp, h = actor(o.view(1, 1, -1), h)
            steps.append(
                {
                    "log_probs": [float(v) for v in logp.view(-1).tolist()],
                    "h": [float(v) for v in h.view(-1).tolist()],
                }
            )
    save_file(
        {k: v.contiguous() for k, v in actor.state_dict().items()},
        os.path.join(OUT_DIR, "gru_actor_torch.safetensors"),
    )
    with open(os.path.join(OUT_DIR, "gru_actor_torch.json"), "w") as f:
        json.dump({"obs": [[float(v) for v in o.tolist()] for o in obs], "steps": steps}, f)
        f.write("\n")


if __name__ == "__main__":
    main()
