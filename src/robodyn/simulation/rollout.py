"""Batched rollouts: many simulations of one model from many initial states, in parallel.

    R = rd.rollout(model, q0, v0, duration, dt, controller=None, contacts=None)

``q0`` (B, nq) and ``v0`` (B, nv) (either may be one state, broadcast): ``B`` rollouts of the
same robot, controller and contacts, each the time stepping of :func:`robodyn.simulate` with
contacts (with or without them: a step solves ``M (v+ - v) = dt (tau - h) + J^T P``, the
free and planar joints' linear velocities stepped in a frame that does not turn with the body,
see ``_contact_step.moving_frame_terms``; for other joints it is ``simulate``'s
semi-implicit Euler), run on all threads in compiled code (as MuJoCo's ``rollout``). Each
rollout equals the single simulation with contacts from its initial state to the last bit.
The controller must run in compiled code: None, ``control.PDGravity``, ``ComputedTorque`` or
``JointPD``. A model with mimic couplings (:class:`~robodyn.CoupledModel`) is stepped as
:func:`robodyn.simulate` steps it with contacts (its full tree's state on the coupling, the
coupled model's own step), its controller in the independent coordinates.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from .._deprecated import renamed_keyword
from ..algorithms.driver import chunks
from ..algorithms.status import NO_WRENCH, OK
from ..contact import solver as CS
from ..errors import RobodynWarning
from ..coupling import expand_q, expand_v, is_coupled, joint_tree
from . import _contact_runs as CR
from .coupled import run_coupling
from .simulate import law_arrays, compiled_law, positive_number, raise_at, unit_configuration

@dataclass(frozen=True)
class Rollouts:
    """``B`` rollouts sampled at ``t`` (N,): ``q`` (B, N, nq), ``v``, ``a``, ``tau`` (B, N, nv)
    (as :class:`Trajectory`'s); with contacts ``contact_names``, ``contact_force``
    (B, N, npairs, 3), ``contact_distance`` (B, N, npairs), ``contact_normal`` (B, N, npairs,
    3), ``solver_iterations`` and
    ``solver_residual`` (B, N)."""

    model: object = field(repr=False)
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    contact_names: tuple = ()
    contact_force: np.ndarray | None = None
    contact_distance: np.ndarray | None = None
    contact_normal: np.ndarray | None = None
    solver_iterations: np.ndarray | None = None
    solver_residual: np.ndarray | None = None


def _states(name, x, n):
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(x).__name__}") from None
    if a.ndim not in (1, 2) or a.shape[-1] != n:
        raise ValueError(f"{name}: expected shape (B, {n}) or ({n},), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or Inf")
    return a.reshape(-1, n)


def _bodies(model, theta, B: int) -> np.ndarray:
    """The body table of each rollout (B or 1, nb, BODY_COLUMNS) with its inertial parameters."""
    from ..layout import INERTIA, INERTIA_END
    from ..model import consistent_inertial_parameters

    body = joint_tree(model).kernel.body
    if theta is None:
        return body[None]
    try:
        theta = np.array(theta, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"theta: expected an array of numbers, got {type(theta).__name__}") from None
    if theta.ndim != 3 or theta.shape[0] not in (1, B) or theta.shape[1:] != (model.nbodies, 10):
        raise ValueError(f"theta: expected shape ({B}, {model.nbodies}, 10), got {theta.shape}")
    good = consistent_inertial_parameters(theta.reshape(-1, 10)).reshape(theta.shape[:2])
    if not good.all():
        b, i = (int(x) for x in np.argwhere(~good)[0])
        raise ValueError(f"theta: rollout {b}, body {i} ({model.link_names[i]!r}): {theta[b, i].tolist()} are not "
                         f"the inertial parameters of a rigid body (mass >= 0, inertia about the centre of mass "
                         f"positive semi-definite with the triangle inequality)")
    bodies = np.repeat(body[None], theta.shape[0], axis=0)
    bodies[:, :, INERTIA:INERTIA_END] = theta
    return bodies


def rollout(model, q0, v0, duration: float, dt: float, controller=None, *, contacts=None, every: int = 1,
            theta=None, inertia=None) -> Rollouts:
    """``B`` simulations of ``duration`` seconds with steps of ``dt`` from the initial states
    ``q0`` (B, nq) and ``v0`` (B, nv) (one of them may be a single state), in parallel (see
    the module docstring), keeping every ``every``-th sample (times ``k every dt``; the steps'
    accelerations, torques and contact forces at those samples), so that long batches fit in
    memory. ``theta``: None, or (B, nbodies, 10) the inertial parameters of each rollout's
    robot (``Model.theta``'s layout; checked as a model's are): Monte Carlo over masses and
    inertias, the controller keeping its own model. Raises for the first rollout that fails
    (naming it and the time); warns, as :func:`robodyn.simulate`, when contact solves stopped
    above ``warn_above``."""
    if inertia is not None:  # the old spelling of ``theta``
        theta = renamed_keyword("inertia", inertia, "theta", theta, "rollout()", default=None)
    q0, v0 = _states("q0", q0, model.nq), _states("v0", v0, model.nv)
    B = max(q0.shape[0], v0.shape[0], np.shape(theta)[0] if np.ndim(theta) == 3 else 1)
    if q0.shape[0] not in (1, B) or v0.shape[0] not in (1, B):
        raise ValueError(f"q0, v0: {q0.shape[0]} and {v0.shape[0]} states do not broadcast")
    bodies = _bodies(model, theta, B)
    duration, dt = positive_number("duration", duration), positive_number("dt", dt)
    if dt > duration:
        raise ValueError(f"dt: must not exceed duration ({duration}), got {dt}")
    compiled = (0, None, None, None, None) if controller is None else compiled_law(controller)
    if compiled is None:
        raise ValueError(f"controller: rollout runs compiled control laws only (None, PDGravity, ComputedTorque, "
                         f"JointPD), got {type(controller).__name__}; use rd.simulate for other controllers")
    cmodel = getattr(controller, "model", model)
    if (cmodel.nq, cmodel.nv) != (model.nq, model.nv):
        raise ValueError(f"controller: its model has nq={cmodel.nq}, nv={cmodel.nv}; the simulated model has "
                         f"nq={model.nq}, nv={model.nv}")
    tree = joint_tree(model)
    if contacts is not None:
        from ..contact.geometry import Contacts

        if not isinstance(contacts, Contacts):
            raise ValueError(f"contacts: expected a robodyn.contact.Contacts or None, got {type(contacts).__name__}")
        (points, centers, radii), surf, settings, names = contacts.pack(tree)
    else:
        points, centers, radii = np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0)
        surf, settings, names = np.zeros((0, CS.SURFACE_COLUMNS)), np.array([1.0, 1.0, 0.0, 0.0, 0.0, 0.0]), ()
    n = max(1, int(round(duration / dt)))
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1 or n % every:
        raise ValueError(f"every: expected an integer >= 1 dividing the {n} steps, got {every!r}")
    N, npairs = n // every + 1, len(names)
    Q, V = np.empty((B, N, tree.nq)), np.empty((B, N, tree.nv))
    if is_coupled(model):  # the full tree's state on the coupling
        q0, v0 = expand_q(model, q0), expand_v(model, v0)
    Q[:, 0] = q0
    V[:, 0] = v0
    unit_configuration(tree, Q[:, 0])
    A, T = np.zeros((B, N, tree.nv)), np.zeros((B, N, tree.nv))
    Fc, D, info = np.zeros((B, N, npairs, 3)), np.zeros((B, N, npairs, 4)), np.zeros((B, N, CS.INFO_SIZE))
    failed, status = np.zeros(B, np.int64), np.zeros(B, np.int64)
    k = tree.kernel
    c, law, gains, breaks, coefs = law_arrays(model, compiled)
    coupling = run_coupling(model) if is_coupled(model) else (None,) * 4
    args = (k.ints, bodies, k.dofs[True, True], k.params[True], k.zero_wrench, NO_WRENCH,
            np.ascontiguousarray(tree.effort_limit),
            *c, law, gains, breaks, coefs, np.zeros(model.nv), points, centers, radii, surf, settings, dt, int(every),
            0, True, Q, V, A, T, Fc, D, info, np.zeros((B, npairs, 3)), failed, *coupling)
    CR.run_batch(args, tree, model if is_coupled(model) else None, cmodel, npairs, int(every), status, chunks(B))
    bad = np.flatnonzero(status != OK)
    if bad.size:
        b = int(bad[0])
        s, k = int(failed[b]), int(failed[b]) // every
        try:
            raise_at(tree, int(status[b]), s * dt, Q[b, k], V[b, k], T[b, k], is_coupled(model))
        except ValueError as e:
            raise ValueError(f"rollout {b}: {e}") from None
    t = np.arange(0, n + 1, every) * dt
    if is_coupled(model):  # read in the independent coordinates
        iq, iv = model.independent_q, model.independent_v
        Q, V, A, T = Q[..., iq], V[..., iv], A[..., iv], T[..., iv]
    if contacts is None:
        return Rollouts(model, t, Q, V, A, T)
    residual = info[..., CS.RESIDUAL]
    worst = np.unravel_index(np.argmax(residual), residual.shape)
    if residual[worst] > contacts.warn_above:
        warnings.warn(f"rollout: the contact solver stopped above {contacts.warn_above:g} m/s in "
                      f"{int((residual > contacts.warn_above).sum())} of {residual.size} steps (largest residual "
                      f"{residual[worst]:.3g} m/s in rollout {worst[0]} at t = {t[worst[1]]:.6g})",
                      RobodynWarning, stacklevel=2)
    return Rollouts(model, t, Q, V, A, T, names, Fc, D[..., 0], D[..., 1:], info[..., CS.ITERATIONS].astype(np.int64),
                    residual)
