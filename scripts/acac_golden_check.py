#!/usr/bin/env python3
"""Recomputes, with numpy alone, what tests/golden_acac/README.md says ACAC's learners compute,
from the other fields of each golden: discounts, macro-level GAE (acac) and its micro-lambda
variant (acac_micro_gae), returns with ACAC's last-step quirk, PopArt's update and
normalization, critic losses, PPO ratios and losses, the advantages each actor picks,
acac_vanilla's n-step returns and policy-gradient losses, and the dropout masks' lengths.
It also replays, from the recorded weights, inputs and dropout masks, every critic forward
(target-critic bootstrap, each epoch's critic) and the actors' old log-probabilities, and
epoch 0's Adam step from the recorded gradients. An
executable form of the README (needs numpy and safetensors, not torch); tests never run it.

  python scripts/acac_golden_check.py [CASE ...]     (default: every case)
"""
import glob
import json
import os
import sys

import numpy as np

DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "golden_acac")


# -- numpy forwards of ACAC's nets (GRU encoders, GPT-2 block with the recorded dropout masks,
#    mean_linear/PopArt head; actors with LayerNorm and the eps-mixture) -----------------------

def unpack(bits, shape):
    n = int(np.prod(shape))
    v = np.array([int(c, 16) for c in bits], dtype=np.uint8)
    b = np.stack([(v >> 3) & 1, (v >> 2) & 1, (v >> 1) & 1, v & 1], axis=1).ravel()[:n]
    return b.reshape(shape).astype(np.float64)

def lrelu(x): return np.where(x > 0, x, 0.01 * x)
def sig(x): return 1 / (1 + np.exp(-x))

def gru(W, pre, x):  # x [B,T,in] -> [B,T,H]
    wih, whh, bih, bhh = (W[pre + s] for s in ("weight_ih_l0", "weight_hh_l0", "bias_ih_l0", "bias_hh_l0"))
    H = whh.shape[1]; B, T, _ = x.shape
    h = np.zeros((B, H)); out = np.zeros((B, T, H))
    for t in range(T):
        gi = x[:, t] @ wih.T + bih; gh = h @ whh.T + bhh
        r = sig(gi[:, :H] + gh[:, :H]); z = sig(gi[:, H:2*H] + gh[:, H:2*H])
        n = np.tanh(gi[:, 2*H:] + r * gh[:, 2*H:])
        h = (1 - z) * n + z * h; out[:, t] = h
    return out

def encoder(W, pre, x):
    x = lrelu(x @ W[pre + "fc1.weight"].T + W[pre + "fc1.bias"])
    x = lrelu(x @ W[pre + "fc2.weight"].T + W[pre + "fc2.bias"])
    return gru(W, pre + "gru.", x)

def ln(x, w, b, eps=1e-5):
    m = x.mean(-1, keepdims=True); v = ((x - m) ** 2).mean(-1, keepdims=True)
    return (x - m) / np.sqrt(v + eps) * w + b

def gelu_new(x): return 0.5 * x * (1 + np.tanh(np.sqrt(2 / np.pi) * (x + 0.044715 * x ** 3)))

