#!/usr/bin/env python3
"""Write the ACAC nets test fixture from ACAC's own PyTorch modules (values our LayerNorm, GELU,
GPT-2 encoder, time embedding, PopArt and value heads must reproduce).

Builds, with torch.manual_seed(0) and small sizes (3 agents, width 8, 2 heads, batch of 4 joint
macro-steps), the reference's modules from its own code (LGAI-Research/acac at 26b94d9,
acac/acac_marl/cores/acac/{models,transformer_model,popart}.py):

- AgentCentricGRUCritic(value_head="mean_linear", use_popart=True, use_time_emb=True,
  time_emb_dim=4, max_timestep=20), ACAC's default critic: its `centralized_transformer`
  (GPT2Model(config, use_causal_mask=False), one block, n_positions 1024) and `value` (PopArt);
- AgentCentricGRUActor(use_ln=True, use_time_emb=True): its `ln` (nn.LayerNorm) and its
  `time_embedding` (nn.Embedding.from_pretrained(positionalencoding1d(25, 4)));
- critics with value_head "concat" and "max_linear" (plain Linear value layers);
- a two-block, four-head GPT2Model of the same file (n_positions 16), to cover the layer loop.

Every trainable tensor is then redrawn at a scale where each term matters (LayerNorm gains
1 + 0.2 N(0, 1), biases 0.1 N(0, 1), weights and position embeddings 0.3 N(0, 1)). Cases, each a
forward and a backward of loss = sum(output * c) with fixed random c:

- "layer_norm": actor.ln on x [5, 8];  "gelu": transformers' ACT2FN["gelu_new"] on x [3, 7];
- "gpt2": the critic's transformer called as AgentCentricGRUCritic.forward calls it
  (inputs_embeds [4, 3, 8], attention_mask all ones, use_position_embedding=True) in eval mode
  (dropout off);
- "critic_top": the same followed by the critic's value head (`self.value(out.mean(dim=1))`,
  PopArt), the loss adding sum(value * c_v): the critic after its encoders;
- "gpt2_dropout": the same in train mode (dropout 0.1, live in the reference): forward hooks
  record each nn.Dropout's multipliers (0 or 1/0.9, checked to reproduce its output exactly),
  written in our row layout, so the Rust test replays the same masks;
- "gpt2_two_layers": the two-block model, eval mode;
- "value_heads": concat, mean_linear (PopArt) and max_linear on h [4, 3, 8], with the lines of
  AgentCentricGRUCritic.forward;
- "popart": the critic's PopArt through update(G1) [6, 1], update(G2) [9, 1], with its
  weights, bias, statistics, normalize(G) and denormalize(v) after each, as learner_acac.py calls
  them;
- "time_embedding": positionalencoding1d(205, 6) (max_timestep 200), beside the actor's table.

Writes, under tests/fixtures/:
- acac_nets_torch.safetensors: the modules' state_dicts under prefixes `critic.`, `actor.`,
  `concat.`, `max_linear.`, `gpt2_two_layers.` (ACAC's own names after the prefix, e.g.
  `critic.centralized_transformer.h.0.attn.c_attn.weight` [8, 24], Conv1D's [in, out]). The
  causal-mask buffers `h.N.attn.bias` (bool [1, 1, 1024, 1024], unused with
  use_causal_mask=False) are left out to keep the file small; `h.N.attn.masked_bias` stays.
- acac_nets_torch.json: inputs, loss weights, outputs and the gradient of every trainable tensor
  and input per case (position embeddings: the first n rows; the others get none). Floats are
  written with repr(), exact for float32.

The Rust tests (src/nn/{layer_norm,gpt2,time_embedding,popart,value_head,acac_weights}.rs) read
both files; they never need torch. How this was run (torch 2.15.0 CPU from PyPI; transformers
4.40.2, since 5.x no longer has the `SequenceSummary` ACAC's GPT-2 copy imports):

    python3 -m venv /tmp/torchenv
    /tmp/torchenv/bin/pip install torch safetensors numpy "transformers==4.40.2"
    mkdir -p /tmp/acac
    git -C /work/.mirror/LGAI-Research+acac/repo archive HEAD | tar -x -C /tmp/acac
    ACAC_DIR=/tmp/acac /tmp/torchenv/bin/python scripts/acac_nets_fixture_from_torch.py
"""

