"""URDF writer: ``write_urdf(model, path=None) -> str``, read back by ``load_urdf``.

Each body becomes a link (its ``<inertial>`` at the centre of mass, axes of the body frame,
mass-less bodies without ``<inertial>``) and each joint a revolute, continuous (a revolute
joint without position limits), or prismatic joint with its placement (``rpy`` extrinsic
X-Y-Z, ``R = Rz Ry Rx``), axis, ``<limit>`` and ``<dynamics damping friction>``. A revolute or
prismatic joint's ``<limit>`` always carries ``lower``, ``upper``, ``effort`` and
``velocity`` (urdfdom, hence Pinocchio and ROS, refuse it otherwise); URDF has no infinity,
so "no limit" is written as the largest double, ``1.7976931348623157e+308`` (with its
sign), which ``load_urdf`` reads back as no limit. Frames (links
merged into bodies) become mass-less links on fixed joints. A fixed base's root link keeps
its name (the model's frame attached to the world); a floating base's root link is body 0,
and the file must be loaded with ``floating_base=True``. Other free joints (bodies flying
beside a fixed base) become ``floating`` joints under the root link. Spherical joints, and free
joints beside a floating base, raise ``ValueError``. Numbers are written with ``repr``
(exact round trip).

A 1-dof joint's armature is written as Drake's extension, a ``<transmission>`` whose actuator
has ``<drake:rotor_inertia value>`` (gear ratio 1): Drake reads it as the reflected rotor
inertia, ``load_urdf`` as the armature, and other readers (urdfdom, Pinocchio, ROS) ignore
it. What URDF cannot hold is reported with a :class:`RobodynWarning`: the armature of
multi-dof joints, Coulomb smoothing, and a gravity other than ``(0, 0, -9.81)``
(``load_urdf(gravity=...)`` sets it). A one-sided position limit raises ``ValueError``.
"""

from __future__ import annotations

import warnings
from xml.sax.saxutils import quoteattr

import numpy as np

from ..files import write_text
from .. import joints as J
from ..coupling import is_coupled
from ..errors import RobodynWarning
from ..model import mass_com_inertia
from ._xml import numbers


_num = numbers


def _origin(R, p) -> str:
    from scipy.spatial.transform import Rotation

    with warnings.catch_warnings():  # gimbal lock: scipy picks one of the equivalent angle sets
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(np.asarray(R)).as_euler("xyz")
    return f'<origin xyz="{_num(p)}" rpy="{_num(rpy)}"/>'


def _unique(name: str, taken: set) -> str:
    out, k = name, 1
    while out in taken:
        out, k = f"{name}_{k}", k + 1
    taken.add(out)
    return out


def _inertial(theta) -> list[str]:
    m = float(theta[0])
    if m <= 0.0:
        return []
    m, c, Ic = mass_com_inertia(theta)
    return ["    <inertial>",
            f'      <origin xyz="{_num(c)}" rpy="0.0 0.0 0.0"/>',
            f'      <mass value="{_num(m)}"/>',
            f'      <inertia ixx="{_num(Ic[0, 0])}" ixy="{_num(Ic[0, 1])}" ixz="{_num(Ic[0, 2])}" '
            f'iyy="{_num(Ic[1, 1])}" iyz="{_num(Ic[1, 2])}" izz="{_num(Ic[2, 2])}"/>',
            "    </inertial>"]


def _link_and_joint(model, i: int, kind: str, parent: str) -> list[str]:
    """Body ``i``'s link, and its joint's opening up to the origin (the caller closes it)."""
    return [f"  <link name={quoteattr(model.link_names[i])}>", *_inertial(model.theta[i]), "  </link>",
            f"  <joint name={quoteattr(model.body_joint_names[i])} type=\"{kind}\">",
            f"    <parent link={quoteattr(parent)}/>", f"    <child link={quoteattr(model.link_names[i])}/>",
            f"    {_origin(model.X_tree_R[i], model.X_tree_p[i])}"]


DRAKE = "http://drake.mit.edu"  # the namespace of Drake's URDF extensions
NO_LIMIT = float(np.finfo(float).max)  # URDF has no infinity: the largest double means "no limit"


def _finite(x: float) -> float:
    """``x``, or +-NO_LIMIT for +-inf."""
    return float(x) if np.isfinite(x) else float(np.copysign(NO_LIMIT, x))