def critic(W, table, x, v, time_emb, masks, n_agent, n_head, p=0.1):
    B, K, _ = x.shape
    x = x.reshape(B, K, n_agent, -1).transpose(2, 0, 1, 3)
    te = table[np.array(time_emb)]  # [B,K,2]
    x = np.concatenate([x, np.broadcast_to(te, (n_agent,) + te.shape)], -1)
    v = np.array(v, dtype=bool).transpose(2, 0, 1)
    jv = v.any(0)
    feats = []
    for i in range(n_agent):
        lens = v[i].sum(1); J = lens.max()
        xi = np.zeros((B, J, x.shape[-1]))
        for e in range(B): xi[e, :lens[e]] = x[i, e][v[i, e]]
        out = encoder(W, f"encoders.{i}.", xi)
        idx = np.cumsum(v[i], 1) - 1
        f = np.stack([out[e][idx[e]] for e in range(B)]) * jv[..., None]
        feats.append(f)
    feat = np.stack(feats, 2)[jv]  # [N, n, d]
    T = "centralized_transformer."
    d = feat.shape[-1]; hd = d // n_head
    m = iter(masks)
    def drop(h):
        mk = next(m); assert list(h.shape) == mk["shape"], (h.shape, mk["shape"])
        return h * unpack(mk["bits"], mk["shape"]) / (1 - p)
    h = drop(feat + W[T + "wpe.weight"][:n_agent])
    a = ln(h, W[T + "h.0.ln_1.weight"], W[T + "h.0.ln_1.bias"])
    qkv = a @ W[T + "h.0.attn.c_attn.weight"] + W[T + "h.0.attn.c_attn.bias"]
    q, k, vv = np.split(qkv, 3, -1)
    sp = lambda t: t.reshape(t.shape[0], n_agent, n_head, hd).transpose(0, 2, 1, 3)
    q, k, vv = sp(q), sp(k), sp(vv)
    w = q @ k.transpose(0, 1, 3, 2) / np.sqrt(hd)
    w = np.exp(w - w.max(-1, keepdims=True)); w /= w.sum(-1, keepdims=True)
    w = drop(w)
    o = (w @ vv).transpose(0, 2, 1, 3).reshape(-1, n_agent, d)
    o = drop(o @ W[T + "h.0.attn.c_proj.weight"] + W[T + "h.0.attn.c_proj.bias"])
    h = h + o
    a = ln(h, W[T + "h.0.ln_2.weight"], W[T + "h.0.ln_2.bias"])
    a = gelu_new(a @ W[T + "h.0.mlp.c_fc.weight"] + W[T + "h.0.mlp.c_fc.bias"])
    a = drop(a @ W[T + "h.0.mlp.c_proj.weight"] + W[T + "h.0.mlp.c_proj.bias"])
    h = ln(h + a, W[T + "ln_f.weight"], W[T + "ln_f.bias"])
    val = h.mean(1) @ W["value.weight"].T + W["value.bias"]
    out = np.zeros((B, jv.sum(1).max(), 1)); pos = 0
    for e in range(B):
        c = jv[e].sum(); out[e, :c] = val[pos:pos + c]; pos += c
    return out

def actor(W, table, x, seq, eps):
    te = table[np.array(seq)]
    x = np.concatenate([x, te], -1)
    h = encoder(W, "encoder.", x)
    h = lrelu(h @ W["fc3.weight"].T + W["fc3.bias"])
    h = ln(h, W["ln.weight"], W["ln.bias"])
    z = h @ W["fc4.weight"].T + W["fc4.bias"]
    ls = z - z.max(-1, keepdims=True); ls = ls - np.log(np.exp(ls).sum(-1, keepdims=True))
    n = z.shape[-1]
    return np.logaddexp(ls + np.log(1 - eps), np.log(eps) - np.log(n))

def net(S, prefix, name):
    p = f"{prefix}/{name}/"
    return {k[len(p):]: v.astype(np.float64) for k, v in S.items() if k.startswith(p)}

