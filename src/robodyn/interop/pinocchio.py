"""Pinocchio models to and from robodyn models: :func:`to_pinocchio`, :func:`from_pinocchio`.

Pinocchio (``pip install pin``, version 3 or later; tested with 4.1) is an optional dependency:
it is imported inside the functions, and a missing Pinocchio raises ``ImportError`` naming
``pip install pin``.

How the two models correspond (both are trees with parents before children):

- Pinocchio joint ``j`` (``1 <= j < njoints``; joint 0 is the ``universe``) is robodyn body
  ``i = j - 1``, with ``parent[i] = parents[j] - 1`` (``-1``: the world). The joint order, and
  hence the ``v``, ``a`` and ``tau`` layouts (``idx_v``), are the same one to one.
- ``jointPlacements[j]`` is ``(X_tree_R[i], X_tree_p[i])``: the joint frame in the parent
  joint's (body's) frame; the body frame coincides with the joint frame at ``q = 0``.
- ``inertias[j]`` is ``inertia[i]``: the inertia of everything rigidly attached to the joint,
  in the joint (body) frame. Pinocchio's ``Inertia.toDynamicParameters()`` is robodyn's order
  ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``, about the frame origin. The
  ``universe``'s inertia (links fixed to the world) carries no dynamics and is not converted.
- Joint types: robodyn ``revolute`` <-> ``JointModelRX``/``RY``/``RZ`` (axis +x, +y or +z) or
  ``JointModelRevoluteUnaligned`` (any other axis); ``prismatic`` <-> ``PX``/``PY``/``PZ`` or
  ``PrismaticUnaligned``; ``free`` <-> ``JointModelFreeFlyer`` (at the root only). Pinocchio's
  continuous joints ``RUBX``/``RUBY``/``RUBZ``/``RevoluteUnboundedUnaligned`` become unbounded
  revolute joints (robodyn's continuous joints). ``JointModelSpherical``, ``Planar`` and helical
  joints map to robodyn's; ``JointModelUniversal`` (``R = Rot(axis1, q1) Rot(axis2, q2)``)
  becomes two revolute joints ``<name>[1]``, ``<name>[2]`` on a massless cross link
  ``<link>:<name>``, as ``ModelBuilder`` builds a universal joint (same ``q``, ``v``; one body
  more). ``JointModelMimic`` joints are robodyn's mimic couplings (a
  :class:`~robodyn.coupling.CoupledModel`, both ways). Other Pinocchio joints (translation,
  spherical ZYX, composite, ...) raise ``ModelError``.
- ``q``: a free joint is ``[x, y, z, qx, qy, qz, qw]`` (unit quaternion, scalar last) in both,
  with ``v = [v_lin, omega]`` in the child (base) frame in both: no conversion. A continuous
  joint is ``(cos t, sin t)`` (2 entries) in Pinocchio and ``t`` in robodyn:
  :func:`configuration_to_pinocchio` and :func:`configuration_from_pinocchio` convert.
  :func:`to_pinocchio` writes no continuous joints, so its ``q`` is robodyn's.
- Spatial vectors: Pinocchio's ``Motion`` is ``[linear, angular]`` and ``Force``
  ``[force, torque]``, as robodyn's public arrays.
- Frames: robodyn's link names are Pinocchio ``BODY`` frames on their joint (identity
  placement); robodyn's frames (links merged by fixed joints, the fixed base's root link) are
  ``BODY`` frames too, placed relative to their parent joint; ``OP_FRAME`` and ``SENSOR`` frames
  also become robodyn frames. ``JOINT`` and ``FIXED_JOINT`` frames are joint names, not
  frames, in robodyn.
- Per-dof data (arrays of ``nv``): position limits (1-dof joints), ``velocityLimit``,
  ``effortLimit``, ``damping``, ``friction`` (Coulomb, robodyn's ``coulomb``) and ``armature``.
  Unbounded in robodyn is ``+-inf``, in Pinocchio ``+-numpy.finfo(float).max``.
  Pinocchio's dynamics leave joint friction out; robodyn's add it unless ``friction=False``.
- Units: SI in both (m, kg, kg m^2, rad, N, N m); gravity ``(3,)`` in the world frame.
"""

