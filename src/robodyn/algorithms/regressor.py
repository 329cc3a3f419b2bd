"""Regressors: joint forces and energies as linear functions of the inertial parameters.

The equation of motion is linear in the inertial parameters ``theta`` (10 per body, about
the body origin in the body frame, order ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz,
Izz]``, as in ``Model.inertial_parameters()``):

    tau = Y(q, v, a) theta                       (joint-torque regressor, nv x 10 nb)
    M qdd_r + C(q, v) qd_r + g = Y(q, v, qd_r, qdd_r) theta    (Slotine-Li regressor, nv x 10 nb)
    T(q, v) = Y_T(q, v) theta,  U(q) = Y_U(q) theta    (energy regressors, 10 nb)

Body ``i``'s spatial force ``f_i = I_i a_i + v_i x* I_i v_i`` (body frame, with the base
accelerating at ``-g``) is ``A_i theta_i`` with the 6 x 10 body regressor ``A_i`` whose column
``c`` is the force of the unit parameter vector ``e_c``. Dof ``k`` of body ``j`` carries the
forces of every body ``i`` in its subtree, so

    Y[k, 10 i : 10 i + 10] = S_k^T  jX*_i  A_i      (i in the subtree of j, zero otherwise)

computed by carrying each ``A_i`` up the chain of its ancestors: O(n d) per state, d the depth
of the tree. Reference: Atkeson, An and Hollerbach, "Estimation of inertial parameters of
manipulator loads and links", IJRR 5(3), 1986; Khalil and Dombre, *Modeling, Identification
and Control of Robots* (2002), section 12.3 (Newton-Euler form of the identification model).

Optional columns of the joint-torque regressor, appended after the ``10 nb`` inertial columns
in this order, ``nv`` columns each (column ``k`` of a block acts on dof ``k`` only):

    damping    v_k                 (parameter: ``model.damping[k]``, viscous friction)
    coulomb    sgn(v_k)            (``model.coulomb[k]``; ``tanh(v_k / eps)`` when
                                    ``model.coulomb_smoothing = eps > 0``, as in ``rnea``)
    stiffness  q_k                 (``model.stiffness[k]``, the joint spring; ``q_k`` the
                                    joint's coordinate; 0 on the dofs of free, spherical and
                                    planar joints, which have no spring)
    armature   a_k                 (``model.armature[k]``)
    offset     1                   (a constant torque offset of the joint)

so that ``Y @ concatenate([theta, damping, coulomb, stiffness, armature, offset]) ==
rnea(q, v, a)`` with friction and armature on and ``offset = -stiffness * spring_reference``:
the spring's torque ``K (q - q_ref)`` is linear in ``K`` and in the constant ``-K q_ref``,
which the offset block absorbs (together with any real torque offset of the joint; see
:func:`extended_parameters`).

Pinocchio's ``computeJointTorqueRegressor`` has the same columns in the same order: its
dynamic parameters per joint, ``[m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` with the inertia
about the joint frame origin, are these 10 parameters (the body frame is the joint frame);
``tests/test_regressor.py`` checks the two on every example-robot-data URDF.
"""

from __future__ import annotations

import numpy as np

from .._deprecated import renamed_keywords
from .._jit import core, inline, scratch
from ..layout import IQ, IV, MOTION, NDOF, PARAMS_SIZE, PARENT, SMOOTHING
from ..spatial import dot6, force_act, force_cross, inertia_mul, motion_act_inv, motion_cross
from ..coupling import expand_q, expand_v, is_coupled, reduce_rows
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status
from .status import NONFINITE, OK, finite, finite2, result_status
from .kinematics import poses_checked
from .rnea import base_acceleration, motion_pass
from .driver import batch_kernel

EXTRA_COLUMNS = ("damping", "coulomb", "stiffness", "armature", "offset")
# The flags of the extra columns follow the model's ``params`` in the kernels' ``params``.
EXTRA_FLAGS = PARAMS_SIZE