import json
import os
import sys

import torch
from safetensors.torch import save_file

sys.path.insert(0, os.environ.get("ACAC_DIR", "/tmp/acac"))
from acac.acac_marl.cores.acac import transformer_model  # noqa: E402
from acac.acac_marl.cores.acac.models import (  # noqa: E402
    AgentCentricGRUActor,
    AgentCentricGRUCritic,
    positionalencoding1d,
)
from transformers import GPT2Config  # noqa: E402
from transformers.activations import ACT2FN  # noqa: E402

N_AGENT, WIDTH, N_HEAD, BATCH, OBS = 3, 8, 2, 4, 5
TIME_DIM, MAX_T = 4, 20
OUT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures")


def tensor(t):
    t = t.detach().to(torch.float32).contiguous()
    return {"shape": list(t.shape), "data": [float(v) for v in t.reshape(-1).tolist()]}


def redraw(module):
    """Every trainable tensor at a scale where it matters (see the module docs)."""
    with torch.no_grad():
        for name, p in module.named_parameters():
            if not p.requires_grad:
                continue
            leaf = name.split(".")[-1]
            owner = module.get_submodule(name.rsplit(".", 1)[0]) if "." in name else module
            if isinstance(owner, torch.nn.LayerNorm) and leaf == "weight":
                p.copy_(1.0 + 0.2 * torch.randn_like(p))
            elif leaf == "bias":
                p.copy_(0.1 * torch.randn_like(p))
            else:
                p.copy_(0.3 * torch.randn_like(p))


def state(module, prefix):
    """A module's state_dict for the file: prefixed, f32, without the causal-mask buffers."""
    return {
        prefix + k: v.detach().to(torch.float32).contiguous().clone()
        for k, v in module.state_dict().items()
        if not k.endswith(".attn.bias")
    }


def grads_of(module, names=None, wpe_rows=N_AGENT):
    out = {}
    for name, p in module.named_parameters():
        if p.grad is None:
            continue
        g = p.grad
        if name.endswith("wpe.weight"):
            assert torch.count_nonzero(g[wpe_rows:]) == 0
            g = g[:wpe_rows]
        out[name] = tensor(g)
    return out


def rows(x):
    """[B, n, d] -> our [B n, d] rows."""
    return x.reshape(-1, x.shape[-1])


def run_transformer(model, x0, c, train=False, value=None, c_v=None):
    """ACAC's call of its transformer (AgentCentricGRUCritic.forward), then the mean_linear head."""
    model.train(train)
    model.zero_grad()
    if value is not None:
        value.zero_grad()
    x = x0.clone().requires_grad_(True)
    out = model(
        inputs_embeds=x.reshape(x.size()[0], x.size()[1], -1).contiguous(),
        attention_mask=torch.ones(x.size()[0], x.size()[1]),
        use_position_embedding=True,
    )["last_hidden_state"]
    loss = (out * c).sum()
    case = {}
    if value is not None:
        v = value(out.mean(dim=1))
        loss = loss + (v * c_v).sum()
        case["value"] = tensor(v)
    loss.backward()
    case.update(
        {
            "x": tensor(rows(x0)),
            "loss_weights": tensor(rows(c)),
            "loss": float(loss.detach()),
            "output": tensor(rows(out)),
            "grads": grads_of(model),
        }
    )
    case["grads"]["x"] = tensor(rows(x.grad))
    if value is not None:
        case["value_loss_weights"] = tensor(c_v)
        case["grads"].update({"value." + k: tensor(p.grad) for k, p in value.named_parameters() if p.grad is not None})
    return case