from __future__ import annotations

import warnings

import numpy as np

from .. import joints as J
from ..errors import ModelError, RobodynWarning, user_stacklevel
from ..coupling import CoupledModel, is_coupled
from ..model import Model, check_inertial_parameters, inertia_about_origin, repair_note, repaired_inertial_parameters

# Pinocchio's "unbounded" (the default of its limits) is the largest double.
_BIG = np.finfo(float).max

_REVOLUTE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned")
_CONTINUOUS = ("JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned")
_PRISMATIC = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")
# Pinocchio joint type -> robodyn joint type
_FROM_PIN = {**dict.fromkeys(_REVOLUTE + _CONTINUOUS, J.REVOLUTE), **dict.fromkeys(_PRISMATIC, J.PRISMATIC),
             "JointModelFreeFlyer": J.FREE, "JointModelSpherical": J.SPHERICAL, "JointModelPlanar": J.PLANAR,
             **dict.fromkeys(("JointModelHX", "JointModelHY", "JointModelHZ", "JointModelHelicalUnaligned"), J.HELICAL)}

UNIVERSAL = -1  # a Pinocchio universal joint: two robodyn revolute joints on a massless cross link

# Symmetric per-dof bounds: robodyn field, Pinocchio's name (the upper bound in Pinocchio >= 4),
# and the suffix of Pinocchio >= 4's separate lower bound ("lower" + suffix).
_BOUNDS = (("effort_limit", "effortLimit", "EffortLimit"), ("velocity_limit", "velocityLimit", "VelocityLimit"),
           ("coulomb", "friction", "DryFrictionLimit"))


def _import_pinocchio(caller: str):
    try:
        import pinocchio
    except ImportError as e:
        raise ImportError(f"{caller} needs Pinocchio, an optional dependency of robodyn: pip install pin") from e
    return pinocchio


def _to_pin_bound(x) -> np.ndarray:
    return np.clip(np.asarray(x, dtype=float), -_BIG, _BIG)


def _from_pin_bound(x) -> np.ndarray:
    x = np.array(x, dtype=float)
    x[x >= _BIG], x[x <= -_BIG] = np.inf, -np.inf
    return x


# ---------------------------------------------------------------------------------------
# robodyn -> Pinocchio


def _check_depth_first(model: Model) -> None:
    """Pinocchio's subtree algorithms (its CRBA) need the bodies in depth-first order."""
    for i in range(1, model.nbodies):  # the parent of i is i - 1 or one of its ancestors
        j = i - 1
        while j >= 0 and j != model.parent[i]:
            j = model.parent[j]
        if j != model.parent[i]:
            raise ValueError(f"to_pinocchio: body {i} ({model.link_names[i]!r}) breaks the depth-first order "
                             "Pinocchio needs (its parent is not body i - 1 or one of its ancestors)")


def _aligned(axis) -> int | None:
    """0, 1, 2 if ``axis`` is +x, +y or +z exactly, else None."""
    k = int(np.argmax(np.abs(axis)))
    return k if axis[k] == 1.0 else None


def _pin_joint(pin, jtype: int, axis: np.ndarray, pitch: float = 0.0):
    if jtype == J.HELICAL:
        k = _aligned(axis)
        if k is not None:
            return (pin.JointModelHX, pin.JointModelHY, pin.JointModelHZ)[k](float(pitch))
        return pin.JointModelHelicalUnaligned(np.asarray(axis, dtype=float), float(pitch))
    if jtype == J.FREE:
        return pin.JointModelFreeFlyer()
    if jtype == J.SPHERICAL:
        return pin.JointModelSpherical()
    if jtype == J.PLANAR:
        return pin.JointModelPlanar()
    aligned = {J.REVOLUTE: (pin.JointModelRX, pin.JointModelRY, pin.JointModelRZ),
               J.PRISMATIC: (pin.JointModelPX, pin.JointModelPY, pin.JointModelPZ)}[jtype]
    k = _aligned(axis)
    if k is not None:
        return aligned[k]()
    unaligned = pin.JointModelRevoluteUnaligned if jtype == J.REVOLUTE else pin.JointModelPrismaticUnaligned
    return unaligned(*axis)