def check_forwards(case, d):
    """Replays every critic forward (dropout masks included) and the actors' old log-probabilities
    in numpy from the recorded weights and inputs; returns the worst relative error."""
    from safetensors.numpy import load_file

    S = load_file(os.path.join(DIR, case + ".safetensors"))
    b = d["batch"]; n = len(d["obs_size"]); s = d["settings"]
    obs = [np.array(o, dtype=np.float64) for o in b["obs"]]
    fin = [np.array(o, dtype=np.float64) for o in b["final_next_obs"]]
    E = b["n_episodes"]
    def nxt(i, e, t): return obs[i][e][t + 1] if t + 1 < b["epi_len"][e] else fin[i][e]
    L = d["squeezed"]["cen_epi_len"]; K = max(L)
    jobs = np.zeros((E, K, sum(d["obs_size"]))); njobs = np.zeros_like(jobs)
    for e in range(E):
        ts = [t for t in range(b["max_len"]) if b["joint_mac_valid"][e][t]]
        for k, t in enumerate(ts):
            jobs[e, k] = np.concatenate([obs[i][e][t] for i in range(n)])
            njobs[e, k] = np.concatenate([nxt(i, e, t) for i in range(n)])
    Wc = net(S, "init", "critic"); table = Wc["time_embedding.weight"]
    worst = 0
    for fw in d["dropout"]:
        if fw["call"] == "bootstrap":
            x = np.concatenate([jobs[:, :1], njobs], 1)[:, : fw["x_shape"][1]]
            W = Wc
            want = np.array(fw["output"])
        else:
            x = jobs
            ep = int(fw["call"].split("/")[0][5:])
            if fw["call"].endswith("/advantage"):
                W = dict(Wc); W.update(net(S, f"epoch{ep}/mb0/after", "critic")); want = np.array(d["epochs"][ep]["minibatches"][0]["values_for_advantage"])
            else:
                W = dict(Wc)
                if ep > 0: W.update(net(S, f"epoch{ep-1}/mb0/after", "critic"))
                elif d["popart"]:
                    W["value.weight"] = np.array(d["popart"]["after"]["weight"]); W["value.bias"] = np.array(d["popart"]["after"]["bias"])
                want = np.array(d["epochs"][ep]["minibatches"][0]["critic"]["values"])
        got = critic(W, table, x, fw["v"], fw["time_emb"], fw["masks"], n, s["cc_n_head"])
        err = np.abs(got - want).max() / max(1, np.abs(want).max()); worst = max(worst, err)
    if d["alg"] != "acac_vanilla":
        for i in range(n):
            Wa = net(S, "init", f"actor{i}")
            ag = d["squeezed"]["agents"][i]; J = ag["trace_len"]
            xi = np.zeros((E, J, d["obs_size"][i]))
            for e in range(E):
                ts = [t for t in range(b["max_len"]) if b["mac_valid"][e][t][i]]
                for j, t in enumerate(ts): xi[e, j] = obs[i][e][t]
            lp = actor(Wa, Wa["time_embedding.weight"], xi, ag["obs_seq"], d["eps"])
            act = np.array(ag["action"])
            lpa = np.take_along_axis(lp, act, -1)
            err = np.abs(lpa - np.array(d["old_log_pi"][i])).max()
            worst = max(worst, err)
    return worst

def check_first_adam(case, d):
    """Epoch 0's weights are the initial ones (PopArt's rescaled head for `value`) after one Adam
    step (bias-corrected: w - lr g / (|g| + 1e-8)) on the recorded epoch-0 gradients."""
    from safetensors.numpy import load_file

    S = load_file(os.path.join(DIR, case + ".safetensors"))
    worst = 0.0
    for k, g in S.items():
        if not k.startswith("epoch0/mb0/grad/"):
            continue
        net_name, name = k.split("/")[3], "/".join(k.split("/")[4:])
        w0 = S[f"init/{net_name}/{name}"].astype(np.float64)
        if net_name == "critic" and name in ("value.weight", "value.bias") and d["popart"]:
            w0 = np.array(d["popart"]["after"][name.split(".")[1]], dtype=np.float64)
        w1 = S[f"epoch0/mb0/after/{net_name}/{name}"].astype(np.float64)
        g = g.astype(np.float64)[: w1.shape[0]]
        w0 = w0[: w1.shape[0]]  # wpe: rows [0, n_agent) only after epoch 0
        lr = d["settings"]["c_lr"] if net_name == "critic" else d["settings"]["a_lr"]
        worst = max(worst, np.abs(w1 - (w0 - lr * g / (np.abs(g) + 1e-8))).max())
    return worst


def ratios(num, den):
    with np.errstate(invalid="ignore", divide="ignore"):
        out = num / den
    out[np.isnan(out)] = 0.0
    return out


