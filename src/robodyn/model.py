"""The robot model: an immutable set of flat arrays indexed by body.

A model is a kinematic tree of ``nbodies`` rigid bodies. Body ``i`` hangs from body
``parent[i] < i`` (``-1`` is the fixed world) through one joint whose frame sits at the fixed
placement ``X_tree[i]`` in the parent body's frame. Fixed joints do not appear: the loaders
merge them into the parent body and keep the merged links as *frames*.

Configuration ``q`` (nq,) and velocity ``v`` (nv,) stack the joints in body order; body ``i``
owns ``q[idx_q[i]:idx_q[i] + nq_i]`` and ``v[idx_v[i]:idx_v[i] + nv_i]`` (see
:mod:`robodyn.joints`). A floating base is body 0 with a free joint:
``q = [x, y, z, qx, qy, qz, qw, joints...]`` and ``v = [v_lin, omega, joints...]``, the base
velocities in the base frame.

Inertial parameters, 10 per body about the body frame origin in the body frame:
``[m, m*cx, m*cy, m*cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``.
"""

from __future__ import annotations

import warnings
from typing import Sequence

import numpy as np

from ._deprecated import renamed_attribute, renamed_keyword
from . import joints as J


from .errors import ModelError, RobodynWarning, user_stacklevel
from .layout import pack


_AXIAL_CODE = np.isin(np.arange(len(J.NAMES)), J.AXIAL)  # joint type code -> has an axis

# Tolerances of the physical-consistency checks of inertias: relative to the largest principal
# moment, with an absolute floor (kg m^2) for the round-off of bodies with (almost) no inertia.
INERTIA_RTOL = 1e-6
INERTIA_ATOL = 1e-12


def readonly(a, dtype=float):
    """A read-only copy; returned as a view of a read-only base so that setting
    ``flags.writeable = True`` on it fails as well."""
    a = np.array(a, dtype=dtype, copy=True)
    a.flags.writeable = False
    return a.view()


def inertial_parameters_from(mass: float, com, inertia_com) -> np.ndarray:
    """10 inertial parameters about the frame origin from mass, centre of mass and the 3 x 3
    inertia about the centre of mass (all in the same frame), by the parallel-axis theorem."""
    c = np.asarray(com, dtype=float)
    Ic = np.asarray(inertia_com, dtype=float)
    Io = Ic + mass * (np.dot(c, c) * np.eye(3) - np.outer(c, c))
    h = mass * c
    return np.array([mass, h[0], h[1], h[2], Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]])


def inertia_about_origin(theta) -> np.ndarray:
    """3 x 3 rotational inertia about the frame origin from 10 parameters."""
    t = theta
    return np.array([[t[4], t[5], t[7]], [t[5], t[6], t[8]], [t[7], t[8], t[9]]], dtype=float)


def mass_com_inertia(theta) -> tuple[float, np.ndarray, np.ndarray]:
    """``(m, c, I_c)`` of 10 inertial parameters: mass, centre of mass and inertia about it
    (zero centre of mass for a massless body)."""
    m = float(theta[0])
    c = np.asarray(theta[1:4], dtype=float) / m if m > 0 else np.zeros(3)
    return m, c, inertia_about_origin(theta) - m * (c @ c * np.eye(3) - np.outer(c, c))


def inertial_parameters_in_parent(R, p, theta) -> np.ndarray:
    """Inertial parameters of a body expressed in the frame where it is placed at ``(R, p)``.

    ``h' = R h + m p``;
    ``I' = R I R^T - p h_r^T - h_r p^T + 2 (p . h_r) 1 - m p p^T + m |p|^2 1`` with
    ``h_r = R h`` (the parallel-axis theorem without dividing by the mass).
    """
    R, p, t = np.asarray(R, dtype=float), np.asarray(p, dtype=float), np.asarray(theta, dtype=float)
    m, hr = t[0], R @ t[1:4]
    I = R @ inertia_about_origin(t) @ R.T - np.outer(p, hr) - np.outer(hr, p) \
        + (2.0 * p @ hr + m * (p @ p)) * np.eye(3) - m * np.outer(p, p)
    h = hr + m * p
    return np.array([m, h[0], h[1], h[2], I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]])