def _pin_inertia(pin, theta: np.ndarray):
    """Pinocchio's Inertia of robodyn's 10 parameters (the same order); a massless body keeps
    its rotational inertia (``FromDynamicParameters`` would divide by the mass)."""
    if theta[0] > 0:
        return pin.Inertia.FromDynamicParameters(np.asarray(theta, dtype=float))
    return pin.Inertia(0.0, np.zeros(3), inertia_about_origin(theta))


def to_pinocchio(model: Model | CoupledModel):
    """The same robot as a ``pinocchio.Model``: same joints in the same order, same ``q``/``v``.

    Converted: the tree (joint ``j = i + 1`` for body ``i``, named ``model.body_joint_names[i]``),
    joint placements ``X_tree``, joint types (revolute and prismatic joints on +x, +y or +z
    become ``JointModelRX``... ``PZ``, other axes the ``Unaligned`` variants, the free joint a
    ``JointModelFreeFlyer``), body inertias (in the body frame), gravity (world frame), the
    model name, and per dof: position limits of 1-dof joints, velocity and effort limits,
    damping, Coulomb friction (Pinocchio's ``friction``) and armature. Frames: a ``JOINT`` frame
    per joint, a ``BODY`` frame per body named ``model.link_names[i]`` (identity placement on
    its joint), and a ``BODY`` frame per robodyn frame (``model.frame_names``, placed in its
    body's frame; on the ``universe`` for the world). ``coulomb_smoothing`` has no Pinocchio
    counterpart. Conventions and frames: see :mod:`robodyn.interop.pinocchio`; ``q``, ``v``,
    ``a`` and ``tau`` can be passed unchanged to Pinocchio's functions.

    A model with mimic joints (:class:`~robodyn.coupling.CoupledModel`) becomes its tree with
    each mimic joint turned into a ``JointModelMimic`` of its source (``transformJointIntoMimic``):
    Pinocchio's ``q``, ``v`` are then the independent coordinates, in robodyn's order. Pinocchio
    needs each source before its mimic joint, and its mimic of a helical joint is not usable
    (``ValueError`` for both); it keeps no limits, damping, friction or armature of a mimic
    joint (a warning names those that are lost).

    Pinocchio's subtree algorithms (its CRBA) need the bodies in depth-first order; a model in
    another order (a random tree, say) raises ``ValueError``. Pinocchio is imported here (an
    optional dependency); without it this raises ``ImportError`` (``pip install pin``).
    """
    pin = _import_pinocchio("to_pinocchio")
    if is_coupled(model):
        return _mimic_to_pinocchio(pin, model, to_pinocchio(model.full))
    _check_depth_first(model)
    pm = pin.Model()
    pm.name = model.name
    pm.gravity = pin.Motion(np.asarray(model.gravity, dtype=float), np.zeros(3))
    body_frame = {-1: 0}  # robodyn body -> Pinocchio frame of its link (the world: "universe")
    for i in range(model.nbodies):
        parent = int(model.parent[i])
        placement = pin.SE3(np.asarray(model.X_tree_R[i]), np.asarray(model.X_tree_p[i]))
        jid = pm.addJoint(parent + 1, _pin_joint(pin, int(model.joint_type[i]), model.joint_axis[i], model.joint_pitch[i]),
                          placement, model.body_joint_names[i])
        pm.appendBodyToJoint(jid, _pin_inertia(pin, model.theta[i]), pin.SE3.Identity())
        joint_frame = pm.addJointFrame(jid, body_frame[parent])
        body_frame[i] = pm.addBodyFrame(model.link_names[i], jid, pin.SE3.Identity(), joint_frame)
    for name, b, R, p in zip(model.frame_names, model.frame_body, model.frame_R, model.frame_p):
        frame = pin.Frame(name, int(b) + 1, body_frame[int(b)], pin.SE3(np.asarray(R), np.asarray(p)),
                          pin.FrameType.BODY)
        pm.addFrame(frame, False)

    one_dof = J.NQ[model.joint_type] == 1  # free, spherical, planar joints keep Pinocchio's default limits
    lower, upper = pm.lowerPositionLimit.copy(), pm.upperPositionLimit.copy()
    lower[model.idx_q[one_dof]] = _to_pin_bound(model.lower[model.idx_v[one_dof]])
    upper[model.idx_q[one_dof]] = _to_pin_bound(model.upper[model.idx_v[one_dof]])
    pm.lowerPositionLimit, pm.upperPositionLimit = lower, upper
    for field, name, suffix in _BOUNDS:
        bound = _to_pin_bound(getattr(model, field))
        setattr(pm, name, bound)
        if hasattr(pm, "lower" + suffix):  # Pinocchio >= 4: a separate lower bound
            setattr(pm, "lower" + suffix, -bound)
    pm.damping = np.asarray(model.damping, dtype=float).copy()
    pm.armature = np.asarray(model.armature, dtype=float).copy()
    if np.any(model.stiffness != 0):
        sprung = [model.dof_names[k] for k in np.flatnonzero(model.stiffness)]
        warnings.warn(f"to_pinocchio: joint springs of {sprung} not converted (a pinocchio.Model has none)",
                      RobodynWarning, stacklevel=2)
    if np.any(model.stribeck != 0):
        named = [model.dof_names[k] for k in np.flatnonzero(model.stribeck)]
        warnings.warn(f"to_pinocchio: Stribeck friction of {named} not converted (a pinocchio.Model has none)",
                      RobodynWarning, stacklevel=2)
    return pm