def record_dropout(model):
    """Forward hooks keeping each nn.Dropout's multipliers, in call order."""
    masks = []

    def hook(module, inputs, output):
        if not module.training or module.p == 0:
            return
        scale = torch.ones(1).div_(1 - module.p)
        noise = torch.where(output != 0, scale, torch.zeros(1))
        assert torch.equal(inputs[0] * noise, output), "dropout is not x * mask / (1 - p)"
        masks.append((module.name, noise.detach().clone()))

    for name, m in model.named_modules():
        if isinstance(m, torch.nn.Dropout):
            m.name = name
            m.register_forward_hook(hook)
    return masks


def dropout_case(model, x0, c):
    masks = record_dropout(model)
    case = run_transformer(model, x0, c, train=True)
    out = {}
    for name, noise in masks:
        if noise.dim() == 4:  # attention probabilities [B, H, n, n] -> [B n, H n]
            noise = noise.permute(0, 2, 1, 3).reshape(noise.shape[0] * noise.shape[2], -1)
        else:
            noise = rows(noise)
        assert name not in out
        out[name] = tensor(noise)
    case["dropout"] = out
    model.eval()
    return case


def value_heads_case(critics, h0, c):
    cases = {}
    n_batch = h0.shape[0]
    for head, critic in critics.items():
        critic.zero_grad()
        joint_transformer_outputs = h0.clone().requires_grad_(True)
        # The lines of AgentCentricGRUCritic.forward.
        if head == "concat":
            state_value = critic.value(joint_transformer_outputs.reshape((joint_transformer_outputs.size()[0], -1)))
        elif head == "mean_linear":
            state_value = critic.value(joint_transformer_outputs.mean(dim=1))
        elif head == "max_linear":
            state_value = critic.value(joint_transformer_outputs.max(dim=1)[0])
        (state_value * c).sum().backward()
        cases[head] = {
            "value": tensor(state_value),
            "grads": {
                "value.weight": tensor(critic.value.weight.grad),
                "value.bias": tensor(critic.value.bias.grad),
                "h": tensor(rows(joint_transformer_outputs.grad)),
            },
        }
    assert n_batch == BATCH
    return {"h": tensor(rows(h0)), "loss_weights": tensor(c), "heads": cases}


def popart_snapshot(p):
    return {
        "weight": tensor(p.weight),
        "bias": tensor(p.bias),
        "stddev": tensor(p.stddev),
        "mean": tensor(p.mean),
        "mean_sq": tensor(p.mean_sq),
        "debiasing_term": tensor(p.debiasing_term),
    }


def popart_case(p):
    x = torch.randn(5, WIDTH)
    steps = []
    before = popart_snapshot(p)
    for n in (6, 9):
        returns = 5.0 * torch.randn(n, 1) + 3.0
        values = torch.randn(n, 1)
        with torch.no_grad():
            y_before = p.denormalize(p(x))
        p.update(returns)
        with torch.no_grad():
            steps.append(
                {
                    "returns": tensor(returns),
                    "after": popart_snapshot(p),
                    "normalized": tensor(p.normalize(returns)),
                    "values": tensor(values),
                    "denormalized": tensor(p.denormalize(values)),
                    "denormalized_output_before": tensor(y_before),
                    "denormalized_output_after": tensor(p.denormalize(p(x))),
                }
            )
    return {"beta": p.beta, "epsilon": p.epsilon, "x": tensor(x), "before": before, "steps": steps}