@scratch
def workspace(nb, nv):
    """Placements, world poses, motion, the unit parameter vectors and a 10 x 6 block."""
    return (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3, 3)), np.empty((nb, 3)),
            np.empty((3, 3)), np.empty(3), np.empty((nb, 6)), np.empty((nb, 6)), np.empty(6), np.empty(6),
            np.empty(6), np.eye(10), np.empty((10, 6)), np.zeros(nv), np.zeros(3))


@inline
def body_regressor(E, vel, acc, W, t1, t2):
    """``W[c] = I(e_c) acc + vel x* I(e_c) vel``: the body force of each unit parameter (10, 6)."""
    for c in range(10):
        inertia_mul(E[c], acc, W[c])
        inertia_mul(E[c], vel, t1)
        force_cross(vel, t1, t2)
        for r in range(6):
            W[c, r] += t2[r]


@inline
def joint_rows(ints, dofs, liR, lip, i, W, Y, t1):
    """Columns ``10 i : 10 i + 10`` of ``Y`` from body ``i``'s regressor ``W`` (10, 6) in body
    ``i`` coordinates: ``Y[k] = S_k^T jX*_i W`` for the dofs ``k`` of ``i`` and of each
    ancestor ``j``. ``W`` is carried up the chain (overwritten)."""
    j = i
    while j >= 0:  # W holds A_i expressed in body j's frame
        for k in range(ints[j, IV], ints[j, IV] + ints[j, NDOF]):
            for c in range(10):
                Y[k, 10 * i + c] = dot6(dofs[k, MOTION:MOTION + 6], W[c])
        if ints[j, PARENT] >= 0:
            for c in range(10):
                force_act(liR[j], lip[j], W[c], t1)
                for r in range(6):
                    W[c, r] = t1[r]
        j = ints[j, PARENT]


@inline
def extra_rows(ints, params, q, v, a, col, Y):
    """The extra column blocks from column ``col`` on (flags ``params[EXTRA_FLAGS:]``, see
    ``EXTRA_COLUMNS``): ``v_k``, ``sgn v_k`` (smoothed when ``params[SMOOTHING] > 0``), ``q_k``
    (joints of one dof; 0 on the others), ``a_k``, ``1``."""
    nv, eps = v.shape[0], params[SMOOTHING]
    for block in range(5):
        if params[EXTRA_FLAGS + block] == 0.0:
            continue
        if block == 2:  # the joint coordinate of each one-dof joint: ints[i, IQ]
            for i in range(ints.shape[0]):
                if ints[i, NDOF] == 1:
                    Y[ints[i, IV], col + ints[i, IV]] = q[ints[i, IQ]]
            col += nv
            continue
        for k in range(nv):
            if block == 0:
                Y[k, col + k] = v[k]
            elif block == 1:
                Y[k, col + k] = (np.tanh(v[k] / eps) if eps > 0.0 else
                                 (1.0 if v[k] > 0.0 else (-1.0 if v[k] < 0.0 else 0.0)))
            elif block == 3:
                Y[k, col + k] = a[k]
            else:
                Y[k, col + k] = 1.0
        col += nv


@core
def regressor_one(ints, body, dofs, params, q, v, a, check, Y, ws):
    """Joint-torque regressor of one state into ``Y`` (nv, 10 nb + extra columns); returns a
    status (see ``_inputs``). Columns past ``10 nb`` are the extra blocks in the order of
    ``EXTRA_COLUMNS`` whose flags ``params[EXTRA_FLAGS:]`` are non-zero."""
    liR, lip, oR, op, Rj, pj, vel, acc, vJ, t1, t2, E, W, zero_v, zero_g = ws
    nb = ints.shape[0]
    status = poses_checked(ints, body, q, v, check, liR, lip, Rj, pj, oR, op)
    if status != OK:
        return status
    if check and not finite(a):
        return NONFINITE
    motion_pass(ints, dofs, liR, lip, v, a, params, vel, acc, vJ, t1, t2)
    Y[:, :] = 0.0
    for i in range(nb):
        body_regressor(E, vel[i], acc[i], W, t1, t2)
        joint_rows(ints, dofs, liR, lip, i, W, Y, t1)
    extra_rows(ints, params, q, v, a, 10 * nb, Y)
    return result_status(check, finite2(Y))