def write_urdf(model, path=None) -> str:
    """The URDF text of ``model`` (module docstring); also written to ``path`` if given. A model
    with mimic joints (:class:`~robodyn.coupling.CoupledModel`) is written as its tree with a
    ``<mimic>`` element on each mimic joint (following its independent source)."""
    mimic = {}
    if is_coupled(model):
        mimic = {joint: (source, r, o) for joint, source, r, o in model.mimic}
        model = model.full
    lost = []
    one_dof = J.NV[model.joint_type] == 1
    rotors = [(model.body_joint_names[i], model.armature[model.idx_v[i]]) for i in range(model.nbodies)
              if one_dof[i] and model.armature[model.idx_v[i]] != 0]
    if any(np.any(model.armature[model.idx_v[i]:model.idx_v[i] + J.NV[model.joint_type[i]]] != 0)
           for i in range(model.nbodies) if not one_dof[i]):
        lost.append("armature of multi-dof joints")
    if model.coulomb_smoothing != 0:
        lost.append("coulomb_smoothing")
    if np.any(model.stiffness != 0):
        lost.append("joint springs (stiffness, spring_reference)")
    if np.any(model.stribeck != 0):
        lost.append("Stribeck friction (stribeck, stribeck_velocity; the Coulomb level is written)")
    if np.any(model.gravity != np.array([0.0, 0.0, -9.81])):
        lost.append(f"gravity {model.gravity.tolist()} (pass it to load_urdf)")
    taken = set(model.link_names) | set(model.frame_names)
    drake = f' xmlns:drake="{DRAKE}"' if rotors else ""
    lines = ["<?xml version=\"1.0\"?>", f"<robot name={quoteattr(model.name)}{drake}>"]
    floating = model.floating_base
    world = [k for k in range(len(model.frame_names)) if model.frame_body[k] == -1]
    if floating:
        root = model.link_names[0]
    elif world and np.array_equal(model.frame_R[world[0]], np.eye(3)) and not np.any(model.frame_p[world[0]]):
        root = model.frame_names[world[0]]  # the root link the model was loaded from
    else:
        root = _unique("world", taken)

    def link_of(body: int) -> str:
        return root if body < 0 else model.link_names[body]

    lines.append(f"  <link name={quoteattr(root)}>")
    lines += _inertial(model.theta[0]) if floating else []
    lines.append("  </link>")
    joint_names = set(model.body_joint_names)
    for i in range(model.nbodies):
        jt = model.joint_type[i]
        if jt in (J.SPHERICAL, J.HELICAL):
            raise ValueError(f"write_urdf: joint {model.body_joint_names[i]!r} is {J.NAMES[jt]}, which URDF cannot "
                             "express")
        if jt == J.FREE:
            k = model.idx_v[i]
            if np.any(model.damping[k:k + 6]) or np.any(model.coulomb[k:k + 6]):
                lost.append(f"damping and friction of the free joint {model.body_joint_names[i]!r}")
        if jt == J.FREE and i == 0 and floating:
            continue
        if jt == J.PLANAR:
            lines += _link_and_joint(model, i, "planar", link_of(model.parent[i]))
            lines.append('    <axis xyz="0.0 0.0 1.0"/>')
            k = model.idx_v[i]
            if np.any(model.damping[k:k + 3]) or np.any(model.coulomb[k:k + 3]):
                lost.append(f"damping and friction of the planar joint {model.body_joint_names[i]!r}")
            lines.append("  </joint>")
            continue
        if jt == J.FREE:  # another free body: a floating joint under the fixed world
            if floating:
                raise ValueError(f"write_urdf: free joint {model.body_joint_names[i]!r} beside a floating base, "
                                 "which URDF cannot express (one tree from one root link)")
            lines += _link_and_joint(model, i, "floating", root) + ["  </joint>"]
            continue
        k = model.idx_v[i]
        lo, hi = model.lower[k], model.upper[k]
        bounded = np.isfinite(lo) and np.isfinite(hi)
        if np.isfinite(lo) != np.isfinite(hi):
            raise ValueError(f"write_urdf: joint {model.body_joint_names[i]!r} has a one-sided position limit "
                             f"[{lo}, {hi}], which URDF cannot express")
        kind = ("revolute" if bounded else "continuous") if jt == J.REVOLUTE else "prismatic"
        lines += _link_and_joint(model, i, kind, link_of(model.parent[i]))
        lines.append(f'    <axis xyz="{_num(model.joint_axis[i])}"/>')
        rates = (("velocity", model.velocity_limit[k]), ("effort", model.effort_limit[k]))
        if kind == "continuous":  # a <limit> is optional: only the finite rates
            attrs = " ".join(f'{key}="{_num(val)}"' for key, val in rates if np.isfinite(val))
        else:  # required, with all four attributes
            attrs = " ".join(f'{key}="{_num(_finite(val))}"' for key, val in (("lower", lo), ("upper", hi), *rates))
        if attrs:
            lines.append(f"    <limit {attrs}/>")
        if model.damping[k] or model.coulomb[k]:
            lines.append(f'    <dynamics damping="{_num(model.damping[k])}" friction="{_num(model.coulomb[k])}"/>')
        if model.body_joint_names[i] in mimic:
            source, r, o = mimic[model.body_joint_names[i]]
            lines.append(f'    <mimic joint={quoteattr(source)} multiplier="{_num(r)}" offset="{_num(o)}"/>')
        lines.append("  </joint>")
    for f in range(len(model.frame_names)):
        name, body = model.frame_names[f], int(model.frame_body[f])
        if name == root:
            continue
        jname = _unique(f"{name}_fixed", joint_names)
        lines += [f"  <link name={quoteattr(name)}/>",
                  f"  <joint name={quoteattr(jname)} type=\"fixed\">",
                  f"    <parent link={quoteattr(link_of(body))}/>",
                  f"    <child link={quoteattr(name)}/>",
                  f"    {_origin(model.frame_R[f], model.frame_p[f])}",
                  "  </joint>"]
    for joint, inertia in rotors:  # armature as Drake's rotor inertia (other readers ignore it)
        lines += [f"  <transmission name={quoteattr(joint + '_transmission')}>",
                  "    <type>transmission_interface/SimpleTransmission</type>",
                  f"    <joint name={quoteattr(joint)}>"
                  "<hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>",
                  f"    <actuator name={quoteattr(joint + '_motor')}><drake:rotor_inertia value=\"{_num(inertia)}\"/>"
                  "</actuator>",
                  "  </transmission>"]
    lines.append("</robot>")
    text = "\n".join(lines) + "\n"
    if lost:
        warnings.warn(f"write_urdf: URDF cannot hold {', '.join(lost)}; not written", RobodynWarning, stacklevel=2)
    if path is not None:
        write_text(path, text)
    return text