def main():
    torch.manual_seed(0)
    critic_kw = dict(
        input_dim=OBS, output_dim=1, mlp_layer_size=[WIDTH, WIDTH], rnn_layer_size=WIDTH,
        n_agent=N_AGENT, cc_n_head=N_HEAD, use_time_emb=True, time_emb_dim=TIME_DIM,
        max_timestep=MAX_T,
    )
    critic = AgentCentricGRUCritic(value_head="mean_linear", use_popart=True, **critic_kw)
    actor = AgentCentricGRUActor(
        OBS, 4, [WIDTH, WIDTH], WIDTH, use_time_emb=True, time_emb_dim=TIME_DIM,
        max_timestep=MAX_T, use_ln=True,
    )
    heads = {
        "concat": AgentCentricGRUCritic(value_head="concat", **critic_kw),
        "mean_linear": critic,
        "max_linear": AgentCentricGRUCritic(value_head="max_linear", **critic_kw),
    }
    two = transformer_model.GPT2Model(
        GPT2Config(vocab_size=1, n_embd=WIDTH, n_layer=2, n_head=4, n_positions=16),
        use_causal_mask=False,
    )
    for m in [critic, actor, heads["concat"], heads["max_linear"], two]:
        redraw(m)
    for m in [critic, actor, two, *heads.values()]:
        m.eval()
    tensors = {}
    tensors.update(state(critic, "critic."))
    tensors.update(state(actor, "actor."))
    tensors.update({k: v for k, v in state(heads["concat"], "concat.").items() if ".value." in k})
    tensors.update({k: v for k, v in state(heads["max_linear"], "max_linear.").items() if ".value." in k})
    tensors.update(state(two, "gpt2_two_layers."))

    # layer norm and GELU
    x = 2.0 * torch.randn(5, WIDTH)
    c = torch.randn(5, WIDTH)
    xr = x.clone().requires_grad_(True)
    y = actor.ln(xr)
    (y * c).sum().backward()
    layer_norm = {
        "eps": actor.ln.eps, "x": tensor(x), "loss_weights": tensor(c), "output": tensor(y),
        "grads": {"weight": tensor(actor.ln.weight.grad), "bias": tensor(actor.ln.bias.grad), "x": tensor(xr.grad)},
    }
    x = 3.0 * torch.randn(3, 7)
    c = torch.randn(3, 7)
    xr = x.clone().requires_grad_(True)
    y = ACT2FN["gelu_new"](xr)
    (y * c).sum().backward()
    gelu = {"x": tensor(x), "loss_weights": tensor(c), "output": tensor(y), "grads": {"x": tensor(xr.grad)}}

    # GPT-2 cases
    model = critic.centralized_transformer
    x = torch.randn(BATCH, N_AGENT, WIDTH)
    c = torch.randn(BATCH, N_AGENT, WIDTH)
    c_v = torch.randn(BATCH, 1)
    gpt2 = run_transformer(model, x, c)
    critic_top = run_transformer(model, x, c, value=critic.value, c_v=c_v)
    gpt2_dropout = dropout_case(model, x, c)
    gpt2_two = run_transformer(two, x, c)

    # value heads, on ACAC's output layout [B, n, d]
    h = torch.randn(BATCH, N_AGENT, WIDTH)
    c = torch.randn(BATCH, 1)
    value_heads = value_heads_case(heads, h, c)

    fixture = {
        "generator": "scripts/acac_nets_fixture_from_torch.py",
        "torch_version": torch.__version__,
        "sizes": {"n_agent": N_AGENT, "width": WIDTH, "n_head": N_HEAD, "batch": BATCH,
                  "time_emb_dim": TIME_DIM, "max_timestep": MAX_T},
        "layer_norm": layer_norm,
        "gelu": gelu,
        "gpt2": gpt2,
        "critic_top": critic_top,
        "gpt2_dropout": gpt2_dropout,
        "gpt2_two_layers": gpt2_two,
        "value_heads": value_heads,
        "popart": popart_case(critic.value),
        "time_embedding": {"length": 205, "dim": 6, "table": tensor(positionalencoding1d(205, 6))},
    }
    os.makedirs(OUT_DIR, exist_ok=True)
    save_file(tensors, os.path.join(OUT_DIR, "acac_nets_torch.safetensors"), metadata={"format": "pt"})
    with open(os.path.join(OUT_DIR, "acac_nets_torch.json"), "w") as f:
        json.dump(fixture, f, indent=0)
        f.write("\n")
    print("wrote", os.path.normpath(OUT_DIR), "acac_nets_torch.json and acac_nets_torch.safetensors,",
          len(tensors), "tensors")


if __name__ == "__main__":
    main()
