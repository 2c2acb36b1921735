"""The PNG figures of ``workstation evaluate`` (the paper's Figs. 5–9 on the simulated office)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workstation.fingerprints.localize import Metric
from workstation.io.atomic import save_figure

if TYPE_CHECKING:  # (the simulator and the baselines are loaded only when it runs)
    from workstation.evaluate.paper import Simulated


def _save(fig, out: Path, figs: dict[str, str], name: str) -> None:
    import matplotlib.pyplot as plt

    figs[name] = f"{name}.png"
    fig.tight_layout()
    save_figure(fig, out / figs[name], dpi=110)
    plt.close(fig)


def figures(sim: Simulated, out: Path) -> dict[str, str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figs: dict[str, str] = {}
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, e in sim.trajectory_error_samples.items():
        e = np.sort(e)
        ax.plot(e, np.arange(1, e.size + 1) / e.size, label=f"{name} ({e.mean():.2f} m)")
    ax.set_xscale("symlog", linthresh=1.0)
    ax.set_xlabel("trajectory error (m)")
    ax.set_ylabel("CDF")
    ax.set_title("Fig. 5 — trajectory error per method (simulated office, normal walk)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    _save(fig, out, figs, "fig5_trajectory_cdf")

    rows = [r for r in sim.belief_bins if "mean_m" in r.errors]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.5))
    for bel, e in sim.belief_scatter:
        ax1.scatter(np.minimum(bel, 150), e, s=8, alpha=0.6)
    eps = sim.rp_error_by_belief.threshold
    ax1.axvline(eps, color="r", lw=1, label=f"ε_S = {eps:g}")
    ax1.set_xlabel("belief of the segment (capped at 150)")
    ax1.set_ylabel("reference point position error (m)")
    ax1.legend(fontsize=7)
    ax2.plot([r.belief for r in rows], [r.errors["mean_m"] for r in rows], marker="o")
    ax2.set_xlabel("radio map from segments with belief")
    ax2.set_ylabel("mean 1-NN error (m)")
    fig.suptitle("Fig. 6 — belief vs reference-point error and 1-NN error (normal + varied walks)")
    _save(fig, out, figs, "fig6_belief")

    names = list(sim.radio_maps)
    for key, label, fname in (
        ("floor_accuracy", "floor accuracy (%)", "fig7_floor_accuracy"),
        ("mean_m", "mean 1-NN error (m)", "fig8_mean_error"),
    ):
        fig, ax = plt.subplots(figsize=(6, 3.5))
        xs = np.arange(len(names))
        for i, metric in enumerate(Metric):
            vals = [sim.radio_maps[n].under(metric).get(key) or 0 for n in names]
            if key == "floor_accuracy":
                vals = [100 * v for v in vals]
            ax.bar(xs + (i - 0.5) * 0.38, vals, 0.38, label=metric.value)
        ax.set_xticks(xs, names, fontsize=7)
        ax.set_ylabel(label)
        ax.set_title(f"Fig. {7 if key == 'floor_accuracy' else 8} — {label}, τ = −90 dBm")
        ax.legend(fontsize=7)
        _save(fig, out, figs, fname)

    fig, ax = plt.subplots(figsize=(6, 3.5))
    for name, sweep in sim.tau_sweep_sorensen_mean_m.items():
        ax.plot(
            list(sweep),
            [v if v is not None else np.nan for v in sweep.values()],
            marker="o",
            label=name,
        )
    ax.set_xlabel("τ (dBm)")
    ax.set_ylabel("mean 1-NN error (m), Sørensen")
    ax.set_title("Fig. 9 — effect of the RSS threshold τ")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    _save(fig, out, figs, "fig9_tau")
    return figs