def check(case):
    d = json.load(open(os.path.join(DIR, case + ".json")))
    s = d["settings"]
    gamma, lam, alg = s["gamma"], s["GAE_lambda"], d["alg"]
    sq, b, L = d["squeezed"], d["batch"], d["squeezed"]["cen_epi_len"]
    f32 = np.float32
    disc_name = "discount" if alg == "acac_vanilla" else "j_discount"
    for e in range(b["n_episodes"]):
        ts = [t for t in range(b["max_len"]) if b["joint_mac_valid"][e][t]]
        assert len(ts) == L[e]
        got = np.array(sq[disc_name][e])[: L[e], 0]
        want = np.power(f32(gamma), np.array(ts, dtype=np.float32))
        assert np.allclose(got, want, rtol=1e-6), (case, e)
    for fw in d["dropout"]:
        for m in fw["masks"]:
            assert len(m["bits"]) == (int(np.prod(m["shape"])) + 3) // 4
    if alg == "acac_vanilla":
        check_vanilla(d, sq, L, gamma)
    else:
        check_ppo(d, sq, b, L, gamma, lam, alg)
    worst = check_forwards(case, d)
    assert worst < 1e-5, worst
    adam = check_first_adam(case, d)
    assert adam < 1e-6, adam
    print(case, "ok (forwards replayed to %.1e, first Adam step to %.1e)" % (worst, adam))


def check_ppo(d, sq, b, L, gamma, lam, alg):
    g = d["gae"]
    for e in range(b["n_episodes"]):
        l = L[e]
        r = np.array(sq["jr"][e])[:, 0].astype(np.float64)
        D = np.array(sq["j_discount"][e])[:, 0].astype(np.float64)
        term = np.array(sq["j_terminate"][e])[:, 0]
        boot = np.array(g["bootstrap"][e])[:, 0]
        init = g["init_value"][e][0][0]
        md = ratios(D, np.concatenate([[1 / gamma], D[:-1]]))
        if alg == "acac_micro_gae":
            G = np.array(sq["j_gae_lambda"][e])[:, 0].astype(np.float64)
            ml = ratios(G, np.concatenate([[1 / lam], G[:-1]]))
        else:
            ml = np.full(len(D), lam)
        adv = np.zeros(len(D))
        end = l - 1
        adv[end] = r[end] + (0 if term[end] else md[end] * boot[end]) - boot[end - 1]
        for k in range(end - 1, -1, -1):
            v = init if k == 0 else boot[k - 1]
            adv[k] = r[k] + md[k] * boot[k] - v + md[k] * ml[k] * adv[k + 1]
        got = np.array(g["advantage"][e])[:, 0]
        assert np.allclose(got[:l], adv[:l], rtol=1e-4, atol=1e-4)
        val = np.zeros(len(D))
        val[:end] = np.concatenate([[init], boot[: end - 1]])  # the last value stays 0 (ACAC)
        assert np.allclose(np.array(g["returns_raw"][e])[:l, 0], (adv + val)[:l], rtol=1e-4, atol=1e-4)
    pb, pa = d["popart"]["before"], d["popart"]["after"]
    raw = np.concatenate([np.array(g["returns_raw"][e])[: L[e], 0] for e in range(len(L))]).astype(np.float64)
    beta = 0.99999
    mean = pb["mean"][0] * beta + raw.mean() * (1 - beta)
    msq = pb["mean_sq"][0] * beta + (raw**2).mean() * (1 - beta)
    deb = pb["debiasing_term"] * beta + (1 - beta)
    assert np.isclose(mean, pa["mean"][0], rtol=1e-5) and np.isclose(msq, pa["mean_sq"][0], rtol=1e-5)
    assert np.isclose(deb, pa["debiasing_term"], rtol=1e-5)
    dm = mean / max(deb, 1e-5)
    dv = max(msq / max(deb, 1e-5) - dm**2, 1e-2)
    norm = (raw - dm) / np.sqrt(dv)
    got = np.concatenate([np.array(g["returns"][e])[: L[e], 0] for e in range(len(L))])
    assert np.allclose(got, norm, rtol=1e-4, atol=1e-4)
    clip = d["settings"]["clip_ratio"]
    A = np.array(g["advantage"])[:, :, 0]
    for ep in d["epochs"]:
        mb = ep["minibatches"][0]
        c = mb["critic"]
        ev = np.array(sq["exp_valid"])[:, :, 0]
        TD = np.array(c["TD"])[:, :, 0]
        assert np.allclose(TD, np.array(g["returns"])[:, :, 0] - np.array(c["V_value"])[:, :, 0], atol=1e-5)
        assert np.isclose(c["loss"], (ev * TD * TD).sum() / ev.sum(), rtol=1e-5)
        for i, a in enumerate(mb["actors"]):
            evi = np.array(sq["agents"][i]["exp_valid"])[:, :, 0]
            lp = np.array(a["log_pi_a"])[:, :, 0]
            old = np.array(d["old_log_pi"][i])[:, :, 0]
            ratio = np.exp((lp - old) * evi)
            assert np.allclose(ratio, np.array(a["is_ratio"])[:, :, 0], rtol=1e-5)
            adv = np.array(a["adv_agent"])[:, :, 0]
            p1, p2 = evi * adv * ratio, evi * adv * np.clip(ratio, 1 - clip, 1 + clip)
            loss = (-np.minimum(p1, p2) * evi).sum() / evi.sum()
            assert np.isclose(loss, a["loss"], rtol=1e-4, atol=1e-6)
            mst = np.array(sq["agents"][i]["mac_st_j"]).astype(bool)
            for e in range(len(L)):
                sel = A[e][: mst.shape[1]][mst[e]]
                assert np.allclose(adv[e][: len(sel)], sel)


