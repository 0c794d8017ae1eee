"""Load one agent of an exported macdec policy into PyTorch and print its Q-values.

Shows that the exported files are portable: the safetensors tensor names are the reference's
DDRQN state_dict keys, so the weights load with `load_state_dict(strict=True)`.

    pip install torch safetensors
    python examples/load_policy.py POLICY_DIR --agent 0 --obs 0 0 1 0 0 --obs 1 0 0 0 0

Each --obs is one macro-observation at a macro-action boundary; the LSTM state is carried from
one to the next, as `macdec robot` does. Not needed by any test.
"""

import argparse
import hashlib
import json
import pathlib

import torch
import torch.nn as nn
import torch.nn.functional as F
from safetensors.torch import load_file


class DDRQN(nn.Module):
    """fc1 -> leaky_relu -> fc2 -> leaky_relu -> LSTM(H, H) -> fc3 -> leaky_relu -> fc4."""

    def __init__(self, obs_size, n_actions, mlp, hidden, slope):
        super().__init__()
        self.slope = slope
        self.fc1 = nn.Linear(obs_size, mlp)
        self.fc2 = nn.Linear(mlp, hidden)
        self.lstm = nn.LSTM(hidden, hidden, num_layers=1, batch_first=True)
        self.fc3 = nn.Linear(hidden, mlp)
        self.fc4 = nn.Linear(mlp, n_actions)

    def forward(self, x, h=None):
        # x: [batch, time, obs_size]
        x = F.leaky_relu(self.fc1(x), self.slope)
        x = F.leaky_relu(self.fc2(x), self.slope)
        x, h = self.lstm(x, h)
        x = F.leaky_relu(self.fc3(x), self.slope)
        return self.fc4(x), h


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("policy", type=pathlib.Path)
    parser.add_argument("--agent", type=int, default=0)
    parser.add_argument("--obs", type=float, nargs="+", action="append", required=True)
    args = parser.parse_args()

    if (args.policy / "policy.json").exists():
        # format_version 2: the agent's layout in "agents", its net among "nets".
        description = json.loads((args.policy / "policy.json").read_text())
        entry = description["agents"][args.agent]
        net_entry = next(n for n in description["nets"] if n["kind"] == "q"
                         and n["role"] == "dec" and n.get("agent") == args.agent)
        weights, sha256, arch = net_entry["file"], net_entry["sha256"], net_entry["architecture"]
    else:
        # An export from before format_version 2: manifest.json, one entry per agent.
        description = json.loads((args.policy / "manifest.json").read_text())
        entry = description["agents"][args.agent]
        weights, sha256, arch = entry["weights"], entry["sha256"], description["architecture"]
    path = args.policy / weights
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != sha256:
        raise SystemExit(f"{path}: SHA-256 {digest} differs from the description's {sha256}")

    net = DDRQN(entry["obs_size"], entry["n_actions"], arch["mlp_layer_size"],
                arch["rnn_h_size"], arch["leaky_relu_slope"])
    net.load_state_dict(load_file(str(path)), strict=True)
    net.eval()

    h = None
    with torch.no_grad():
        for obs in args.obs:
            if len(obs) != entry["obs_size"]:
                raise SystemExit(f"--obs has {len(obs)} values, agent {args.agent} expects "
                                 f"{entry['obs_size']}: {entry['obs_names']}")
            q, h = net(torch.tensor([[obs]], dtype=torch.float32), h)
            q = q[0, 0]
            action = int(torch.argmax(q))  # first maximum, as macdec's greedy choice
            print(json.dumps({"action": action, "name": entry["action_names"][action],
                              "q": [round(v, 6) for v in q.tolist()]}))


if __name__ == "__main__":
    main()
