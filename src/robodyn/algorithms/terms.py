"""Terms of the equation of motion ``M(q) qdd + C(q, v) v + g(q) = tau``, from the RNEA, and
their derivatives, from the RNEA's (``rnea_derivatives.py``).

    gravity(q)                 = rnea(q, 0, 0)          = g(q)
    nonlinear_effects(q, v)    = rnea(q, v, 0)          = C(q, v) v + g(q)
    generalized_momentum(q, v) = rnea(q, 0, v) - g(q)   = M(q) v   (gravity switched off)

All without friction (these are the rigid-body terms; :func:`robodyn.rnea` adds friction).
Derivatives with respect to ``q`` are in the tangent space of :func:`robodyn.integrate`.
"""

from __future__ import annotations

import numpy as np

from ..coupling import expand_q, expand_v, reduce_force, reduce_matrix
from ._lazy import any_lazy, deferred
from . import _inputs
from .rnea import run as _rnea_run
from .rnea_derivatives import run as _derivatives_run


def _rnea_term(model, what, check_finite, gravity, armature, given, roles, run=_rnea_run, **options):
    """``run`` (the RNEA, or its derivatives) without friction on the caller's arrays ``given``
    (by their names), with ``roles`` mapping the kernel's ``v``/``a`` to a given name (missing:
    zeros). For a coupled model (mimic joints), the full tree's terms mapped by ``G``: forces
    ``G^T f``, matrices ``G^T D G`` (see ``robodyn.coupling``)."""
    batch, x = _inputs.states(model, **given)
    try:
        F, fcode = _inputs.body_wrenches(model, None, batch, "local")  # reads the kernel tables
    except AttributeError:  # a CoupledModel, which has none
        full = {name: expand_q(model, x) if name == "q" else expand_v(model, x, name) for name, x in given.items()}
        result = _rnea_term(model.full, what, check_finite, gravity, armature, full, roles, run, **options)
        if run is _rnea_run:
            return reduce_force(model, result)
        return tuple(reduce_matrix(model, D) if D.shape[-1] else D for D in result)  # (0, 0): not computed
    zeros = np.zeros(model.nv) if batch == () else np.zeros((x["q"].shape[0], model.nv))
    kin = {"q": x["q"], **{role: x[name] if name else zeros for role, name in roles.items()}}
    return run(model, batch, kin, F, fcode, check_finite, gravity=gravity, friction=False, armature=armature,
               what=what, report=x, **options)


def gravity(model, q, *, check_finite: bool = True) -> np.ndarray:
    """Generalised gravity ``g(q)`` (..., nv): the joint forces that hold the robot still."""
    if any_lazy(q):
        return deferred(gravity, locals())
    return _rnea_term(model, "gravity", check_finite, True, False, {"q": q}, {"v": None, "a": None})


def nonlinear_effects(model, q, v, *, check_finite: bool = True) -> np.ndarray:
    """``C(q, v) v + g(q)`` (..., nv), the Coriolis, centrifugal and gravity forces."""
    if any_lazy(q, v):
        return deferred(nonlinear_effects, locals())
    return _rnea_term(model, "nonlinear_effects", check_finite, True, False, {"q": q, "v": v}, {"v": "v", "a": None})


def generalized_momentum(model, q, v, *, armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Generalised momentum ``M(q) v`` (..., nv), O(n) (``armature`` as in :func:`robodyn.crba`)."""
    if any_lazy(q, v):
        return deferred(generalized_momentum, locals())
    return _rnea_term(model, "generalized_momentum", check_finite, False, armature, {"q": q, "v": v},
                      {"v": None, "a": "v"})


def gravity_derivatives(model, q, *, check_finite: bool = True) -> np.ndarray:
    """``dg/dq`` (..., nv, nv) of :func:`robodyn.gravity` (Pinocchio's
    ``computeGeneralizedGravityDerivatives``)."""
    if any_lazy(q):
        return deferred(gravity_derivatives, locals())
    return _rnea_term(model, "gravity_derivatives", check_finite, True, False, {"q": q}, {"v": None, "a": None},
                      _derivatives_run, mass=False)[0]


def nonlinear_effects_derivatives(model, q, v, *, check_finite: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """``(d/dq, d/dv)`` (..., nv, nv) of ``C(q, v) v + g(q)`` (:func:`robodyn.nonlinear_effects`)."""
    if any_lazy(q, v):
        return deferred(nonlinear_effects_derivatives, locals())
    return _rnea_term(model, "nonlinear_effects_derivatives", check_finite, True, False, {"q": q, "v": v},
                      {"v": "v", "a": None}, _derivatives_run, mass=False)[:2]


def generalized_momentum_derivatives(model, q, v, *, armature: bool = True,
                                     check_finite: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """``(d(M v)/dq, M)`` (..., nv, nv) of :func:`robodyn.generalized_momentum` (``d(M v)/dv =
    M``, with the armature when ``armature``)."""
    if any_lazy(q, v):
        return deferred(generalized_momentum_derivatives, locals())
    dq, _, M = _rnea_term(model, "generalized_momentum_derivatives", check_finite, False, armature,
                          {"q": q, "v": v}, {"v": None, "a": "v"}, _derivatives_run)
    return dq, M