def check_vanilla(d, sq, L, gamma):
    n = d["settings"]["n_step_TD"]
    G = np.array(d["returns"]["returns"])[:, :, 0]
    for e, l in enumerate(L):
        r = np.array(sq["reward"][e])[:, 0].astype(np.float64)
        D = np.array(sq["discount"][e])[:, 0].astype(np.float64)
        B = np.array(sq["bootstrap"][e])[:, 0]
        term = np.array(sq["terminate"][e])[:, 0]
        prev = np.concatenate([[1 / gamma], D[:-1]])
        md = ratios(D, prev)
        end = l - 1
        g = r.copy()
        if not term[end]:
            g[end] += md[end] * B[end]
        for k in range(end - 1, -1, -1):
            if k > end - n:  # fewer than n joint steps left: discounted sum to the end
                g[k] = g[k] + md[k] * g[k + 1]
            else:  # n-step: r_k, ..., r_{k+n-1}, then the bootstrap after step k+n-1
                w = np.concatenate([[1.0], D[k : k + n] / prev[k]])
                g[k] = (w * np.concatenate([r[k : k + n], [B[k + n - 1]]])).sum()
        assert np.allclose(g[:l], G[e][:l], rtol=1e-4, atol=1e-4)
    for ep in d["epochs"]:
        for i, a in enumerate(ep["minibatches"][0]["actors"]):
            ag = sq["agents"][i]
            ev = np.array(ag["exp_valid"])[:, :, 0]
            dc = np.array(ag["discount"])[:, :, 0]
            lp, adv = np.array(a["log_pi_a"])[:, :, 0], np.array(a["adv"])[:, :, 0]
            ent = np.array(a["pi_entropy"])[:, :, 0]
            loss = -(ev * dc * (lp * adv + d["etrpy_w"] * ent)).sum() / ev.sum()
            assert np.isclose(loss, a["loss"], rtol=1e-4)


if __name__ == "__main__":
    cases = sys.argv[1:] or sorted(os.path.basename(p)[:-5] for p in glob.glob(os.path.join(DIR, "*.json")))
    for c in cases:
        check(c)
