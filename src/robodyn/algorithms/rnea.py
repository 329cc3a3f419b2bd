"""Inverse dynamics by the Recursive Newton-Euler Algorithm (RBDA Table 5.1), O(n).

    tau = M(q) a + C(q, v) v + g(q) - sum_i J_i(q)^T f_ext_i  [+ armature a + friction(v)]

Pass 1 (root to leaves), in body coordinates, with gravity as a fictitious base acceleration
``a_0 = -g``::

    v_i = iX_p v_p + S_i qd_i
    a_i = iX_p a_p + S_i qdd_i + v_i x S_i qd_i
    f_i = I_i a_i + v_i x* I_i v_i - f_ext_i

Pass 2 (leaves to root)::

    tau_i = S_i^T f_i (+ armature, friction),   f_p += iX_p^T f_i
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64

from .._deprecated import renamed_keyword
from .._jit import INTS, MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, core, fast, inline, scratch
from ..layout import ARMATURE, GRAVITY, INERTIA, INERTIA_END, IQ, IV, JTYPE, MOTION, NDOF, PARENT, SMOOTHING, UNIT_AXIS
from ..joint_kernels import body_placement, nq_of, passive_torque
from ..spatial import (force_act, force_cross, inertia_mul, momentum, motion_act_inv, motion_cross, motion_cross_unit,
                       wrench_to_local)
from ..coupling import is_coupled
from ..coupling_kernels import expand_positions, expand_velocity, reduce_vector
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status
from ._workspace import POSES_SIZE, POSES_SIZE_NB, poses, take, view
from ._inputs import coupled_one_state, fits, unpack
from .status import BAD_QUATERNION, NO_WRENCH, NONFINITE, OK, WRONG_SIZE, finite, result_status
from .kinematics import world_placement
from .driver import batch_kernel


@inline
def workspace_views(buf, nb):
    """The scratch arrays of :func:`rnea_state` carved from ``buf`` (see :func:`workspace`),
    after ``buf`` itself (which an ``inline`` function may not return: see ``_jit``)."""
    P, o = poses(buf, 0, nb)
    vel, o = take(buf, o, (nb, 6))
    acc, o = take(buf, o, (nb, 6))
    f, o = take(buf, o, (nb, 6))
    vJ, o = take(buf, o, (6,))
    t1, o = take(buf, o, (6,))
    t2, o = take(buf, o, (6,))
    return (P, vel, acc, f, vJ, t1, t2)


@scratch
def buffer(nb):
    """``(buffer,)``: the memory of :func:`workspace`, the workspace of the batch code (which
    carves the views once per chunk, :func:`rnea_views`)."""
    return (np.empty((POSES_SIZE_NB + 18) * nb + POSES_SIZE + 18),)


@scratch
def workspace(nb):
    """Scratch of :func:`rnea_one`: ``(buffer, (liR, lip, oR, op, Rj, pj), vel, acc, f, vJ, t1, t2)``."""
    buf = buffer(nb)[0]
    return (buf,) + workspace_views(buf, nb)


@scratch
def motion_workspace(nb, nv):
    """Workspace of a velocity/acceleration pass at ``qdd = 0`` without gravity (used by the
    Jacobian derivative and the energies): placements, world poses, motion, zeros."""
    return (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3, 3)), np.empty((nb, 3)),
            np.empty((3, 3)), np.empty(3), np.empty((nb, 6)), np.empty((nb, 6)), np.empty(6), np.empty(6),
            np.empty(6), np.zeros(nv), np.zeros(3))


@inline
def base_acceleration(grav, a0):
    """``a0 = [-g; 0]``: gravity as a fictitious acceleration of the base (RBDA 5.3); ``grav``
    is the kernels' ``params`` (gravity at ``GRAVITY``)."""
    for k in range(6):
        a0[k] = 0.0
    a0[0], a0[1], a0[2] = -grav[GRAVITY], -grav[GRAVITY + 1], -grav[GRAVITY + 2]


@inline
def motion_step(i, par, dofs, iv, n, axis, R, p, v, a, vel, acc, a0, vJ, t1):
    """Velocity ``vel[i]`` and acceleration ``acc[i]`` of body ``i`` from its parent's (or
    from the base acceleration ``a0`` for a root), ``(R, p)`` its placement in the parent:
    ``v_i = iX_p v_p + S qd``, ``a_i = iX_p a_p + S qdd + v_i x S qd``; ``axis`` >= 0 when
    ``S = e_axis`` (see ``layout.pack``)."""
    if par >= 0:
        motion_act_inv(R, p, vel[par], vel[i])
        motion_act_inv(R, p, acc[par], acc[i])
    else:
        vel[i, :] = 0.0
        motion_act_inv(R, p, a0, acc[i])
    if axis >= 0:
        vel[i, axis] += v[iv]
        acc[i, axis] += a[iv]
        motion_cross_unit(vel[i], axis, v[iv], t1)
        for r in range(6):
            acc[i, r] += t1[r]
        return
    for r in range(6):
        vJ[r] = 0.0
    for k in range(iv, iv + n):
        for r in range(6):
            vJ[r] += dofs[k, MOTION + r] * v[k]
            acc[i, r] += dofs[k, MOTION + r] * a[k]
    for r in range(6):
        vel[i, r] += vJ[r]
    motion_cross(vel[i], vJ, t1)
    for r in range(6):
        acc[i, r] += t1[r]


