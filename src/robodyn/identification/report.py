"""Identification report: a text summary and plots (PNG, matplotlib).

``write_report(result, log, directory)`` writes

* ``report.txt``: the estimate (``Identification.summary``: base parameters, standard
  deviations, nominal values), the condition number, RMS torque errors per joint, and the
  base parameters with their singular-value gap;
* ``torques.png``: measured and predicted torque of every joint over time;
* ``residuals.png``: measured minus predicted torque, and its histogram per joint;
* ``singular_values.png``: singular values of the stacked base regressor of the samples
  identified from (``Identification.singular_values``, all logs), condition number in the title.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files import atomic_path, write_text
from .data import Log


def _save(fig, path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90)


def rms_per_joint(pred: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Root-mean-square of ``pred - tau`` per joint (column)."""
    return np.sqrt(np.mean((pred - tau) ** 2, axis=0))


def write_report(result, log: Log, directory, *, validation: Log | None = None) -> list[Path]:
    """Write the report of an :class:`~robodyn.identification.identify.Identification` on the
    log it was identified from (and optionally a ``validation`` log of another motion).
    Writes report.txt, torques.png, residuals.png, singular_values.png and a render of the
    robot (robot.png, :func:`robodyn.viewer.render`). Returns the paths written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    model = result.model
    pred = result.predict(log)
    rms = rms_per_joint(pred, log.tau)
    text = [result.summary(), "", "RMS torque error per joint (identification data):"]
    text += [f"  {name:<20} {r:.6g}" for name, r in zip(model.joint_names, rms)]
    if validation is not None:
        vrms = rms_per_joint(result.predict(validation), validation.tau)
        text += ["", "RMS torque error per joint (validation data):"]
        text += [f"  {name:<20} {r:.6g}" for name, r in zip(model.joint_names, vrms)]
    text += ["", result.base.summary()]
    paths = [out / "report.txt"]
    write_text(paths[0], "\n".join(text) + "\n")

    nv = model.nv
    fig, axes = plt.subplots(nv, 1, figsize=(9, 1.8 * nv + 1), sharex=True, squeeze=False)
    for j, ax in enumerate(axes[:, 0]):
        ax.plot(log.t, log.tau[:, j], lw=0.8, label="measured")
        ax.plot(log.t, pred[:, j], lw=0.8, label="predicted")
        ax.set_ylabel(model.joint_names[j], fontsize="small")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize="small")
    axes[0, 0].set_title(f"Joint torques, {result.estimate.method.upper()} estimate")
    axes[-1, 0].set_xlabel("t [s]")
    fig.tight_layout()
    paths.append(out / "torques.png")
    _save(fig, paths[-1])
    plt.close(fig)

    res = log.tau - pred
    fig, axes = plt.subplots(nv, 2, figsize=(10, 1.8 * nv + 1), squeeze=False,
                             gridspec_kw={"width_ratios": [3, 1]})
    for j in range(nv):
        axes[j, 0].plot(log.t, res[:, j], lw=0.6)
        axes[j, 0].set_ylabel(model.joint_names[j], fontsize="small")
        axes[j, 0].grid(True, alpha=0.3)
        axes[j, 1].hist(res[:, j], bins=40)
        axes[j, 1].set_title(f"RMS {rms[j]:.3g}", fontsize="small")
    axes[0, 0].set_title("Residuals: measured - predicted torque")
    axes[-1, 0].set_xlabel("t [s]")
    fig.tight_layout()
    paths.append(out / "residuals.png")
    _save(fig, paths[-1])
    plt.close(fig)

    s = result.singular_values
    if s is None:  # an Identification made by hand: those of the log's regressor
        s = np.linalg.svd(result.base.regressor(model, log.q, log.v, log.a).reshape(-1, result.base.count),
                          compute_uv=False)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.semilogy(np.arange(1, s.size + 1), s, "o-")
    ax.set_xlabel("index")
    ax.set_ylabel("singular value")
    ax.set_title(f"Base regressor: condition number {result.condition_number:.4g}")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    paths.append(out / "singular_values.png")
    _save(fig, paths[-1])
    plt.close(fig)

    from ..viewer import render  # the robot, at the middle sample of the log (capsule skeleton)

    paths.append(render(model, log.q[len(log.q) // 2], out / "robot.png", size=(480, 360)))
    return paths
