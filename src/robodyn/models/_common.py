"""Helpers shared by the built-in robots: inertias from their upper triangle and extra frames
(the inertias of uniform bodies are in :mod:`robodyn.inertia`)."""

from __future__ import annotations

import numpy as np

from ..model import Model


def inertia_from_upper(ixx: float, ixy: float, ixz: float, iyy: float, iyz: float, izz: float) -> np.ndarray:
    """Symmetric 3 x 3 inertia from its upper triangle, row by row."""
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def with_frame(model: Model, name: str, parent: str, xyz=(0.0, 0.0, 0.0)) -> Model:
    """``model`` with one more frame ``name``, placed at ``xyz`` in the existing frame
    ``parent`` (same orientation), on the body that carries ``parent``."""
    body, R, p = model.frame_index(parent)
    # Copies: Model.__init__ normalises the axes and fills the limits in place, and the
    # model's own arrays are read-only (Model.replace passes them as they are).
    return model.replace(
        joint_axis=model.joint_axis.copy(), lower=model.lower.copy(), upper=model.upper.copy(),
        frame_names=model.frame_names + (name,),
        frame_body=np.append(model.frame_body, body),
        frame_R=np.concatenate([model.frame_R, R[None]]),
        frame_p=np.concatenate([model.frame_p, (p + R @ np.asarray(xyz, dtype=float))[None]]),
    )


def homogeneous(R) -> np.ndarray:
    """4 x 4 transform of a pure rotation (the ``base`` argument of :func:`robodyn.from_dh`)."""
    T = np.eye(4)
    T[:3, :3] = R
    return T