@inline
def motion_pass(ints, dofs, liR, lip, v, a, grav, vel, acc, vJ, t1, a0):
    """Body velocities ``vel`` and accelerations ``acc`` (nb, 6) in body coordinates, with the
    base accelerating at ``-grav`` (pass ``grav = 0`` for the true accelerations)."""
    base_acceleration(grav, a0)
    for i in range(ints.shape[0]):
        motion_step(i, ints[i, PARENT], dofs, ints[i, IV], ints[i, NDOF], ints[i, UNIT_AXIS], liR[i], lip[i], v, a,
                    vel, acc, a0, vJ, t1)


@inline
def rnea_state(ints, body, dofs, params, q, v, a, fext, fcode, check, tau, ws):
    """Inverse dynamics of one state into ``tau`` (nv,); returns a status (see ``_inputs``).

    ``params = [gravity (3), Coulomb smoothing]``; ``fcode < 0``: no external wrench.
    Inlined into :func:`rnea_one` (one state, for other kernels) and :func:`rnea_at` (the
    batch code, which ``rnea`` runs for a single state too, as a batch of one; a call per
    state would cost more than a tenth of the work).
    """
    _, (liR, lip, oR, op, Rj, pj), vel, acc, f, vJ, t1, t2 = ws
    nb, nv = ints.shape[0], dofs.shape[0]
    if not (q.shape[0] == nq_of(ints) and v.shape[0] == nv and a.shape[0] == nv):
        return WRONG_SIZE
    if check and not (finite(q) and finite(v) and finite(a)):
        return NONFINITE
    # Pass 1 (one sweep from the root): placements, motion, body forces
    base_acceleration(params, t2)
    for i in range(nb):
        par = ints[i, PARENT]
        if not body_placement(ints[i, JTYPE], body[i], q, ints[i, IQ], liR[i], lip[i], Rj):
            return BAD_QUATERNION
        if fcode > 0:
            world_placement(i, par, liR, lip, oR, op)
        motion_step(i, par, dofs, ints[i, IV], ints[i, NDOF], ints[i, UNIT_AXIS], liR[i], lip[i], v, a, vel, acc, t2,
                    vJ, t1)
        theta = body[i, INERTIA:INERTIA_END]
        inertia_mul(theta, acc[i], f[i])
        force_cross(vel[i], momentum(theta, vel[i]), vJ)
        for r in range(6):
            f[i, r] += vJ[r]
        if fcode >= 0:
            wrench_to_local(fcode, oR[i], op[i], fext[i], t1)
            for r in range(6):
                f[i, r] -= t1[r]
    # Pass 2: joint torques and forces transmitted to the parents
    eps = params[SMOOTHING]
    for i in range(nb - 1, -1, -1):
        par, iv, n, axis = ints[i, PARENT], ints[i, IV], ints[i, NDOF], ints[i, UNIT_AXIS]
        for k in range(iv, iv + n):
            if axis >= 0:
                s = f[i, axis]
            else:
                s = 0.0
                for r in range(6):
                    s += dofs[k, MOTION + r] * f[i, r]
            tau[k] = s + dofs[k, ARMATURE] * a[k] + passive_torque(dofs, eps, q, ints[i, IQ], v, k)
        if par >= 0:
            force_act(liR[i], lip[i], f[i], t1)
            for r in range(6):
                f[par, r] += t1[r]
    return result_status(check, finite(tau))


@core
def rnea_one(ints, body, dofs, params, q, v, a, fext, fcode, check, tau, ws):
    """:func:`rnea_state` of one state (the compiled function other kernels call)."""
    return rnea_state(ints, body, dofs, params, q, v, a, fext, fcode, check, tau, ws)


@inline
def rnea_at(args, s, ws):
    """:func:`rnea_state` of state ``s`` of a batch (``F`` has one row per state, or a single
    row for all)."""
    ints, body, dofs, params, Q, V, A, F, fcode, check, TAU = args
    return rnea_state(ints, body, dofs, params, Q[s], V[s], A[s], F[s if F.shape[0] > 1 else 0], fcode, check,
                      TAU[s], ws)