def check_inertial_parameters(theta, where: str) -> None:
    """Raise :class:`ModelError` unless ``theta`` is a physically consistent rigid body.

    Checks: finite values, mass >= 0, a massless body has no first moment and no inertia,
    the inertia about the centre of mass is positive semi-definite and its principal moments
    satisfy the triangle inequality ``I1 + I2 >= I3`` (tolerances ``INERTIA_RTOL`` relative to
    the largest principal moment and ``INERTIA_ATOL`` absolute).
    """
    theta = np.asarray(theta, dtype=float)
    if not np.all(np.isfinite(theta)):
        raise ModelError(f"{where}: inertial parameters are not finite: {theta.tolist()}")
    m = theta[0]
    Io = inertia_about_origin(theta)
    scale = max(np.abs(Io).max(), 1e-300)
    if m < 0:
        raise ModelError(f"{where}: negative mass {m}")
    if m == 0:
        if np.abs(theta[1:]).max() > 0:
            raise ModelError(f"{where}: zero mass with non-zero first moment or inertia")
        return
    c = theta[1:4] / m
    Ic = Io - m * (np.dot(c, c) * np.eye(3) - np.outer(c, c))
    eig = np.linalg.eigvalsh(Ic)
    tol = inertia_tolerance(eig, scale)
    if eig[0] < -tol:
        raise ModelError(
            f"{where}: inertia about the centre of mass is not positive semi-definite "
            f"(principal moments {eig.tolist()})"
        )
    if eig[0] + eig[1] < eig[2] - tol:
        raise ModelError(
            f"{where}: principal moments of inertia {eig.tolist()} violate the triangle "
            "inequality I1 + I2 >= I3"
        )


def repair_note(before, after, mass: float) -> str:
    """The warning text of a repaired body (:func:`repaired_inertial_parameters`)."""
    if mass == 0:
        return "massless with a first moment or inertia: its inertial parameters set to 0 (physical='repair')"
    steps = (["negative principal moments raised to 0"] if before[0] < 0 else []) + \
        (["I1 + I2 >= I3 failing, all three set to their mean"] if np.ptp(after) == 0 < np.ptp(before) else [])
    fmt = lambda e: "[" + ", ".join(f"{x:.6g}" for x in e) + "]"  # noqa: E731
    return (f"principal moments of inertia {fmt(before)} repaired to {fmt(after)} ({'; '.join(steps)}; mass, "
            "centre of mass and principal axes kept; physical='repair')")


def inertia_tolerance(eig, scale: float) -> float:
    """The tolerance of the principal-moment tests: ``INERTIA_RTOL`` of the largest moment,
    at least ``1e-12`` of ``scale`` (the largest entry about the frame origin) and
    ``INERTIA_ATOL``."""
    return max(INERTIA_RTOL * np.abs(eig).max(), 1e-12 * scale, INERTIA_ATOL)


