"""Train two methods on Box Pushing 8x8 from Python, load the learning curves into pandas and
plot the mean return over seeds with matplotlib (about ten seconds on two cores).

    pip install ./python pandas matplotlib
    python examples/python/train_and_plot.py            # writes py_example.png
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import macdec

config = {
    "name": "py_example",
    "methods": ["dec-hddrqn", "our1"],
    "seeds": "0..3",
    "params": {
        "env_name": "BP_MA",
        "grid_dim": 8,
        "env_terminate_step": 50,
        "total_epi": 600,
        "eps_l_d_steps": 400,
        "eval_freq": 20,
    },
}
runs = macdec.train(config, out="results_py")
print(f"trained {len(runs)} runs, e.g. {runs[0]}")

df = macdec.load_results("results_py")
df = df[df["experiment"] == "py_example"]
curves = df.groupby(["method", "episode"], observed=True)["eval_return"].agg(["mean", "sem"]).reset_index()
print(df.groupby("method", observed=True)["eval_return"].describe())

fig, ax = plt.subplots(figsize=(6, 4))
for method, c in curves.groupby("method", observed=True):
    ax.plot(c["episode"], c["mean"], label=method)
    ax.fill_between(c["episode"], c["mean"] - c["sem"], c["mean"] + c["sem"], alpha=0.25)
ax.set_xlabel("training episode")
ax.set_ylabel("evaluation return (discounted)")
ax.set_title("Box Pushing 8x8, 3 seeds (mean ± SE)")
ax.legend()
fig.tight_layout()
fig.savefig("py_example.png", dpi=100)
print("wrote py_example.png")

# The trained policy of one run, acting in its own environment as `macdec eval` does.
policy = macdec.Policy.load(runs[-1])
env = policy.make_env()
obs, infos = env.reset(seed=0)
policy.reset()
total = 0.0
while env.agents:
    obs, rewards, terminations, truncations, infos = env.step(policy.act(obs, infos))
    total += rewards["agent_0"]
print(f"{policy}: one greedy episode, undiscounted return {total:.2f}")
