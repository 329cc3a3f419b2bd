"""Terms of the equation of motion ``M(q) qdd + C(q, v) v + g(q) = tau``, from the RNEA.

    gravity(q)                 = rnea(q, 0, 0)          = g(q)
    nonlinear_effects(q, v)    = rnea(q, v, 0)          = C(q, v) v + g(q)
    generalized_momentum(q, v) = rnea(q, 0, v) - g(q)   = M(q) v   (gravity switched off)

All without friction (these are the rigid-body terms; :func:`robodyn.rnea` adds friction).
"""

from __future__ import annotations

import numpy as np

from . import _inputs
from .rnea import run


def _rnea_term(model, q, v, a, check_finite, gravity, armature=False) -> np.ndarray:
    """``rnea`` without friction, with ``v``/``a`` replaced by zeros where ``None``."""
    arrays = {"q": q, **({"v": v} if v is not None else {}), **({"a": a} if a is not None else {})}
    batch, flat = _inputs.states(model, check_finite, **arrays)
    Z = np.zeros((flat["q"].shape[0], model.nv))
    F = np.zeros((1, model.nbodies, 6))
    TAU = run(model, flat["q"], flat.get("v", Z), flat.get("a", Z), F, -1, gravity, model._dof(False, armature))
    return _inputs.unflatten(TAU, batch)


def gravity(model, q, *, check_finite: bool = True) -> np.ndarray:
    """Generalised gravity ``g(q)`` (..., nv): the joint forces that hold the robot still."""
    return _rnea_term(model, q, None, None, check_finite, model.gravity)


def nonlinear_effects(model, q, v, *, check_finite: bool = True) -> np.ndarray:
    """``C(q, v) v + g(q)`` (..., nv), the Coriolis, centrifugal and gravity forces."""
    return _rnea_term(model, q, v, None, check_finite, model.gravity)


def generalized_momentum(model, q, v, *, armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Generalised momentum ``M(q) v`` (..., nv), O(n) (``armature`` as in :func:`robodyn.crba`)."""
    return _rnea_term(model, q, None, v, check_finite, np.zeros(3), armature)
