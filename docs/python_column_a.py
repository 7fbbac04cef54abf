# %% [markdown]
# # Column A from Python: gains, a Dask sweep, a plot
#
# A notebook in script form (cells marked `# %%`; open it in Jupyter with jupytext or VS Code, or
# run it: `python docs/python_column_a.py`; CI runs it this way). Install the package first:
#
#     pip install crates/python numpy matplotlib "dask[distributed]"
#
# Column A (Skogestad & Postlethwaite, *Multivariable Feedback Control*, §12.4): 41 stages,
# α = 1.5, LV configuration with P level loops. (Each cell runs under `if __name__ == "__main__"`: the
# Dask workers of a process-based LocalCluster import this file again and must not run the cells.)

# %%
if __name__ == "__main__":  # Dask's worker processes import this file: they must not run the cells
    import os
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")  # files, no display
    import matplotlib.pyplot as plt
    import numpy as np
    import plantwide as pw

    REPO = Path(__file__).resolve().parents[1]
    OUT = Path(os.environ.get("PLANTWIDE_EXAMPLE_OUT", REPO / "target" / "python_example"))
    OUT.mkdir(parents=True, exist_ok=True)
    COLUMN_A = REPO / "flowsheets" / "column_a.json"

# %% [markdown]
# ## Steady state and LV gains
#
# `steady()` is `plantwide steady --json`: every variable under its path, in SI.

# %%
if __name__ == "__main__":
    plant = pw.load(COLUMN_A)
    ss = plant.steady()
    print(f"yD = {ss['distillate.x[light]']:.4f}, xB = {ss['bottoms.x[light]']:.4f}")

    inputs = ["column.reflux@kmol/min", "column.boilup@kmol/min"]
    outputs = ["distillate.x[light]", "bottoms.x[light]"]
    g = plant.gains(inputs, outputs)
    print("G(0) =\n", np.array2string(g.gain, precision=4))
    print(f"λ11 = {g.rga[0, 0]:.2f}, Niederlinski = {g.niederlinski:.4f}, condition number = {g.condition_number:.1f}")
    # S&P eq. 12.17 (idealized LV model): [0.878 −0.864; 1.082 −1.096], λ11 = 35.1.
    assert np.allclose(g.gain, [[0.878, -0.864], [1.082, -1.096]], rtol=0.03)

# %% [markdown]
# ## A feed-rate sweep on a Dask cluster
#
# Each point is an independent task carrying the flowsheet text and its `set`; the workers load
# the plant themselves. The same call without `client=` runs the points in this process.

# %%
if __name__ == "__main__":
    from dask.distributed import Client, LocalCluster

    feeds = np.linspace(0.9, 1.1, 9)  # kmol/min
    sets = [{"feed_source.F": f"{f} kmol/min"} for f in feeds]
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            on_cluster = pw.sweep(COLUMN_A, sets=sets, outputs=outputs, client=client)
    in_process = pw.sweep(COLUMN_A, sets=sets, outputs=outputs)
    assert np.array_equal(on_cluster, in_process), "where a point runs does not change a digit"
    for f, (yd, xb) in zip(feeds, on_cluster):
        print(f"F = {f:.3f} kmol/min: yD = {yd:.5f}, xB = {xb:.5f}")

# %% [markdown]
# ## The plot

# %%
if __name__ == "__main__":
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogy(feeds, 1 - on_cluster[:, 0], "o-", label="1 − yD (distillate impurity)")
    ax.semilogy(feeds, on_cluster[:, 1], "s-", label="xB (bottoms impurity)")
    ax.set_xlabel("feed rate F [kmol/min] (L, V fixed)")
    ax.set_ylabel("impurity [mol/mol]")
    ax.set_title("Column A, LV: steady states over the feed rate")
    ax.legend()
    fig.tight_layout()
    figure = OUT / "column_a_feed_sweep.png"
    fig.savefig(figure, dpi=100)
    print(f"wrote {figure}")