def _mimic_to_pinocchio(pin, model: CoupledModel, pm):
    """``pm`` (the full tree's Pinocchio model) with the mimic joints of ``model`` turned into
    ``JointModelMimic`` joints (Pinocchio joint ``i + 1`` is robodyn body ``i``)."""
    full = model.full
    body = {name: i for i, name in enumerate(full.body_joint_names)}
    lost = []
    for joint, source, r, o in model.mimic:
        i, s = body[joint], body[source]
        if s > i:
            raise ValueError(f"to_pinocchio: mimic joint {joint!r} comes before its source {source!r} in the tree; "
                             "Pinocchio's mimic joints need the source first")
        if full.joint_type[i] == J.HELICAL:  # checked against the gradient of the potential energy
            raise ValueError(f"to_pinocchio: mimic joint {joint!r} is helical; Pinocchio's mimic of a helical "
                             "joint is not usable (4.1 computes a wrong rnea for JointModelHX/HY/HZ and crashes on "
                             "JointModelHelicalUnaligned); convert model.full and couple it in Pinocchio otherwise")
        k = full.idx_v[i]
        kept = [f"{field} {getattr(full, field)[k]:g}" for field in ("damping", "coulomb", "armature", "stiffness")
                if getattr(full, field)[k] != 0]
        if kept:
            lost.append(f"{joint!r} ({', '.join(kept)})")
        pm = pin.transformJointIntoMimic(pm, s + 1, i + 1, float(r), float(o))
    if lost:
        warnings.warn(f"to_pinocchio: a Pinocchio mimic joint has no damping, friction, armature or spring: not "
                      f"converted for {', '.join(lost)}", RobodynWarning, stacklevel=user_stacklevel())
    return pm


# ---------------------------------------------------------------------------------------
# Pinocchio -> robodyn