@inline
def rnea_views(args, ws):
    """The workspace views carved once per chunk from the buffer, where the compiler sees
    their shapes."""
    return (ws[0],) + workspace_views(ws[0], args[0].shape[0])


_rnea_batch = batch_kernel(rnea_at, buffer, rnea_views)


@fast(MODEL_INTS, MODEL_PACKED, VEC, VEC, VEC, boolean, VEC)
def _rnea_packed(ints, packed, q, v, a, check, tau):
    """One state without external wrenches, the model in one array (the fast path). Unlike the
    other fast paths it keeps its own copy of the state code rather than calling the batch's
    (``driver.BatchKernel.call_one``): the RNEA is the cheapest call, and here the code for
    external wrenches is cut at compile time and no call passes the arguments (about 0.1 us
    of 1.7 on the Panda, ``benchmarks/RESULTS.md``)."""
    body, dofs, params, zero = unpack(ints, packed)
    if not fits(tau, dofs.shape[0], q, v, a):
        return WRONG_SIZE
    return rnea_state(ints, body, dofs, params, q, v, a, zero, NO_WRENCH, check, tau, workspace(ints.shape[0]))


@scratch
def coupled_workspace(nb, nqf, nvf):
    """Scratch of :func:`rnea_coupled_state`: the RNEA's, and a buffer for the full tree's
    ``q, v, a, tau`` (nq_full + 3 nv_full)."""
    return workspace(nb), np.empty(nqf + 3 * nvf)


@inline
def rnea_coupled_state(ints, body, dofs, params, cints, cfloats, q, v, a, fext, fcode, check, tau, ws):
    """Inverse dynamics of a model with mimic couplings (``robodyn.coupling``), one state:
    ``tau = G^T rnea_full(P q + o, G v, G a)`` (nv,), the full tree in ``ints, body, dofs,
    params``, the coupling in ``cints, cfloats`` (``CouplingTables``). Returns a status."""
    rws, buf = ws
    nqf, nvf = nq_of(ints), dofs.shape[0]
    qf, vf = view(buf, 0, (nqf,)), view(buf, nqf, (nvf,))
    af, tf = view(buf, nqf + nvf, (nvf,)), view(buf, nqf + 2 * nvf, (nvf,))
    if not (q.shape[0] == cints[0] and v.shape[0] == cints[1] and a.shape[0] == cints[1]):
        return WRONG_SIZE
    if check and not (finite(q) and finite(v) and finite(a)):
        return NONFINITE
    expand_positions(cints, cfloats, q, qf)
    expand_velocity(cints, cfloats, v, vf)
    expand_velocity(cints, cfloats, a, af)
    status = rnea_one(ints, body, dofs, params, qf, vf, af, fext, fcode, check, tf, rws)
    if status != OK:
        return status
    reduce_vector(cints, cfloats, tf, tau)
    return result_status(check, finite(tau))


@inline
def rnea_coupled_at(args, s, ws):
    """:func:`rnea_coupled_state` of state ``s`` of a batch (``F`` as in :func:`rnea_at`)."""
    ints, body, dofs, params, cints, cfloats, Q, V, A, F, fcode, check, TAU = args
    return rnea_coupled_state(ints, body, dofs, params, cints, cfloats, Q[s], V[s], A[s],
                              F[s if F.shape[0] > 1 else 0], fcode, check, TAU[s], ws)


COUPLED_ONE_STATE = ((MODEL_INTS, MAT, MAT, VEC, INTS, VEC, MAT, MAT, MAT, TENSOR, int64, boolean, MAT),
                     (int64, int64, int64))
_rnea_coupled_batch = batch_kernel(rnea_coupled_at, coupled_workspace, one_state=COUPLED_ONE_STATE)
_rnea_coupled_call_one = _rnea_coupled_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, INTS, VEC, VEC, VEC, VEC, boolean, VEC)
def _rnea_coupled_one(address, ints, packed, cints, cfloats, q, v, a, check, tau):
    """One state of a coupled model without external wrenches: the batch's code at ``address``
    (``_rnea_coupled_batch.one_address``) for a batch of one."""
    ok, args = coupled_one_state(ints, packed, cints, cfloats, q, v, a, check, tau)
    return (_rnea_coupled_call_one(address, args, coupled_workspace(ints.shape[0], nq_of(ints), args[2].shape[0]))
            if ok else WRONG_SIZE)


def run_coupled(model, q, v, a, f_ext, frame: str, friction: bool, armature: bool, check: bool, out=None):
    """:func:`rnea` of a :class:`~robodyn.coupling.CoupledModel` (compiled: the full tree's
    RNEA between the coupling's maps, per state)."""
    sizes = (model.nbodies, model.full.nq, model.full.nv)
    return _inputs.coupled_call(model, _rnea_coupled_one, _rnea_coupled_batch, sizes, "a", q, v, a, f_ext, frame,
                                friction, armature, check, out, "rnea")