@inline
def regressor_at(args, s, ws):
    """The regressor of state ``s`` of a batch."""
    ints, body, dofs, params, Q, V, A, check, Y = args
    return regressor_one(ints, body, dofs, params, Q[s], V[s], A[s], check, Y[s], ws)


_regressor_batch = batch_kernel(regressor_at, workspace)


@scratch
def reference_workspace(nb, nv):
    """:func:`workspace` plus the reference velocities (nb, 6) and two 6-vectors."""
    liR, lip, oR, op, Rj, pj, vel, acc, vJ, t1, t2, E, W, zero_v, zero_g = workspace(nb, nv)
    return (liR, lip, oR, op, Rj, pj, vel, acc, vJ, t1, t2, E, W, np.empty((nb, 6)), np.empty(6), np.empty(6))


@inline
def reference_motion_pass(ints, dofs, liR, lip, v, v_r, a_r, grav, vel, vel_r, acc_r, vJ, t1, a0):
    """Body velocities ``vel``, reference velocities ``vel_r`` and reference accelerations
    ``acc_r`` (nb, 6) in body coordinates, the base accelerating at ``-grav``::

        v_i = iX_p v_p + S_i qd_i,   v_r,i = iX_p v_r,p + S_i qd_r,i,
        a_r,i = iX_p a_r,p + S_i qdd_r,i + v_i x S_i qd_r,i

    (``a_r,i = J_i qdd_r + Jdot_i qd_r``: the joint axes move with the true velocity).
    """
    base_acceleration(grav, a0)
    for i in range(ints.shape[0]):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        if par >= 0:
            motion_act_inv(liR[i], lip[i], vel[par], vel[i])
            motion_act_inv(liR[i], lip[i], vel_r[par], vel_r[i])
            motion_act_inv(liR[i], lip[i], acc_r[par], acc_r[i])
        else:
            vel[i, :] = 0.0
            vel_r[i, :] = 0.0
            motion_act_inv(liR[i], lip[i], a0, acc_r[i])
        for r in range(6):
            vJ[r] = 0.0
        for k in range(iv, iv + n):
            for r in range(6):
                vel[i, r] += dofs[k, MOTION + r] * v[k]
                vJ[r] += dofs[k, MOTION + r] * v_r[k]
                acc_r[i, r] += dofs[k, MOTION + r] * a_r[k]
        for r in range(6):
            vel_r[i, r] += vJ[r]
        motion_cross(vel[i], vJ, t1)
        for r in range(6):
            acc_r[i, r] += t1[r]


@inline
def body_reference_regressor(E, vel, vel_r, acc_r, W, w, t1, t2):
    """``W[c] = I(e_c) a_r + B(e_c, v) v_r`` (10, 6) with
    ``B(v) v_r = 1/2 [ v x* I v_r + v_r x* I v - I (v x v_r) ]``; ``w`` (6,) a workspace."""
    motion_cross(vel, vel_r, w)
    for c in range(10):
        inertia_mul(E[c], acc_r, W[c])
        inertia_mul(E[c], w, t1)
        for r in range(6):
            W[c, r] -= 0.5 * t1[r]
        inertia_mul(E[c], vel_r, t1)
        force_cross(vel, t1, t2)
        for r in range(6):
            W[c, r] += 0.5 * t2[r]
        inertia_mul(E[c], vel, t1)
        force_cross(vel_r, t1, t2)
        for r in range(6):
            W[c, r] += 0.5 * t2[r]


