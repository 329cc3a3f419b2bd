"""MJCF writer: ``write_mjcf(model, path=None) -> str``, compiled by MuJoCo and read back by
:func:`~robodyn.io.mjcf.load_mjcf`.

Each body becomes a ``<body>`` at its ``X_tree`` placement (``pos``, ``quat`` w x y z) with its
joint at the body origin: ``hinge`` (revolute), ``slide`` (prismatic), ``ball`` (spherical),
``free`` (whose ``X_tree`` must be the identity: MuJoCo places a free body by its ``qpos``
alone), with ``range`` where both limits are finite, ``damping``, ``armature``
and ``frictionloss`` (Coulomb friction), and an ``<inertial>`` (``pos`` the centre of mass,
``mass``, ``fullinertia`` about it in the body axes). Frames become ``<site>`` elements.
Angles are in radians (``<compiler angle="radian">``), gravity in ``<option>``; numbers are
written with ``repr`` (exact round trip).

MuJoCo refuses a moving body without mass and inertia. A chain of massless bodies that each
carry one child and no frame (as :func:`load_mjcf` makes of a body with several joints) is
written as one MuJoCo body with several joints: with ``C_j`` the placement of the chain's last
body in body ``j``'s frame at ``q = 0``, joint ``j`` sits at ``C_j^-1``'s origin with axis
``R_Cj^T a_j`` in the last body's frame, so that MuJoCo's product of rotations about anchors,
in order, is the chain's ``X_1 J_1 X_2 J_2 ... X_n J_n``. Any other massless moving body raises
``ValueError`` (a massless body on a free joint too: it merges no joint), as do one-sided
position limits and free joints placed away from the world origin. Velocity and effort
limits and Coulomb smoothing, which MJCF joints do not hold, are reported in a
:class:`~robodyn.errors.RobodynWarning`, as are principal moments of inertia below ``1e-12``
of the model's largest (point masses, which MuJoCo refuses): the file raises them to that
bound with ``<compiler boundinertia>``.
"""

from __future__ import annotations

import warnings
from xml.sax.saxutils import quoteattr

import numpy as np

from .. import joints as J
from ..coupling import is_coupled
from ..errors import RobodynWarning
from ..files import write_text
from ..model import mass_com_inertia
from ._xml import numbers

_KIND = {J.REVOLUTE: "hinge", J.PRISMATIC: "slide", J.SPHERICAL: "ball", J.FREE: "free"}