def repaired_inertial_parameters(theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(theta', before, after)``: a consistent body near ``theta`` (finite, mass >= 0),
    with the principal moments about the centre of mass before and after.

    Mass and centre of mass are kept, and so are the principal axes. Negative principal
    moments are raised to 0 (positive semi-definite); then, when ``I1 + I2 >= I3`` still fails
    (beyond the tolerance of :func:`check_inertial_parameters`), all three become their mean,
    the rule of MuJoCo's ``<compiler balanceinertia="true">``. A massless body keeps no first
    moment and no inertia (all ten parameters 0). A consistent ``theta`` comes back unchanged.
    """
    theta = np.asarray(theta, dtype=float)
    if not (np.all(np.isfinite(theta)) and theta[0] >= 0):
        raise ModelError(f"inertial parameters {theta.tolist()} (not finite, or a negative mass) cannot be repaired")
    m, c, Ic = mass_com_inertia(theta)
    eig, V = np.linalg.eigh(Ic)
    if m == 0:
        return np.zeros(10), eig, np.zeros(3)
    tol = inertia_tolerance(eig, max(np.abs(inertia_about_origin(theta)).max(), 1e-300))
    if eig[0] >= -tol and eig[0] + eig[1] >= eig[2] - tol:
        return theta.copy(), eig, eig
    moments = np.maximum(eig, 0.0)
    if moments[0] + moments[1] < moments[2] - tol:
        moments[:] = moments.mean()
    return inertial_parameters_from(m, c, (V * moments) @ V.T), eig, moments


def consistent_inertial_parameters(theta) -> np.ndarray:
    """:func:`check_inertial_parameters` of many bodies at once, ``theta`` (n, 10): a boolean
    (n,) mask, True where the body passes (the same tests and tolerances)."""
    theta = np.asarray(theta, dtype=float).reshape(-1, 10)
    n = theta.shape[0]
    ok = np.isfinite(theta).all(1)
    t = np.where(ok[:, None], theta, 0.0)
    m = t[:, 0]
    Io = t[:, [4, 5, 7, 5, 6, 8, 7, 8, 9]].reshape(n, 3, 3)
    scale = np.maximum(np.abs(Io).reshape(n, 9).max(1, initial=0.0), 1e-300)
    massless = m == 0
    ok &= (m >= 0) & ~(massless & (np.abs(t[:, 1:]).max(1, initial=0.0) > 0))
    ms = np.where(massless, 1.0, m)
    c = t[:, 1:4] / ms[:, None]
    Ic = Io - ms[:, None, None] * (np.einsum("ni,ni->n", c, c)[:, None, None] * np.eye(3) - c[:, :, None] * c[:, None, :])
    eig = np.linalg.eigvalsh(Ic) if n else np.zeros((0, 3))
    tol = np.maximum(np.maximum(INERTIA_RTOL * np.abs(eig).max(1, initial=0.0), 1e-12 * scale), INERTIA_ATOL)
    rigid = (eig[:, 0] >= -tol) & (eig[:, 0] + eig[:, 1] >= eig[:, 2] - tol)
    return ok & (massless | rigid)


class Model:
    """Immutable rigid-body tree (see the module docstring for the layout).

    Per-body arrays (``nb = nbodies``): ``parent`` (nb,), ``joint_type`` (nb,),
    ``joint_axis`` (nb, 3), ``joint_pitch`` (nb,) (metres per radian, helical joints only),
    ``X_tree_R`` (nb, 3, 3) and ``X_tree_p`` (nb, 3) (joint frame in the parent body frame),
    ``theta`` (nb, 10) the inertial parameters of each body (``Model.inertial_parameters``
    order), ``idx_q`` (nb,), ``idx_v`` (nb,).
    Per-dof arrays (nv,): ``lower``, ``upper`` (position limits of 1-dof joints, +-inf for free
    joints), ``velocity_limit``, ``effort_limit``, ``damping`` (viscous, N m s/rad), ``coulomb``
    (N m), ``stribeck`` and ``stribeck_velocity`` (the breakaway excess ``F_s - F_c`` of static
    over Coulomb friction, N m, and its decay velocity ``v_s``: the friction
    ``(coulomb + stribeck exp(-(v / v_s)^2)) sgn(v)``), ``armature`` (reflected rotor inertia,
    kg m^2), ``stiffness`` and ``spring_reference``
    (joint springs ``tau = stiffness (q - spring_reference)`` opposed by the actuator, N m/rad
    or N/m; joints of one dof only). Frames (nf): ``frame_names``,
    ``frame_body`` (-1 for the world), ``frame_R`` (nf, 3, 3), ``frame_p`` (nf, 3).
    ``gravity`` (3,) in the world frame.

    ``physical``: ``"error"`` (default) refuses a body no rigid body can be (inertia about the
    centre of mass not positive semi-definite or violating ``I1 + I2 >= I3``, an inertia
    without mass); ``"warn"`` keeps it; ``"repair"`` repairs it with a warning
    (:func:`repaired_inertial_parameters`), and the model is then ``physical="error"``.
    """

    __slots__ = (
        "name", "parent", "joint_type", "joint_axis", "joint_pitch", "X_tree_R", "X_tree_p", "theta",
        "idx_q", "idx_v", "nq", "nv", "link_names", "body_joint_names", "joint_names",
        "lower", "upper", "velocity_limit", "effort_limit", "damping", "coulomb", "armature",
        "stribeck", "stribeck_velocity", "stiffness", "spring_reference", "coulomb_smoothing", "gravity",
        "frame_names", "frame_body", "frame_R", "frame_p",
        "physical", "kernel", "_frame_index",
    )

    def __init__(
        self,
        *,
        parent,
        joint_type,
        joint_axis,
        X_tree_R,
        X_tree_p,
        theta=None,
        link_names: Sequence[str],
        body_joint_names: Sequence[str],
        gravity=(0.0, 0.0, -9.81),
        lower=None,
        upper=None,
        velocity_limit=None,
        effort_limit=None,
        damping=None,
        coulomb=None,
        armature=None,
        stribeck=None,
        stribeck_velocity=None,
        stiffness=None,
        spring_reference=None,
        coulomb_smoothing: float = 0.0,
        frame_names: Sequence[str] = (),
        frame_body=(),
        frame_R=(),
        frame_p=(),
        joint_pitch=None,
        name: str = "robot",
        physical: str = "error",
        inertia=None,
    ):
        if inertia is not None:  # the old spelling of ``theta``
            theta = renamed_keyword("inertia", inertia, "theta", theta, "Model()", default=None)
        if theta is None:
            raise TypeError("Model() missing the keyword argument 'theta' (nb, 10)")
        setattr_ = object.__setattr__
        parent = np.asarray(parent, dtype=np.int64).reshape(-1)
        nb = parent.shape[0]
        jt = np.asarray(joint_type, dtype=np.int64).reshape(-1)
        if jt.shape != (nb,):
            raise ModelError(f"joint_type must have shape ({nb},), got {jt.shape}")
        # every body checked at once; the first that fails is checked again alone, for the message
        bad = ((parent < -1) | (parent >= np.arange(nb)) | (jt < 0) | (jt >= len(J.NAMES))
               | ((jt == J.FREE) & (parent != -1)))
        for i in np.flatnonzero(bad):
            if not (-1 <= parent[i] < i):
                raise ModelError(f"body {i}: parent index {parent[i]} must satisfy -1 <= parent < {i}")
            if not 0 <= jt[i] < len(J.NAMES):
                raise ModelError(f"body {i}: unknown joint type code {jt[i]}")
            if jt[i] == J.FREE and parent[i] != -1:
                raise ModelError(f"body {i}: a free joint must attach to the world")
        nq_i = J.NQ[jt] if nb else np.zeros(0, np.int64)
        nv_i = J.NV[jt] if nb else np.zeros(0, np.int64)
        idx_q = np.concatenate([[0], np.cumsum(nq_i)[:-1]]).astype(np.int64) if nb else nq_i
        idx_v = np.concatenate([[0], np.cumsum(nv_i)[:-1]]).astype(np.int64) if nb else nv_i
        nq, nv = int(nq_i.sum()), int(nv_i.sum())

        def arr(x, shape, what, fill=0.0):
            # a copy: the checks below normalise in place, and inputs may be read-only model arrays
            a = np.full(shape, fill, dtype=float) if x is None else np.array(x, dtype=float)
            if a.shape != shape:
                raise ModelError(f"{what} must have shape {shape}, got {a.shape}")
            return a

        axis = arr(joint_axis, (nb, 3), "joint_axis")
        pitch = arr(joint_pitch, (nb,), "joint_pitch")
        if not np.all(np.isfinite(pitch)):
            raise ModelError(f"joint_pitch is not finite: {pitch.tolist()}")
        if np.any((pitch != 0) & (jt != J.HELICAL)):
            i = int(np.flatnonzero((pitch != 0) & (jt != J.HELICAL))[0])
            raise ModelError(f"body {i}: joint_pitch {pitch[i]} on a {J.NAMES[jt[i]]} joint (only helical joints have one)")
        R = arr(X_tree_R, (nb, 3, 3), "X_tree_R")
        p = arr(X_tree_p, (nb, 3), "X_tree_p")
        theta = arr(theta, (nb, 10), "theta")
        names = list(link_names)
        jnames = list(body_joint_names)
        if len(names) != nb or len(jnames) != nb:
            raise ModelError(f"link_names and body_joint_names need {nb} entries")
        if physical == "repair":  # the bodies no rigid body can have, made consistent (with a warning)
            fixable = np.isfinite(theta).all(1) & (theta[:, 0] >= 0) if nb else np.zeros(0, bool)
            for i in np.flatnonzero(fixable & ~consistent_inertial_parameters(theta)):
                theta[i], before, after = repaired_inertial_parameters(theta[i])
                warnings.warn(f"body {i} ({names[i]!r}): {repair_note(before, after, theta[i][0])}",
                              RobodynWarning, stacklevel=user_stacklevel())
            physical = "error"
        # every body checked at once; the bodies that fail are checked again one by one, in
        # order, for the message
        finite = np.isfinite(axis).all(1) & np.isfinite(R).reshape(nb, 9).all(1) & np.isfinite(p).all(1)
        one_dof = _AXIAL_CODE[jt]
        norms = np.linalg.norm(np.where(finite[:, None], axis, 0.0), axis=1)
        Rf = np.where(finite[:, None, None], R, np.eye(3))
        rotation = ((np.abs(Rf @ Rf.transpose(0, 2, 1) - np.eye(3)).reshape(nb, 9).max(1, initial=0.0) <= 1e-9)
                    & (np.linalg.det(Rf) >= 0)) if nb else np.ones(0, bool)
        if physical == "error":
            inertial = consistent_inertial_parameters(theta)
        else:
            inertial = np.isfinite(theta).all(1) & (theta[:, 0] >= 0)
        for i in np.flatnonzero(~finite | (one_dof & ~(norms >= 1e-12)) | ~rotation | ~inertial):
            where = f"body {i} ({names[i]!r})"
            for what, a in (("joint_axis", axis[i]), ("X_tree_R", R[i]), ("X_tree_p", p[i])):
                if not np.all(np.isfinite(a)):
                    raise ModelError(f"{where}: {what} is not finite")
            if one_dof[i] and np.linalg.norm(axis[i]) < 1e-12:
                raise ModelError(f"{where}: joint axis is zero")
            if np.abs(R[i] @ R[i].T - np.eye(3)).max() > 1e-9 or np.linalg.det(R[i]) < 0:
                raise ModelError(f"{where}: X_tree_R is not a rotation matrix")
            if physical == "error":
                check_inertial_parameters(theta[i], where)
            elif not (np.all(np.isfinite(theta[i])) and theta[i, 0] >= 0):
                raise ModelError(f"{where}: inertial parameters must be finite with mass >= 0")
        axis[one_dof] = axis[one_dof] / norms[one_dof, None]
        g = arr(gravity, (3,), "gravity")
        if not np.all(np.isfinite(g)):
            raise ModelError("gravity is not finite")

        free_dof = np.zeros(nv, dtype=bool)  # no position limits on free, spherical, planar joints
        for i in np.flatnonzero(nq_i > 1):
            free_dof[idx_v[i]:idx_v[i] + nv_i[i]] = True
        lo = arr(lower, (nv,), "lower", -np.inf)
        hi = arr(upper, (nv,), "upper", np.inf)
        lo[free_dof], hi[free_dof] = -np.inf, np.inf
        dofs = {}
        per_dof = (("velocity_limit", velocity_limit, np.inf), ("effort_limit", effort_limit, np.inf),
                   ("damping", damping, 0.0), ("coulomb", coulomb, 0.0), ("armature", armature, 0.0),
                   ("stribeck", stribeck, 0.0), ("stribeck_velocity", stribeck_velocity, 0.0))
        try:  # all at once; on any failure, one by one, for the message of the first
            values = np.array([arr(val, (nv,), key, fill) for key, val, fill in per_dof])
            checked = not (np.isnan(values).any() or (values < 0).any() or not np.isfinite(values[2:]).all())
        except Exception:  # noqa: BLE001 - the loop below raises it, after the messages of the keys before
            checked = False
        if checked:
            dofs = {key: a for (key, _, _), a in zip(per_dof, values)}
        for key, val, fill in () if checked else per_dof:
            a = arr(val, (nv,), key, fill)
            if np.any(np.isnan(a)) or np.any(a < 0):
                raise ModelError(f"{key} must be non-negative, got {a.tolist()}")
            if key not in ("velocity_limit", "effort_limit") and not np.all(np.isfinite(a)):
                raise ModelError(f"{key} must be finite, got {a.tolist()}")
            dofs[key] = a
        no_decay = (dofs["stribeck"] > 0) & (dofs["stribeck_velocity"] == 0)
        if np.any(no_decay):
            raise ModelError(f"stribeck friction at dofs {np.flatnonzero(no_decay).tolist()} needs a "
                             f"stribeck_velocity > 0 (the velocity over which it decays to the Coulomb level)")
        stiff = arr(stiffness, (nv,), "stiffness")
        if not np.all(np.isfinite(stiff)) or np.any(stiff < 0):
            raise ModelError(f"stiffness must be finite and non-negative, got {stiff.tolist()}")
        ref = arr(spring_reference, (nv,), "spring_reference")
        if not np.all(np.isfinite(ref)):
            raise ModelError(f"spring_reference must be finite, got {ref.tolist()}")
        for i in np.flatnonzero(nv_i > 1) if nb else ():
            k = slice(idx_v[i], idx_v[i] + nv_i[i])
            if np.any(stiff[k] != 0) or np.any(ref[k] != 0):
                raise ModelError(f"body {i}: joint springs (stiffness, spring_reference) on a {J.NAMES[jt[i]]} joint; "
                                 f"only joints of one dof (revolute, prismatic, helical) have them")
        dofs["stiffness"], dofs["spring_reference"] = stiff, ref
        if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo > hi):
            raise ModelError("joint position limits must satisfy lower <= upper")
        if not (np.isfinite(coulomb_smoothing) and coulomb_smoothing >= 0):
            raise ModelError(f"coulomb_smoothing must be finite and >= 0, got {coulomb_smoothing}")

        fnames = list(frame_names)
        nf = len(fnames)
        fb = np.asarray(frame_body, dtype=np.int64).reshape(nf)
        fR = arr(np.reshape(frame_R, (nf, 3, 3)) if nf else None, (nf, 3, 3), "frame_R")
        fp = arr(np.reshape(frame_p, (nf, 3)) if nf else None, (nf, 3), "frame_p")
        if np.any(fb < -1) or np.any(fb >= nb):
            raise ModelError("frame_body indices out of range")
        # every body is a frame too, under its own name
        all_names = names + fnames
        if len(set(all_names)) != len(all_names):
            dup = sorted({n for n in all_names if all_names.count(n) > 1})
            raise ModelError(f"duplicate link or frame names: {dup}")
        one_dof = [name for name, n in zip(jnames, nv_i.tolist()) if n == 1]
        if len(set(one_dof)) != len(one_dof):
            raise ModelError("duplicate joint names")

        if physical not in ("error", "warn"):
            raise ValueError(f"physical must be 'error', 'warn' or 'repair', got {physical!r}")
        setattr_(self, "physical", physical)
        setattr_(self, "name", str(name))
        setattr_(self, "parent", readonly(parent, np.int64))
        setattr_(self, "joint_type", readonly(jt, np.int64))
        setattr_(self, "joint_axis", readonly(axis))
        setattr_(self, "joint_pitch", readonly(pitch))
        setattr_(self, "X_tree_R", readonly(R))
        setattr_(self, "X_tree_p", readonly(p))
        setattr_(self, "theta", readonly(theta))
        setattr_(self, "idx_q", readonly(idx_q, np.int64))
        setattr_(self, "idx_v", readonly(idx_v, np.int64))
        setattr_(self, "nq", nq)
        setattr_(self, "nv", nv)
        setattr_(self, "link_names", tuple(names))
        setattr_(self, "body_joint_names", tuple(jnames))
        setattr_(self, "joint_names", tuple(one_dof))
        setattr_(self, "lower", readonly(lo))
        setattr_(self, "upper", readonly(hi))
        for key, a in dofs.items():
            setattr_(self, key, readonly(a))
        setattr_(self, "coulomb_smoothing", float(coulomb_smoothing))
        setattr_(self, "gravity", readonly(g))
        setattr_(self, "frame_names", tuple(fnames))
        setattr_(self, "frame_body", readonly(fb, np.int64))
        setattr_(self, "frame_R", readonly(fR))
        setattr_(self, "frame_p", readonly(fp))
        index = {n: i for i, n in enumerate(all_names)}
        setattr_(self, "_frame_index", index)
        setattr_(self, "kernel", pack(self))

    def __setattr__(self, key, value):
        raise AttributeError("Model is immutable; use with_inertial_parameters() or replace()")

    def __delattr__(self, key):
        raise AttributeError("Model is immutable; use with_inertial_parameters() or replace()")

    # -- pickling (Dask workers, multiprocessing), copies and content tokens ------------------
    def __getstate__(self) -> dict:
        """The fields, without the kernel tables (rebuilt on unpickling)."""
        return {key: getattr(self, key) for key in self.__slots__ if key != "kernel"}

    def __setstate__(self, state: dict) -> None:
        for key, value in state.items():
            if isinstance(value, np.ndarray):
                value.setflags(write=False)
            object.__setattr__(self, key, value)
        object.__setattr__(self, "kernel", pack(self))

    def __dask_tokenize__(self) -> str:
        """A hash of the content: equal models give equal Dask keys, so a model passed to many
        tasks is sent to each worker once (``robodyn.distributed``)."""
        import hashlib
        import pickle

        return hashlib.sha256(pickle.dumps(self.__getstate__(), protocol=5)).hexdigest()

    # -- derived quantities ------------------------------------------------------------
    @property
    def nbodies(self) -> int:
        return int(self.parent.shape[0])

    @property
    def floating_base(self) -> bool:
        return bool(self.nbodies and self.joint_type[0] == J.FREE)

    @property
    def q_names(self) -> list[str]:
        """One name per entry of ``q`` (nq): the joint's name, or ``<joint>:x``, ``:y``, ``:z``,
        ``:qx``, ``:qy``, ``:qz``, ``:qw`` for a free joint (``:qx`` ... ``:qw`` spherical,
        ``:x``, ``:y``, ``:c``, ``:s`` planar). The names of every file column and report."""
        return J.coordinate_names(self.joint_type, self.body_joint_names, "q")

    @property
    def dof_names(self) -> list[str]:
        """One name per entry of ``v``, ``a`` and ``tau`` (nv): the joint's name, or
        ``<joint>:vx``, ``:vy``, ``:vz``, ``:wx``, ``:wy``, ``:wz`` for a free joint (``:wx`` ...
        spherical, ``:vx``, ``:vy``, ``:wz`` planar)."""
        return J.coordinate_names(self.joint_type, self.body_joint_names, "v")

    @property
    def total_mass(self) -> float:
        return float(self.theta[:, 0].sum())

    def inertial_parameters(self) -> np.ndarray:
        """All inertial parameters, (10 * nbodies,), body after body (order in module doc)."""
        return self.theta.reshape(-1).copy()

    def with_inertial_parameters(self, theta) -> "Model":
        """A new model with the inertial parameters ``theta`` (10 * nbodies,)."""
        theta = np.asarray(theta, dtype=float)
        if theta.shape != (10 * self.nbodies,):
            raise ValueError(f"theta: expected shape ({10 * self.nbodies},), got {theta.shape}")
        return self.replace(theta=theta.reshape(self.nbodies, 10))

    inertia = renamed_attribute("inertia", "theta")  # ``inertia`` names 3 x 3 matrices in robodyn

    def rigid(self) -> "Model":
        """The model without joint friction, springs and armature (``damping``, ``coulomb``,
        ``stribeck``, ``stiffness`` and ``armature`` zero): its ``rnea`` is the textbook ``M(q) a + C(q, v) v +
        g(q)`` of the rigid bodies alone, as ``rnea(..., friction=False, armature=False)`` of
        this model."""
        zero = np.zeros(self.nv)
        return self.replace(damping=zero, coulomb=zero, stribeck=zero, stribeck_velocity=zero, armature=zero,
                            stiffness=zero, spring_reference=zero)

    def replace(self, **changes) -> "Model":
        """A new model with some constructor arguments changed (validated again)."""
        if "inertia" in changes:  # the old spelling of ``theta``
            changes["theta"] = renamed_keyword("inertia", changes.pop("inertia"), "theta", changes.get("theta"),
                                               "Model.replace()", default=None)
        kw = {k: getattr(self, k) for k in (
            "parent", "joint_type", "joint_axis", "X_tree_R", "X_tree_p", "theta", "link_names",
            "body_joint_names", "gravity", "lower", "upper", "velocity_limit", "effort_limit",
            "damping", "coulomb", "armature", "stribeck", "stribeck_velocity", "stiffness", "spring_reference",
            "coulomb_smoothing", "frame_names", "frame_body",
            "frame_R", "frame_p", "name", "physical", "joint_pitch")}
        unknown = set(changes) - set(kw)
        if unknown:
            raise TypeError(f"unknown model fields: {sorted(unknown)}")
        kw.update(changes)
        return Model(**kw)

    def frame_index(self, name: str) -> tuple[int, np.ndarray, np.ndarray]:
        """``(body, R, p)``: the body a link/frame name is attached to and its placement."""
        if not isinstance(name, str):
            raise TypeError(f"frame name must be a string, got {type(name).__name__}")
        try:
            k = self._frame_index[name]
        except KeyError:
            raise ValueError(f"unknown link or frame {name!r}; known: {sorted(self._frame_index)}") from None
        if k < self.nbodies:
            return k, np.eye(3), np.zeros(3)
        k -= self.nbodies
        return int(self.frame_body[k]), self.frame_R[k], self.frame_p[k]

    def body_index(self, body) -> int:
        """Index of a body given by index or by the name of a link merged into it."""
        if isinstance(body, (int, np.integer)):
            if not -self.nbodies <= body < self.nbodies:
                raise ValueError(f"body index {body} out of range for {self.nbodies} bodies")
            return int(body) % self.nbodies
        b, _, _ = self.frame_index(body)
        return b

    # -- display -----------------------------------------------------------------------
    def __repr__(self) -> str:
        lines = [
            f"Model {self.name!r}: nq={self.nq}, nv={self.nv}, {self.nbodies} bodies, "
            f"total mass {self.total_mass:.4g} kg, "
            f"{'floating' if self.floating_base else 'fixed'} base, gravity {self.gravity.tolist()}",
            f"  {'#':>3} {'body':<24} {'joint':<24} {'type':<9} {'parent':<20} {'axis':<22} {'mass':>9}",
        ]
        for i in range(self.nbodies):
            par = self.link_names[self.parent[i]] if self.parent[i] >= 0 else "world"
            ax = "" if J.NQ[self.joint_type[i]] > 1 else np.array2string(self.joint_axis[i], precision=3, suppress_small=True)
            lines.append(
                f"  {i:>3} {self.link_names[i]:<24} {self.body_joint_names[i]:<24} "
                f"{J.NAMES[self.joint_type[i]]:<9} {par:<20} {ax:<22} {self.theta[i, 0]:>9.4g}"
            )
        if self.frame_names:
            lines.append(f"  frames: {', '.join(self.frame_names)}")
        return "\n".join(lines)