@core
def slotine_li_regressor_one(ints, body, dofs, params, q, v, v_r, a_r, check, Y, ws):
    """Slotine-Li regressor of one state into ``Y`` (nv, 10 nb + extra columns, as
    :func:`regressor_one` with ``a = a_r``); returns a status (see ``_inputs``)."""
    liR, lip, oR, op, Rj, pj, vel, acc_r, vJ, t1, t2, E, W, vel_r, w, a0 = ws
    nb = ints.shape[0]
    status = poses_checked(ints, body, q, v, check, liR, lip, Rj, pj, oR, op)
    if status != OK:
        return status
    if check and not (finite(v_r) and finite(a_r)):
        return NONFINITE
    reference_motion_pass(ints, dofs, liR, lip, v, v_r, a_r, params, vel, vel_r, acc_r, vJ, t1, a0)
    Y[:, :] = 0.0
    for i in range(nb):
        body_reference_regressor(E, vel[i], vel_r[i], acc_r[i], W, w, t1, t2)
        joint_rows(ints, dofs, liR, lip, i, W, Y, t1)
    extra_rows(ints, params, q, v, a_r, 10 * nb, Y)
    return result_status(check, finite2(Y))


@inline
def slotine_li_at(args, s, ws):
    """The Slotine-Li regressor of state ``s`` of a batch."""
    ints, body, dofs, params, Q, V, VR, AR, check, Y = args
    return slotine_li_regressor_one(ints, body, dofs, params, Q[s], V[s], VR[s], AR[s], check, Y[s], ws)


_slotine_li_batch = batch_kernel(slotine_li_at, reference_workspace)


@core
def energy_regressor_one(ints, body, dofs, grav, q, v, check, out, ws):
    """``out[0]`` kinetic-energy regressor (when ``v`` has entries), ``out[1]`` potential.

    ``T = sum_i 1/2 V_i^T I(theta_i) V_i``; ``U = -g^T sum_i (m_i p_i + R_i h_i)``.
    """
    liR, lip, oR, op, Rj, pj, vel, acc, vJ, t1, t2, E, W, zero_v, zero_g = ws
    status = poses_checked(ints, body, q, v, check, liR, lip, Rj, pj, oR, op)
    if status != OK:
        return status
    if v.shape[0] > 0:
        motion_pass(ints, dofs, liR, lip, v, zero_v, zero_g, vel, acc, vJ, t1, t2)
    for i in range(ints.shape[0]):
        for c in range(10):
            if v.shape[0] > 0:
                inertia_mul(E[c], vel[i], t1)
                out[0, 10 * i + c] = 0.5 * dot6(vel[i], t1)
            else:
                out[0, 10 * i + c] = 0.0
            out[1, 10 * i + c] = 0.0
        out[1, 10 * i] = -(grav[0] * op[i, 0] + grav[1] * op[i, 1] + grav[2] * op[i, 2])
        for c in range(3):  # -g . R h = -(R^T g) . h
            out[1, 10 * i + 1 + c] = -(grav[0] * oR[i, 0, c] + grav[1] * oR[i, 1, c] + grav[2] * oR[i, 2, c])
    return result_status(check, finite2(out))


@inline
def energy_regressor_at(args, s, ws):
    """The energy regressor of state ``s`` of a batch (``V`` has one row per state, or one row for all)."""
    ints, body, dofs, grav, Q, V, check, OUT = args
    return energy_regressor_one(ints, body, dofs, grav, Q[s], V[s if V.shape[0] > 1 else 0], check, OUT[s], ws)


_energy_regressor_batch = batch_kernel(energy_regressor_at, workspace)


@renamed_keywords(viscous="damping")
def extra_columns(model, *, damping: bool = False, coulomb: bool = False, stiffness: bool = False,
                  armature: bool = False, offset: bool = False) -> list[str]:
    """Names of the extra regressor columns, in order: ``"damping[joint]"``, ... one per dof
    (of ``model.full`` for a coupled model)."""
    names = (model.full if is_coupled(model) else model).dof_names
    flags = dict(damping=damping, coulomb=coulomb, stiffness=stiffness, armature=armature, offset=offset)
    return [f"{kind}[{n}]" for kind in EXTRA_COLUMNS if flags[kind] for n in names]