def _joint_type_and_axis(pm, j: int, source: str) -> tuple[int, np.ndarray, float]:
    """robodyn's joint type, axis (child frame) and pitch of Pinocchio joint ``j``, or ModelError."""
    jm, name = pm.joints[j], pm.names[j]
    kind = jm.shortname()
    if kind == "JointModelMimic":
        return _mimic_type_and_axis(pm, j, source)
    if kind == "JointModelUniversal":  # R = Rot(axis1, q1) Rot(axis2, q2): two revolute joints
        u = jm.extract()  # the JointModelUniversal itself (its data's S is not reliably filled by calc(q))
        return UNIVERSAL, np.stack([np.asarray(u.axis1, dtype=float), np.asarray(u.axis2, dtype=float)]), 0.0
    if kind not in _FROM_PIN:
        raise ModelError(
            f"{source}: joint {name!r} is a {kind} ({jm.nq} q, {jm.nv} v), which robodyn cannot represent; "
            f"supported Pinocchio joints: {', '.join(_FROM_PIN)}")
    jtype = _FROM_PIN[kind]
    if jtype == J.FREE:
        if pm.parents[j] != 0:
            raise ModelError(f"{source}: joint {name!r} is a JointModelFreeFlyer below joint "
                             f"{pm.names[pm.parents[j]]!r}; robodyn's free joint must attach to the world")
        return jtype, np.zeros(3), 0.0
    if jtype in (J.SPHERICAL, J.PLANAR):
        return jtype, np.zeros(3), 0.0
    jd = jm.createData()
    jm.calc(jd, np.zeros(jm.nq))  # a helical joint's data holds S only once computed
    S = np.asarray(jd.S, dtype=float).reshape(6)  # constant, [linear; angular]
    if jtype == J.HELICAL:  # S = [pitch axis; axis]
        return jtype, S[3:], float(S[:3] @ S[3:])
    return jtype, (S[3:] if jtype == J.REVOLUTE else S[:3]), 0.0


def _mimic_source(pm, j: int) -> int:
    """The Pinocchio joint that mimic joint ``j`` follows: the joint whose velocity it shares
    (``idx_v``; ``mimicked_joints`` is not kept in the order of ``mimicking_joints``)."""
    return next(k for k in range(1, pm.njoints) if pm.joints[k].shortname() != "JointModelMimic"
                and pm.joints[k].nv == 1 and pm.joints[k].idx_v == pm.joints[j].idx_v)


def _mimic_type_and_axis(pm, j: int, source: str) -> tuple[int, np.ndarray, float]:
    """Type, axis and pitch of the joint inside Pinocchio mimic joint ``j`` (which Python does
    not expose), from its motion: ``X_J(t) = jointPlacement^-1 liMi`` at ``t = 1`` (the source
    moved to ``(1 - offset) / scaling`` from the neutral configuration) is ``Rot(a, 1)`` for a
    revolute joint, ``Trans(a)`` for a prismatic one and ``Rot(a, 1) Trans(h a)`` for a helical
    one of pitch ``h``."""
    import pinocchio as pin

    jm = pm.joints[j].extract()
    p = pm.joints[_mimic_source(pm, j)]
    if jm.scaling == 0 or p.nv != 1:
        raise ModelError(f"{source}: mimic joint {pm.names[j]!r}: scaling {jm.scaling} of a {p.shortname()}; "
                         "robodyn couples joints of one dof with a non-zero multiplier")
    dv = np.zeros(pm.nv)
    dv[p.idx_v] = (1.0 - jm.offset) / jm.scaling
    data = pm.createData()
    pin.forwardKinematics(pm, data, pin.integrate(pm, pin.neutral(pm), dv))
    X = pm.jointPlacements[j].inverse() * data.liMi[j]
    w, t = np.asarray(pin.log3(X.rotation), dtype=float), np.asarray(X.translation, dtype=float)

    def unit(x):
        x = np.where(np.abs(x) < 1e-14, 0.0, x)
        return x / np.linalg.norm(x)

    if np.linalg.norm(w) < 1e-12:
        return J.PRISMATIC, unit(t), 0.0
    axis = unit(w)
    pitch = float(t @ axis)
    return (J.HELICAL, axis, pitch) if abs(pitch) > 1e-14 else (J.REVOLUTE, axis, 0.0)


def _link_names_and_frames(pin, pm):
    """The name of each body (its joint's first ``BODY`` frame with identity placement, else the
    joint's name) and the other ``BODY``/``OP_FRAME``/``SENSOR`` frames as
    ``(name, body, R, p)`` with the placement in the body frame (``body = -1``: the world)."""
    link_frame = {}  # Pinocchio joint -> index of the frame that names its body
    for k, f in enumerate(pm.frames):
        if f.type == pin.FrameType.BODY and f.parentJoint > 0 and f.parentJoint not in link_frame \
                and f.placement.isIdentity():
            link_frame[f.parentJoint] = k
    names = [pm.frames[link_frame[j]].name if j in link_frame else pm.names[j] for j in range(1, pm.njoints)]
    kept = (pin.FrameType.BODY, pin.FrameType.OP_FRAME, pin.FrameType.SENSOR)
    taken = set(link_frame.values())
    frames = [(f.name, f.parentJoint - 1, f.placement.rotation, f.placement.translation)
              for k, f in enumerate(pm.frames) if f.type in kept and k not in taken]
    return names, frames