def _quat(R) -> str:
    """``quat="w x y z"`` of a rotation matrix."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(np.asarray(R)).as_quat()
    return f'quat="{numbers([w, x, y, z])}"'


def _pose(R, p) -> str:
    return f'pos="{numbers(p)}" {_quat(R)}'


class _Writer:
    def __init__(self, model):
        self.m = model
        self.children = [[] for _ in range(model.nbodies)]
        self.roots = []
        for i in range(model.nbodies):
            (self.children[model.parent[i]] if model.parent[i] >= 0 else self.roots).append(i)
        self.frames = [[] for _ in range(model.nbodies + 1)]  # the last list: the world's
        for f, b in enumerate(model.frame_body):
            self.frames[int(b)].append(f)
        self.lines: list[str] = []
        # MuJoCo refuses principal moments below 1e-15 (point masses): they are raised to
        # 1e-12 of the largest inertia of the model by <compiler boundinertia>, with a warning
        scale = max([np.abs(mass_com_inertia(t)[2]).max() for t in model.theta] + [0.0])
        self.bound = 1e-12 * scale if scale > 0 else 1e-12
        self.bounded: list[str] = []

    def massless(self, i) -> bool:
        m, _, Ic = mass_com_inertia(self.m.theta[i])
        return m <= 0.0 and not np.any(Ic)

    def chain(self, i) -> list[int]:
        """Body ``i`` and the massless, frameless single children after it (see the module)."""
        out = [i]
        if self.m.joint_type[i] == J.FREE:  # a <freejoint> body holds no other joint
            return out
        while (self.massless(out[-1]) and not self.frames[out[-1]] and len(self.children[out[-1]]) == 1
               and self.m.joint_type[self.children[out[-1]][0]] != J.FREE):
            out.append(self.children[out[-1]][0])
        return out

    def sites(self, body, indent) -> None:
        m = self.m
        for f in self.frames[body]:
            self.lines.append(f"{indent}<site name={quoteattr(m.frame_names[f])} "
                              f"{_pose(m.frame_R[f], m.frame_p[f])}/>")

    def joint(self, i, axis, anchor, indent) -> None:
        m = self.m
        jt, k, name = int(m.joint_type[i]), int(m.idx_v[i]), m.body_joint_names[i]
        if jt not in _KIND:
            raise ValueError(f"write_mjcf: joint {name!r} is {J.NAMES[jt]}, which MJCF cannot express")
        attrs = f"name={quoteattr(name)} type=\"{_KIND[jt]}\""
        if jt != J.FREE:
            attrs += f' pos="{numbers(anchor)}"'
        if jt in (J.REVOLUTE, J.PRISMATIC):
            attrs += f' axis="{numbers(axis)}"'
            lo, hi = m.lower[k], m.upper[k]
            if np.isfinite(lo) != np.isfinite(hi):
                raise ValueError(f"write_mjcf: joint {name!r} has a one-sided position limit [{lo}, {hi}], "
                                 "which MJCF cannot express")
            attrs += f' range="{numbers([lo, hi])}" limited="true"' if np.isfinite(lo) else ' limited="false"'
        n = int(J.NV[jt])
        for key, field in (("damping", "damping"), ("armature", "armature"), ("frictionloss", "coulomb")):
            values = getattr(m, field)[k:k + n]
            if np.any(values != values[0]):
                raise ValueError(f"write_mjcf: joint {name!r} has {field} {values.tolist()} differing between its "
                                 "dofs; an MJCF joint holds one value")
            if values[0]:
                attrs += f' {key}="{numbers(values[0])}"'
        if m.stiffness[k] or m.spring_reference[k]:  # joints of one dof only (Model checks)
            attrs += f' stiffness="{numbers(m.stiffness[k])}" springref="{numbers(m.spring_reference[k])}"'
        self.lines.append(f"{indent}<joint {attrs}/>")

    def body(self, i, indent) -> None:
        m = self.m
        chain = self.chain(i)
        last = chain[-1]
        # C[j]: the placement of the last body in body chain[j]'s frame at q = 0
        C = [(np.eye(3), np.zeros(3))]
        for b in reversed(chain[1:]):
            R, p = C[0]
            C.insert(0, (m.X_tree_R[b] @ R, m.X_tree_R[b] @ p + m.X_tree_p[b]))
        R0, p0 = m.X_tree_R[i] @ C[0][0], m.X_tree_R[i] @ C[0][1] + m.X_tree_p[i]
        if m.joint_type[i] == J.FREE:
            if not (np.array_equal(m.X_tree_R[i], np.eye(3)) and not np.any(m.X_tree_p[i])):
                raise ValueError(f"write_mjcf: free joint {m.body_joint_names[i]!r} has a placement in the world; "
                                 "MuJoCo places a free body by its qpos alone")
            self.lines.append(f"{indent}<body name={quoteattr(m.link_names[i])}>")
            self.joint(i, None, None, indent + "  ")
        else:
            self.lines.append(f"{indent}<body name={quoteattr(m.link_names[last])} {_pose(R0, p0)}>")
            for b, (R, p) in zip(chain, C):
                self.joint(b, R.T @ m.joint_axis[b], -R.T @ p, indent + "  ")
        mass, c, Ic = mass_com_inertia(m.theta[last])
        if mass <= 0:
            raise ValueError(f"write_mjcf: body {m.link_names[last]!r} moves without mass, which MuJoCo refuses "
                             "(only a chain of massless bodies with one child each merges into one MuJoCo body)")
        if np.linalg.eigvalsh(Ic)[0] < self.bound:
            self.bounded.append(m.link_names[last])
        f = (Ic[0, 0], Ic[1, 1], Ic[2, 2], Ic[0, 1], Ic[0, 2], Ic[1, 2])
        self.lines.append(f'{indent}  <inertial pos="{numbers(c)}" mass="{numbers(mass)}" fullinertia="{numbers(f)}"/>')
        self.sites(last, indent + "  ")
        for child in self.children[last]:
            self.body(child, indent + "  ")
        self.lines.append(f"{indent}</body>")


def write_mjcf(model, path=None) -> str:
    """The MJCF text of ``model`` (module docstring); also written to ``path`` if given. A model
    with mimic joints (:class:`~robodyn.coupling.CoupledModel`) is written as its tree with an
    ``<equality><joint joint1="mimic" joint2="source" polycoef="offset multiplier 0 0 0"/>``
    per mimic joint (the joints' ``ref`` is 0, so MuJoCo's ``y - y0 = a0 + a1 (x - x0)`` is
    ``q_mimic = multiplier q_source + offset``; MuJoCo holds it softly, :func:`load_mjcf` reads
    it back as the same coupling). Only hinge and slide joints can be coupled in MJCF."""
    mimic = ()
    if is_coupled(model):
        mimic, model = model.mimic, model.full
        names = dict(zip(model.body_joint_names, model.joint_type))
        helical = [j for j, s, _, _ in mimic if names[j] not in (J.REVOLUTE, J.PRISMATIC)
                   or names[s] not in (J.REVOLUTE, J.PRISMATIC)]
        if helical:
            raise ValueError(f"write_mjcf: mimic couplings of {helical} involve a joint that is not a hinge or "
                             "slide, which an MJCF joint equality cannot hold")
    lost = []
    if np.any(np.isfinite(model.velocity_limit)):
        lost.append("velocity limits (not written)")
    if np.any(np.isfinite(model.effort_limit)):
        lost.append("effort limits (not written)")
    if model.coulomb_smoothing != 0:
        lost.append("coulomb_smoothing (not written)")
    if np.any(model.stribeck != 0):
        lost.append("Stribeck friction (stribeck, stribeck_velocity; frictionloss holds the Coulomb level)")
    w = _Writer(model)
    w.lines += [f"<mujoco model={quoteattr(model.name)}>", '  <compiler angle="radian" autolimits="true"/>',
                f'  <option gravity="{numbers(model.gravity)}"/>', "  <worldbody>"]
    w.sites(-1, "    ")
    for i in w.roots:
        w.body(i, "    ")
    w.lines.append("  </worldbody>")
    if mimic:
        w.lines.append("  <equality>")
        w.lines += [f"    <joint joint1={quoteattr(j)} joint2={quoteattr(s)} polycoef=\"{numbers([o, r, 0, 0, 0])}\"/>"
                    for j, s, r, o in mimic]
        w.lines.append("  </equality>")
    w.lines.append("</mujoco>")
    if w.bounded:
        w.lines[1] = f'  <compiler angle="radian" autolimits="true" boundinertia="{numbers(w.bound)}"/>'
        lost.append(f"principal inertias below {w.bound:.3g} (point masses, which MuJoCo refuses) of bodies "
                    f"{w.bounded}: written raised to that bound")
    text = "\n".join(w.lines) + "\n"
    if lost:
        warnings.warn(f"write_mjcf: MJCF cannot hold {'; '.join(lost)}", RobodynWarning, stacklevel=2)
    if path is not None:
        write_text(path, text)
    return text
