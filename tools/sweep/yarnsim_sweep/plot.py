"""The sweep's plot: a reduction over one parameter (lines, one per
combination of the other varied names) or two (heat map; other varied
names are averaged, failed points are blank)."""
import os

import numpy as np


def plot_sweep(sweep, df, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    p = sweep.plot
    value, x, y = p["value"], p["x"], p.get("y")
    path = os.path.join(out, p.get("file", "plot.png"))
    df = df.copy()
    df.loc[df["status"] != "ok", value] = np.nan
    fig, ax = plt.subplots(figsize=(6.4, 4.8), constrained_layout=True)
    if y is None:
        others = [n for n in sweep.varied if n != x]
        groups = df.groupby(others, dropna=False, sort=True) if others else [((), df)]
        for key, g in groups:
            g = g.sort_values(x)
            key = key if isinstance(key, tuple) else (key,)
            label = ", ".join(f"{n} = {v}" for n, v in zip(others, key)) or None
            ax.plot(g[x].to_numpy(), g[value].to_numpy(), marker="o", label=label)
        ax.set_xlabel(x)
        ax.set_ylabel(value)
        if others:
            ax.legend(fontsize="small")
    else:
        table = df.pivot_table(index=y, columns=x, values=value, aggfunc="mean", dropna=False)
        data = table.to_numpy(dtype=float)
        if p.get("log_value"):
            data = np.log10(np.abs(data))
        im = ax.imshow(np.ma.masked_invalid(data), origin="lower", aspect="auto", cmap="viridis")
        ax.set_xticks(range(len(table.columns)), [f"{v:g}" if isinstance(v, float) else str(v) for v in table.columns], rotation=45)
        ax.set_yticks(range(len(table.index)), [f"{v:g}" if isinstance(v, float) else str(v) for v in table.index])
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        fig.colorbar(im, ax=ax, label=("log10 |" + value + "|") if p.get("log_value") else value)
    ax.set_title(p.get("title", os.path.basename(sweep.path)))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