def from_pinocchio(pin_model, *, physical: str = "error") -> Model | CoupledModel:
    """The robodyn :class:`~robodyn.model.Model` of a ``pinocchio.Model``, joints in the same order.

    Converted: the tree (body ``i`` for Pinocchio joint ``j = i + 1``, joint named
    ``pin_model.names[j]``), ``jointPlacements``, joint types (``RX``/``RY``/``RZ`` and
    ``RevoluteUnaligned`` -> revolute; ``RUBX``/``RUBY``/``RUBZ`` and
    ``RevoluteUnboundedUnaligned`` -> unbounded revolute, i.e. robodyn's continuous joint with one
    angle instead of ``(cos, sin)``; ``PX``/``PY``/``PZ`` and ``PrismaticUnaligned`` ->
    prismatic; ``FreeFlyer`` at the root -> free joint, same ``q``/``v`` layout; ``Universal``
    -> two revolute joints on a massless cross link, so that body indices after it are
    shifted by one), ``inertias``,
    gravity (linear part), the model name, and per dof: position limits of 1-dof joints,
    ``velocityLimit``, ``effortLimit``, ``damping``, ``friction`` (Coulomb) and ``armature``
    (Pinocchio's ``+-max double`` becomes ``+-inf``). Bodies are named after their link (the
    joint's first ``BODY`` frame with identity placement; the joint name if there is none);
    the other ``BODY``, ``OP_FRAME`` and ``SENSOR`` frames become ``model.frame_names``.
    Conventions and frames: see :mod:`robodyn.interop.pinocchio`; ``v``, ``a`` and ``tau`` are
    the same vectors in both, ``q`` too unless the model has continuous joints
    (:func:`configuration_from_pinocchio`).

    The Pinocchio order is kept as it is (``ModelBuilder`` would reorder a tree depth first).
    ``physical="error"`` rejects bodies whose inertia no rigid body can have (``ModelError``),
    ``"warn"`` keeps them with a :class:`~robodyn.errors.RobodynWarning`, ``"repair"`` repairs
    them with one, as ``load_urdf``.

    Mimic joints (``JointModelMimic``, e.g. ``buildModelFromUrdf(..., mimic=True)``) make a
    :class:`~robodyn.coupling.CoupledModel`: its tree has the mimic joints as ordinary joints
    (the joint inside each ``JointModelMimic``: revolute, prismatic or helical, without limits,
    damping, friction or armature, which Pinocchio does not keep for them), coupled to their
    source by Pinocchio's ``scaling`` and ``offset``; ``q``, ``v`` are Pinocchio's.

    Raises ``ModelError`` naming the joint for joint types robodyn has no counterpart of
    (translation, composite, spherical ZYX, ...) and free flyers below the root. ``rotorInertia`` and ``rotorGearRatio`` (not used by
    Pinocchio's dynamics, which use ``armature``) are not converted: a non-zero
    ``rotorInertia`` is reported by a warning.
    """
    pin = _import_pinocchio("from_pinocchio")
    if not isinstance(pin_model, pin.Model):
        raise TypeError(f"from_pinocchio: expected a pinocchio.Model, got {type(pin_model).__name__}")
    if physical not in ("error", "warn", "repair"):
        raise ValueError(f"physical must be 'error', 'warn' or 'repair', got {physical!r}")
    pm = pin_model
    source = f"from_pinocchio(model {pm.name!r})"
    joints = range(1, pm.njoints)
    kinds = [_joint_type_and_axis(pm, j, source) for j in joints]
    names, frames = _link_names_and_frames(pin, pm)
    theta = np.reshape([pm.inertias[j].toDynamicParameters() for j in joints], (len(joints), 10))
    for i, t in enumerate(theta):
        try:
            check_inertial_parameters(t, f"{source}: body {i} ({names[i]!r}, joint {pm.names[i + 1]!r})")
        except ModelError as e:
            if physical == "error":
                raise ModelError(f"{e} (convert with physical='warn' to keep it anyway, or physical='repair' to "
                                 "repair it)") from None
            if physical == "repair":
                theta[i], before, after = repaired_inertial_parameters(t)
                warnings.warn(f"{e}; {repair_note(before, after, t[0])}", RobodynWarning, stacklevel=2)
            else:
                warnings.warn(f"{e}; kept as given (physical='warn')", RobodynWarning, stacklevel=2)
    body_of = {0: -1}  # Pinocchio joint -> the robodyn body carrying its inertia
    bodies = dict(parent=[], jtype=[], axis=[], pitch=[], R=[], p=[], theta=[], link=[], joint=[])

    def add(parent, jtype, axis, pitch, R, p, th, link, joint):
        for key, value in zip(bodies, (parent, jtype, axis, pitch, R, p, th, link, joint)):
            bodies[key].append(value)
        return len(bodies["parent"]) - 1

    for i, (j, (jtype, axis, pitch)) in enumerate(zip(joints, kinds)):
        X, parent = pm.jointPlacements[j], body_of[pm.parents[j]]
        if jtype == UNIVERSAL:
            cross = add(parent, J.REVOLUTE, axis[0], 0.0, X.rotation, X.translation, np.zeros(10),
                        f"{names[i]}:{pm.names[j]}", f"{pm.names[j]}[1]")
            body_of[j] = add(cross, J.REVOLUTE, axis[1], 0.0, np.eye(3), np.zeros(3), theta[i], names[i],
                             f"{pm.names[j]}[2]")
        else:
            body_of[j] = add(parent, jtype, axis, pitch, X.rotation, X.translation, theta[i], names[i], pm.names[j])

    # position limits: the q entry of each bounded 1-dof joint (continuous and free: unbounded)
    lower, upper = np.full(pm.nv, -np.inf), np.full(pm.nv, np.inf)
    q_lower, q_upper = _from_pin_bound(pm.lowerPositionLimit), _from_pin_bound(pm.upperPositionLimit)
    for jm in (pm.joints[j] for j in joints if pm.joints[j].shortname() in _REVOLUTE + _PRISMATIC
               + ("JointModelUniversal",)):
        k, n = jm.idx_v, jm.nv  # one q entry per dof
        lower[k:k + n], upper[k:k + n] = q_lower[jm.idx_q:jm.idx_q + n], q_upper[jm.idx_q:jm.idx_q + n]
    # a mimic joint has no dof of Pinocchio's: -1 in dof_of (the tree's dof -> Pinocchio's), and
    # no limits, damping, friction or armature
    mimic = [j for j in joints if pm.joints[j].shortname() == "JointModelMimic"]
    dof_of = np.concatenate([np.full(pm.joints[j].extract().nvExtended, -1) if j in mimic
                             else np.arange(pm.joints[j].idx_v, pm.joints[j].idx_v + pm.joints[j].nv)
                             for j in joints] or [np.zeros(0, int)]).astype(int)

    def per_dof(x, fill):
        return np.where(dof_of >= 0, np.asarray(x, dtype=float)[dof_of], fill)

    lower, upper = per_dof(lower, -np.inf), per_dof(upper, np.inf)
    dofs = {field: per_dof(_from_pin_bound(getattr(pm, name)), np.inf if field != "coulomb" else 0.0)
            for field, name, _ in _BOUNDS}
    if np.any(np.asarray(pm.rotorInertia) != 0):
        warnings.warn(f"{source}: rotorInertia {np.asarray(pm.rotorInertia).tolist()} not converted "
                      "(Pinocchio's dynamics use armature; add rotorInertia * rotorGearRatio**2 to the "
                      "armature if that is the reflected inertia you mean)", RobodynWarning, stacklevel=2)
    gravity = pm.gravity
    if np.any(gravity.angular != 0):
        warnings.warn(f"{source}: angular part {gravity.angular.tolist()} of gravity ignored",
                      RobodynWarning, stacklevel=2)
    nb = len(bodies["parent"])
    full = Model(
        parent=bodies["parent"], joint_type=bodies["jtype"], joint_axis=np.reshape(bodies["axis"], (nb, 3)),
        joint_pitch=np.asarray(bodies["pitch"], dtype=float), X_tree_R=np.reshape(bodies["R"], (nb, 3, 3)),
        X_tree_p=np.reshape(bodies["p"], (nb, 3)), theta=np.reshape(bodies["theta"], (nb, 10)),
        link_names=bodies["link"], body_joint_names=bodies["joint"],
        gravity=gravity.linear, lower=lower, upper=upper, damping=per_dof(pm.damping, 0.0),
        armature=per_dof(pm.armature, 0.0),
        frame_names=[f[0] for f in frames], frame_body=[body_of[f[1] + 1] for f in frames],
        frame_R=np.reshape([f[2] for f in frames], (-1, 3, 3)), frame_p=np.reshape([f[3] for f in frames], (-1, 3)),
        name=pm.name, physical=physical, **dofs,
    )
    if not mimic:
        return full
    rules = [(j, pm.joints[j].extract()) for j in mimic]
    return CoupledModel(full, [(pm.names[j], pm.names[_mimic_source(pm, j)], m.scaling, m.offset) for j, m in rules])