def spring_offset(model) -> np.ndarray:
    """``-stiffness * spring_reference`` (nv,): the constant part of the joint springs'
    torque ``K (q - q_ref)``, the value of the offset columns when the stiffness columns
    carry ``K``."""
    return -np.asarray(model.stiffness, dtype=float) * np.asarray(model.spring_reference, dtype=float)


@renamed_keywords(viscous="damping")
def extended_parameters(model, *, damping: bool = False, coulomb: bool = False, stiffness: bool = False,
                        armature: bool = False, offset=None) -> np.ndarray:
    """The parameter vector that matches :func:`regressor` with the same switches:
    ``[theta, damping, coulomb, stiffness, armature, offset]`` (blocks present when switched
    on). ``offset``: None for no offset columns, ``True`` for the model's own constant joint
    torques ``-stiffness * spring_reference`` (:func:`spring_offset`: zero without springs),
    or an (nv,) array of joint torque offsets. With every block on and ``offset=True``,
    ``regressor(model, q, v, a, damping=True, coulomb=True, stiffness=True, armature=True,
    offset=True) @ extended_parameters(...) == rnea(model, q, v, a)``. For a coupled model
    (mimic joints) the joint blocks are those of every joint of ``model.full``."""
    if is_coupled(model):
        return extended_parameters(model.full, damping=damping, coulomb=coulomb, stiffness=stiffness,
                                   armature=armature, offset=offset)
    parts = [model.inertial_parameters()]
    for on, values in ((damping, model.damping), (coulomb, model.coulomb), (stiffness, model.stiffness),
                       (armature, model.armature)):
        if on:
            parts.append(np.asarray(values, dtype=float))
    if offset is True:
        parts.append(spring_offset(model))
    elif offset is not None and offset is not False:
        off = np.asarray(offset, dtype=float)
        if off.shape != (model.nv,):
            raise ValueError(f"offset: expected True, None or shape ({model.nv},), got {off.shape}")
        parts.append(off)
    return np.concatenate(parts)


@renamed_keywords(viscous="damping")
def regressor(model, q, v, a, *, damping: bool = False, coulomb: bool = False, stiffness: bool = False,
              armature: bool = False, offset: bool = False, check_finite: bool = True) -> np.ndarray:
    """Joint-torque regressor ``Y`` with ``Y @ model.inertial_parameters() == rnea(model, q, v,
    a, friction=False, armature=False)``.

    ``tau = Y(q, v, a) theta``, ``theta`` the 10 inertial parameters per body about the body
    origin in the body frame, ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``.

    Args:
        q: (..., nq) configuration. v, a: (..., nv) velocity and acceleration.
        damping, coulomb, stiffness, armature, offset: append ``nv`` columns each, in this
            order, for viscous friction (``v_k``), Coulomb friction (``sgn v_k``, smoothed as
            in ``rnea`` when ``model.coulomb_smoothing > 0``), the joint springs' stiffness
            (``q_k``, the coordinate of a joint of one dof; 0 on the dofs of free, spherical
            and planar joints, which have no spring), armature (``a_k``) and a constant joint
            torque offset (``1``, which also carries the springs' ``-K q_ref``); see
            :func:`extended_parameters` and :func:`extra_columns`.
        check_finite: reject NaN/Inf inputs.

    Returns:
        Y: (..., nv, 10 nbodies + extra columns). For a floating base the first six rows are
        the base wrench ``[force, torque]`` in the base frame, as in ``rnea``.

    Reference: Khalil and Dombre (2002), section 12.3; Atkeson, An and Hollerbach (1986).
    """
    if any_lazy(q, v, a):
        return deferred(regressor, locals())
    if is_coupled(model):  # mimic joints: G^T Y_full(E(q), G v, G a); extra columns per dof of the full tree
        return reduce_rows(model, regressor(model.full, expand_q(model, q), expand_v(model, v), expand_v(model, a, "a"),
                                            damping=damping, coulomb=coulomb, stiffness=stiffness,
                                            armature=armature, offset=offset, check_finite=check_finite))
    batch, x = _inputs.states(model, q=q, v=v, a=a)
    k = model.kernel
    flags = [float(bool(f)) for f in (damping, coulomb, stiffness, armature, offset)]
    params = np.concatenate([k.params[True], flags])
    ncol = 10 * model.nbodies + model.nv * int(sum(flags))
    Q, V, A = (_inputs.as_batch(x[n]) for n in "qva")
    B = Q.shape[0]
    Y, status = np.empty((B, model.nv, ncol)), np.empty(B, dtype=np.int64)
    _regressor_batch.run((k.ints, k.body, k.dofs[(False, False)], params, Q, V, A, check_finite, Y),
                         (model.nbodies, model.nv), status, batch)
    raise_for_status(model, status, x, "regressor")
    return Y[0] if batch == () else Y.reshape(batch + Y.shape[1:])


