"""Single-state kernels of the controllers (called at every integrator stage, where the
batch drivers' thread start-up would dominate)."""

from __future__ import annotations

import numpy as np

from .._jit import kernel
from ..algorithms._inputs import CHECKED
from ..algorithms.jacobian import jacobian_one
from ..algorithms.rnea import motion_workspace


@kernel
def body_jacobian(ints, body, dofs, q, b, J, oRb, opb):
    """World Jacobian ``J`` (6, nv) of body ``b`` and its world pose; returns a status."""
    ws = motion_workspace(ints.shape[0], dofs.shape[0])
    return jacobian_one(ints, body, dofs, q, q[:0], b, CHECKED, J, oRb, opb, np.empty(6), np.empty(6), ws)