# ---------------------------------------------------------------------------------------
# configurations


def _continuous_q(pin_model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``keep``: the Pinocchio q index of each robodyn q entry; ``rd_idx`` and ``pin_idx``: the
    robodyn q index (the angle) and the Pinocchio q index (``cos``; ``sin`` follows) of each
    continuous joint."""
    keep, rd_idx, pin_idx = [], [], []
    for j in range(1, pin_model.njoints):
        jm = pin_model.joints[j]
        if jm.shortname() in _CONTINUOUS:
            rd_idx.append(len(keep))
            pin_idx.append(jm.idx_q)
            keep.append(jm.idx_q)
        else:
            keep.extend(range(jm.idx_q, jm.idx_q + jm.nq))
    return np.array(keep, dtype=np.int64), np.array(rd_idx, dtype=np.int64), np.array(pin_idx, dtype=np.int64)


def configuration_to_pinocchio(pin_model, q) -> np.ndarray:
    """Pinocchio's configuration ``(..., pin_model.nq)`` of robodyn's ``q`` ``(..., nq)`` for
    the model ``from_pinocchio(pin_model)``: each continuous joint's angle ``t`` becomes
    ``(cos t, sin t)``; every other entry is copied (free joints: same quaternion layout)."""
    keep, rd_idx, pin_idx = _continuous_q(pin_model)
    q = np.asarray(q, dtype=float)
    if q.ndim < 1 or q.shape[-1] != keep.size:
        raise ValueError(f"q: expected shape (..., {keep.size}), got {q.shape}")
    out = np.empty(q.shape[:-1] + (pin_model.nq,))
    out[..., keep] = q
    out[..., pin_idx + 1] = np.sin(q[..., rd_idx])
    out[..., pin_idx] = np.cos(q[..., rd_idx])
    return out


def configuration_from_pinocchio(pin_model, q_pin) -> np.ndarray:
    """robodyn's ``q`` ``(..., nq)`` of Pinocchio's configuration ``(..., pin_model.nq)`` for
    the model ``from_pinocchio(pin_model)``: each continuous joint's ``(cos t, sin t)`` becomes
    ``t = atan2(sin, cos)`` in ``(-pi, pi]``; every other entry is copied."""
    keep, rd_idx, pin_idx = _continuous_q(pin_model)
    q_pin = np.asarray(q_pin, dtype=float)
    if q_pin.ndim < 1 or q_pin.shape[-1] != pin_model.nq:
        raise ValueError(f"q_pin: expected shape (..., {pin_model.nq}), got {q_pin.shape}")
    q = q_pin[..., keep]
    q[..., rd_idx] = np.arctan2(q_pin[..., pin_idx + 1], q_pin[..., pin_idx])
    return q