@renamed_keywords(viscous="damping")
def slotine_li_regressor(model, q, v, v_ref, a_ref, *, damping: bool = False, coulomb: bool = False,
                         stiffness: bool = False, armature: bool = False, offset: bool = False,
                         check_finite: bool = True) -> np.ndarray:
    """Slotine-Li regressor ``Y(q, qd, qd_r, qdd_r)``, linear in the inertial parameters::

        Y @ model.inertial_parameters() == M(q) qdd_r + C(q, qd) qd_r + g(q)

    with ``C`` the Coriolis matrix of :func:`robodyn.coriolis_matrix` (``Mdot - 2C``
    skew-symmetric, which the passivity of the adaptive Slotine-Li controller needs; the
    Coriolis vector alone does not fix ``C qd_r``). With ``v_ref = v`` it is
    :func:`regressor`. Body by body (body coordinates, base accelerating at ``-g``)::

        v_i   = iX_p v_p   + S_i qd_i
        v_r,i = iX_p v_r,p + S_i qd_r,i
        a_r,i = iX_p a_r,p + S_i qdd_r,i + v_i x S_i qd_r,i
        f_i   = I_i a_r,i + B_i(v_i) v_r,i,  B(v) = 1/2 [(v x*) I - I (v x) + (I v) xbar*]

    (``(f xbar*) m = m x* f``), linear in body ``i``'s 10 parameters; ``tau = sum_i J_i^T
    f_i`` is accumulated up each body's chain as in :func:`regressor`, since
    ``C = sum_i J_i^T (I_i Jdot_i + B_i J_i)`` (Echeandia and Wensing 2021).

    Args:
        q: (..., nq) configuration. v: (..., nv) velocity ``qd``. v_ref, a_ref: (..., nv)
            reference velocity ``qd_r`` and acceleration ``qdd_r``.
        damping, coulomb, stiffness, armature, offset: extra ``nv``-column blocks as in
            :func:`regressor`, evaluated at ``(q, v, a_ref)``: ``v_k``, ``sgn v_k``, ``q_k``,
            ``qdd_r,k``, ``1``; with them, ``Y @ extended_parameters(model, ...) == rnea(q, v,
            a_ref) - C(q, v) (v - v_ref)`` (with ``offset=True``): the friction of the true
            velocity, the springs at ``q`` and the armature at ``qdd_r``.
        check_finite: reject NaN/Inf inputs.

    Returns:
        Y: (..., nv, 10 nbodies + extra columns). For a floating base the first six rows are
        the base wrench ``[force, torque]`` in the base frame, as in ``rnea``.

    Reference: Slotine and Li, "On the adaptive control of robot manipulators", IJRR 6(3),
    1987; Niemeyer and Slotine, "Performance in adaptive manipulator control", IJRR 10(2),
    1991; Echeandia and Wensing, J. Comput. Nonlinear Dynam. 16(9), 2021.
    """
    if any_lazy(q, v, v_ref, a_ref):
        return deferred(slotine_li_regressor, locals())
    if is_coupled(model):  # as regressor()
        full = (expand_v(model, v), expand_v(model, v_ref, "v_ref"), expand_v(model, a_ref, "a_ref"))
        return reduce_rows(model, slotine_li_regressor(model.full, expand_q(model, q), *full, damping=damping,
                                                       coulomb=coulomb, stiffness=stiffness, armature=armature,
                                                       offset=offset, check_finite=check_finite))
    batch, x = _inputs.states(model, q=q, v=v, v_ref=v_ref, a_ref=a_ref)
    k = model.kernel
    flags = [float(bool(f)) for f in (damping, coulomb, stiffness, armature, offset)]
    params = np.concatenate([k.params[True], flags])
    ncol = 10 * model.nbodies + model.nv * int(sum(flags))
    args = (k.ints, k.body, k.dofs[(False, False)], params)
    Q, V, VR, AR = _inputs.batched(batch, x["q"], x["v"], x["v_ref"], x["a_ref"])
    Y, status = np.empty((Q.shape[0], model.nv, ncol)), np.empty(Q.shape[0], dtype=np.int64)
    _slotine_li_batch.run((*args, Q, V, VR, AR, check_finite, Y), (model.nbodies, model.nv), status, batch)
    raise_for_status(model, status, x, "slotine_li_regressor")
    return Y.reshape(batch + Y.shape[1:])