def run(model, batch, x, F, fcode, check, gravity=True, friction=True, armature=True, what="rnea", report=None,
        out=None):
    """RNEA on checked inputs ``x = {"q", "v", "a"}`` (see ``_inputs.states``) into ``out``
    (see ``_inputs.output``); errors name the arrays of ``report`` (default ``x``)."""
    k = model.kernel
    dofs, params = k.dofs[(bool(friction), bool(armature))], k.params[gravity]
    tau, result = _inputs.output(out, batch, (model.nv,), x)
    Q, V, A, F, TAU = _inputs.batched(batch, x["q"], x["v"], x["a"], F, tau)
    status = np.empty(Q.shape[0], dtype=np.int64)
    args = (k.ints, k.body, dofs, params, Q, V, A, F, fcode, check, TAU)
    _rnea_batch.run(args, (model.nbodies,), status, batch)
    raise_for_status(model, status, x if report is None else report, what)
    return result


def external_wrenches(model, f_ext, frame: str = "local") -> tuple[np.ndarray, np.int64]:
    """One state's external wrenches for the compiled kernels: ``(F, code)`` with ``F``
    (nbodies, 6) ``[force, torque]`` (checked: shape, finite) and ``code`` the kernels' frame
    code of ``frame`` (``"local"``, ``"world"``, ``"local_world_aligned"``; see :func:`rnea`),
    ``NO_WRENCH`` for ``f_ext=None``."""
    F, code = _inputs.body_wrenches(model, f_ext, (), frame)
    return F, np.int64(code)


def rnea(model, q, v, a, f_ext=None, frame: str = "local", *, friction: bool = True,
         armature: bool = True, check_finite: bool = True, out: np.ndarray | None = None,
         f_ext_frame=None) -> np.ndarray:
    """Inverse dynamics: the joint forces that produce acceleration ``a`` at state ``(q, v)``.

    ``tau = M(q) a + C(q, v) v + g(q) - sum_i J_i^T f_ext_i + armature * a + friction(v) + spring(q)``

    Args:
        q: (..., nq) configuration. v, a: (..., nv) velocity and acceleration.
        f_ext: optional (..., nbodies, 6) external wrenches ``[force, torque]`` applied to each
            body, expressed in ``frame``: ``"local"`` (body frame, torque about the body
            origin), ``"world"`` (world axes, torque about the world origin) or
            ``"local_world_aligned"`` (world axes, torque about the body origin).
        friction: add the model's passive joint torques, friction and springs: ``damping v +
            coulomb sgn(v) + stiffness (q - spring_reference)``.
        armature: add the model's reflected rotor inertia ``armature * a``.
        check_finite: reject NaN/Inf inputs (turn off only in hot loops with trusted input).
        out: optional (..., nv) C-contiguous float64 array to write the result into (and
            return), as in NumPy; it must not overlap the inputs.

    Returns:
        tau: (..., nv). For a floating base its first six entries are the base wrench
        ``[force, torque]`` in the base frame.

    Equivalences: ``rnea(q, 0, 0) == gravity(q)``, ``rnea(q, v, 0, friction=False) ==
    nonlinear_effects(q, v)``, ``rnea(q, v, a) == crba(q) a + nonlinear_effects(q, v)`` without
    friction. Reference: Featherstone, RBDA (2008), Table 5.1.
    """
    if f_ext_frame is not None:  # the old spelling of ``frame``
        frame = renamed_keyword("f_ext_frame", f_ext_frame, "frame", frame, "rnea()")
    if f_ext is None and frame in _inputs.WRENCH_FRAMES:
        tau = _inputs.fast_out(out, (model.nv,))  # fast path for one state: the kernel checks sizes and values
        try:
            k = model.kernel  # a CoupledModel (mimic joints) has none: its path below
            if _rnea_packed(k.ints, k.packed[friction, armature], q, v, a, check_finite, tau) == OK:
                return tau
        except (TypeError, KeyError, AttributeError):  # not contiguous float64 arrays (or options not bool)
            pass
    if any_lazy(q, v, a, f_ext):
        return deferred(rnea, locals())
    if is_coupled(model):  # mimic joints: the compiled coupled path (after the fast path: free for a tree)
        return run_coupled(model, q, v, a, f_ext, frame, friction, armature, check_finite, out)
    batch, x = _inputs.states(model, q=q, v=v, a=a)
    F, fcode = _inputs.body_wrenches(model, f_ext, batch, frame)
    return run(model, batch, x, F, fcode, check_finite, friction=friction, armature=armature, out=out)
