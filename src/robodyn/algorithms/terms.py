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


def _rnea_term(model, q, v, a, check_finite, gravity, armature, what) -> np.ndarray:
    """``rnea`` without friction, with ``v``/``a`` replaced by zeros where ``None``."""
    arrays = {"q": q, **({"v": v} if v is not None else {}), **({"a": a} if a is not None else {})}
    batch, x = _inputs.states(model, **arrays)
    zeros = np.zeros(batch + (model.nv,)).reshape(-1, model.nv) if batch else np.zeros(model.nv)
    x.setdefault("v", zeros)
    x.setdefault("a", zeros)
    F, fcode = _inputs.body_wrenches(model, None, batch, "local")
    return run(model, batch, x, F, fcode, check_finite, gravity=gravity, friction=False, armature=armature, what=what)


def gravity(model, q, *, check_finite: bool = True) -> np.ndarray:
    """Generalised gravity ``g(q)`` (..., nv): the joint forces that hold the robot still."""
    return _rnea_term(model, q, None, None, check_finite, True, False, "gravity")


def nonlinear_effects(model, q, v, *, check_finite: bool = True) -> np.ndarray:
    """``C(q, v) v + g(q)`` (..., nv), the Coriolis, centrifugal and gravity forces."""
    return _rnea_term(model, q, v, None, check_finite, True, False, "nonlinear_effects")


def generalized_momentum(model, q, v, *, armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Generalised momentum ``M(q) v`` (..., nv), O(n) (``armature`` as in :func:`robodyn.crba`)."""
    return _rnea_term(model, q, None, v, check_finite, False, armature, "generalized_momentum")