def _energy(model, check_finite, what, **arrays):
    if is_coupled(model):  # the full tree's at (E(q), G v)
        full = {name: expand_q(model, x) if name == "q" else expand_v(model, x, name) for name, x in arrays.items()}
        return _energy(model.full, check_finite, what, **full)
    batch, x = _inputs.states(model, **arrays)
    k = model.kernel
    Q = _inputs.as_batch(x["q"])
    V = _inputs.as_batch(x["v"]) if "v" in x else np.zeros((1, 0))
    B = Q.shape[0]
    OUT, status = np.empty((B, 2, 10 * model.nbodies)), np.empty(B, dtype=np.int64)
    args = (k.ints, k.body, k.dofs[(False, False)], model.gravity)
    _energy_regressor_batch.run((*args, Q, V, check_finite, OUT), (model.nbodies, model.nv), status,
                                () if B == 1 else (B,))
    raise_for_status(model, status, x, what)
    return OUT.reshape(batch + OUT.shape[1:])


def kinetic_energy_regressor(model, q, v, *, check_finite: bool = True) -> np.ndarray:
    """``Y_T`` (..., 10 nbodies) with ``Y_T @ model.inertial_parameters() ==
    kinetic_energy(model, q, v)``: ``T = sum_i 1/2 V_i^T I(theta_i) V_i`` (body twists
    ``V_i`` in body frames; armature not included, as in ``kinetic_energy``)."""
    if any_lazy(q, v):
        return deferred(kinetic_energy_regressor, locals())
    return _energy(model, check_finite, "kinetic_energy_regressor", q=q, v=v)[..., 0, :]


def potential_energy_regressor(model, q, *, check_finite: bool = True) -> np.ndarray:
    """``Y_U`` (..., 10 nbodies) with ``Y_U @ model.inertial_parameters() ==
    potential_energy(model, q)``: ``U = -g^T sum_i (m_i p_i + R_i h_i)`` (world pose
    ``(R_i, p_i)`` of body ``i``), so only the mass and first-moment columns are non-zero."""
    if any_lazy(q):
        return deferred(potential_energy_regressor, locals())
    return _energy(model, check_finite, "potential_energy_regressor", q=q)[..., 1, :]
