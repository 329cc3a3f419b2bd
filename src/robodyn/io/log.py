"""The CSV format of trajectories: written by ``Trajectory.to_csv`` (``robodyn simulate --csv``),
read by :func:`read_csv` (``robodyn torques``, reference trajectories of the controllers).

CSV format (one header line, comma-separated, one row per sample, SI units)::

    t, q[0], ..., q[nq-1], v[0], ..., v[nv-1], a[0], ..., tau[0], ..., energy, lyapunov

Columns are named ``t``, ``q:<name>``, ``v:<name>``, ``a:<name>``, ``tau:<name>`` with the
names of :func:`coordinate_names` (joint names; a free joint's
entries are ``<joint>:x, :y, :z, :qx, :qy, :qz, :qw`` in ``q`` and ``<joint>:vx ... :wz`` in
``v``), then ``energy`` and, when the controller has one, ``lyapunov``. :func:`read_csv`
needs only ``t`` and the ``q`` columns (``v`` and ``a`` are then obtained by
differentiating a cubic spline through ``q``): a hand-made file ``t, q:joint1, q:joint2``
works as well as the output of ``robodyn simulate --csv``.
"""

from __future__ import annotations

import csv

import numpy as np

from .. import joints as J



def coordinate_names(model) -> tuple[list[str], list[str]]:
    """Names of the entries of ``q`` (nq) and of ``v`` (nv), in order."""
    return (J.coordinate_names(model.joint_type, model.body_joint_names, "q", ":"),
            J.coordinate_names(model.joint_type, model.body_joint_names, "v", ":"))


def read_csv(model, path):
    """``(t, q, v, a)`` of a trajectory file (format in the module docstring).

    ``t`` must increase strictly; ``q`` columns are required (``q:<name>`` for every entry
    of ``q``). ``v`` and ``a`` are read when all their columns are there, otherwise obtained
    from a cubic spline through ``q`` (1-dof joints only).
    """
    from scipy.interpolate import CubicSpline

    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except (UnicodeDecodeError, csv.Error) as e:
        raise ValueError(f"{path}: not a CSV text file ({e})") from None
    if len(rows) < 3:
        raise ValueError(f"{path}: need a header line and at least 2 samples, got {max(len(rows) - 1, 0)} samples")
    header = [h.strip() for h in rows[0]]
    try:
        data = np.array([[float(x) for x in r] for r in rows[1:] if r], dtype=float)
    except ValueError as e:
        raise ValueError(f"{path}: non-numeric entry ({e})") from None
    if data.ndim != 2 or data.shape[1] != len(header):
        raise ValueError(f"{path}: every row needs {len(header)} entries (the header's)")
    if not np.all(np.isfinite(data)):
        raise ValueError(f"{path}: contains NaN or Inf")
    index = {h: k for k, h in enumerate(header)}
    if "t" not in index:
        raise ValueError(f"{path}: no 't' column; header is {header}")
    t = data[:, index["t"]]
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{path}: times must increase strictly")
    qn, vn = coordinate_names(model)

    def block(prefix, names, required):
        missing = [f"{prefix}:{n}" for n in names if f"{prefix}:{n}" not in index]
        if missing and required:
            raise ValueError(f"{path}: missing columns {missing} for model {model.name!r}")
        return None if missing else data[:, [index[f"{prefix}:{n}"] for n in names]]

    q = block("q", qn, True)
    v, a = block("v", vn, False), block("a", vn, False)
    if v is None or a is None:
        if model.nq != model.nv:
            raise ValueError(f"{path}: a floating-base trajectory needs its v and a columns")
        spline = CubicSpline(t, q, axis=0)
        v = spline(t, 1) if v is None else v
        a = spline(t, 2) if a is None else a
    return t, q, v, a
