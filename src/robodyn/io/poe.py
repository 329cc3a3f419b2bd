"""Product-of-exponentials models: ``from_poe(twists, home, inertias, ...) -> Model``.

The form of Murray, Li & Sastry, *A Mathematical Introduction to Robotic Manipulation* (1994),
chapters 3 and 4: joint ``i`` is the unit twist ``xi_i = (v_i, w_i)`` (linear part first, in
the base frame with every joint at 0), link ``i`` carries a frame whose pose at ``q = 0`` is
``g_sl_i(0)`` and whose inertia is given in that frame, and the tool sits at ``g_st(0)``:

    g_sl_i(q) = exp(xi_1 q_1) ... exp(xi_i q_i) g_sl_i(0)           (MLS eq. 3.3 / 4.?)

Joint types follow from the twist: ``w = 0`` is a prismatic joint along ``v``; ``|w| = 1`` a
revolute joint about the line through ``q = w x v`` along ``w`` (``v = -w x q``), or a helical
one of pitch ``h = w . v`` when ``h != 0``.

Each body's frame is its joint frame: on the joint's axis (the point of the axis nearest
the link frame's origin), with the link frame's orientation; the link's mass, centre of mass
and inertia are moved into it. The link frames are kept as frames ``<link>_frame`` and the
tool as ``tool``, so ``frame_pose(model, q, "tool")`` is MLS's ``g_st(q)``. A serial chain by
default; ``parents`` gives a tree (``-1``: the base).

The same construction with sympy entries gives a :class:`robodyn.symbolic.SymbolicModel`
(``robodyn.symbolic.from_poe``, revolute and prismatic joints).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from .._algebra import Algebra, is_symbolic
from ..model import Model, ModelError

AXIS_TOL = 1e-9  # |w| must be 0 or 1 within this


def poe_tree(twists, home, parents=None, where: str = "from_poe"):
    """Per joint ``(kind, parent, axis, pitch, R_tree, p_tree, offset)``: the joint kind
    (``"revolute"``, ``"prismatic"``, ``"helical"``), the parent body (-1: base), the axis in
    the joint frame, the pitch, the joint frame in the parent's joint frame, and the link
    frame's origin in the joint frame (module docstring). NumPy or sympy entries."""
    twists, home = list(twists), list(home)
    n = len(twists)
    if n == 0 or len(home) != n:
        raise ModelError(f"{where}: need one twist and one home pose per joint, got {n} twists and {len(home)} poses")
    parents = list(range(-1, n - 1)) if parents is None else [int(p) for p in parents]
    if len(parents) != n or any(not -1 <= p < i for i, p in enumerate(parents)):
        raise ModelError(f"{where}: parents must list one index per joint with -1 <= parent < joint, got {parents}")
    ops = Algebra(is_symbolic(*twists, *home))
    frames, out = [], []
    for i in range(n):
        xi = list(np.asarray(twists[i], dtype=object).ravel())
        if len(xi) != 6:
            raise ModelError(f"{where}: joint {i + 1}: a twist has 6 entries (v, w), got {len(xi)}")
        g = ops.matrix(home[i], f"{where}: joint {i + 1}: home pose", (4, 4))
        v, w = ops.vector(xi[:3], f"{where}: twist {i + 1}"), ops.vector(xi[3:], f"{where}: twist {i + 1}")
        R, p = g[:3, :3], ops.vector([g[k, 3] for k in range(3)], f"{where}: home pose {i + 1}")
        if ops.is_zero(w, AXIS_TOL):
            if not ops.symbolic and abs(np.linalg.norm(v) - 1.0) > AXIS_TOL:
                raise ModelError(f"{where}: joint {i + 1}: a prismatic twist (0, v) needs |v| = 1, "
                                 f"got {np.linalg.norm(v):.6g}")
            kind, axis, pitch, origin = "prismatic", v, 0, p
        else:
            if not ops.symbolic and abs(np.linalg.norm(w) - 1.0) > AXIS_TOL:
                raise ModelError(f"{where}: joint {i + 1}: a rotation twist (v, w) needs |w| = 1, "
                                 f"got {np.linalg.norm(w):.6g}")
            pitch = ops.dot(w, v)
            on_axis = ops.cross(w, v)                   # the point of the axis nearest the base origin
            origin = on_axis + w * ops.dot(w, p - on_axis)  # ... and nearest the link frame's origin
            kind = "revolute" if (pitch == 0 if ops.symbolic else abs(pitch) <= AXIS_TOL) else "helical"
            pitch = pitch if kind == "helical" else 0  # rounding (|w . v| ~ 1e-34) is no pitch
            axis = w
        frames.append((R, origin))
        parent = parents[i]
        if parent < 0:
            R_tree, p_tree = R, origin
        else:
            Rp, pp = frames[parent]
            R_tree, p_tree = Rp.T @ R, Rp.T @ (origin - pp)
        local_axis = R.T @ axis
        offset = R.T @ (p - origin)
        out.append((kind, parent, ops.simplify(local_axis), pitch, ops.simplify(R_tree), ops.simplify(p_tree),
                    ops.simplify(offset)))
    return out


def from_poe(twists, home, inertias: Sequence, *, parents=None, tool=None, link_names=None, joint_names=None,
             gravity=(0.0, 0.0, -9.81), name: str = "poe_robot", physical: str = "error") -> Model:
    """A :class:`Model` from joint twists, home link poses and link inertias (module docstring).

    Args:
        twists: (n, 6) unit twists ``(v, w)`` in the base frame at ``q = 0``.
        home: (n, 4, 4) poses ``g_sl_i(0)`` of the link frames at ``q = 0``.
        inertias: per link ``(mass, com, inertia)`` with ``com`` (3,) and ``inertia`` (3, 3)
            about the centre of mass, both in the link frame; or MLS's 6 x 6 generalized
            inertia matrix in the link frame, ``[[m 1, -m [c]x], [m [c]x, I_o]]`` (linear
            first; ``diag(m 1, I)`` when the link frame is at the centre of mass).
        parents: the parent joint of each joint (-1: the base); default a serial chain.
        tool: ``g_st(0)``, kept as the frame ``tool`` on the last body.
    """
    from ..builder import ModelBuilder

    n = len(list(twists))
    link_names = list(link_names or [f"link{i + 1}" for i in range(n)])
    joint_names = list(joint_names or [f"joint{i + 1}" for i in range(n)])
    inertias = list(inertias)
    if len(inertias) != n or len(link_names) != n or len(joint_names) != n:
        raise ModelError(f"from_poe: {n} twists need {n} inertias, link names and joint names")
    tree = poe_tree(twists, home, parents)
    b = ModelBuilder(name, gravity=gravity, physical=physical)
    b.add_link("base")
    for i, (kind, parent, axis, pitch, R_tree, p_tree, offset) in enumerate(tree):
        mass, com, Ic = _link_inertia(inertias[i], f"from_poe: link {i + 1} ({link_names[i]!r})")
        b.add_link(link_names[i], mass=mass, com=np.asarray(com) + offset, inertia=Ic)
        b.add_joint(joint_names[i], kind, "base" if parent < 0 else link_names[parent], link_names[i],
                    xyz=p_tree, rotation=R_tree, axis=axis, pitch=float(pitch))
        b.add_link(f"{link_names[i]}_frame")
        b.add_joint(f"{link_names[i]}_frame_fixed", "fixed", link_names[i], f"{link_names[i]}_frame", xyz=offset)
    if tool is not None:
        g = np.asarray(tool, dtype=float)
        if g.shape != (4, 4):
            raise ModelError(f"from_poe: tool: expected a 4 x 4 pose g_st(0), got shape {g.shape}")
        frame_R, frame_p = _joint_frame(home, tree, n - 1)
        b.add_link("tool")
        b.add_joint("tool_fixed", "fixed", link_names[-1], "tool", xyz=frame_R.T @ (g[:3, 3] - frame_p),
                    rotation=frame_R.T @ g[:3, :3])
    return b.build()


def _joint_frame(home, tree, i):
    """World rotation and origin of joint frame ``i`` at ``q = 0`` (numeric)."""
    R = np.asarray(home[i], dtype=float)[:3, :3]
    p = np.asarray(home[i], dtype=float)[:3, 3]
    return R, p - R @ np.asarray(tree[i][6], dtype=float)


def _link_inertia(spec, where: str):
    """``(mass, com, I_com)`` of a ``(mass, com, inertia)`` triple or a 6 x 6 generalized
    inertia matrix ``[[m 1, -m [c]x], [m [c]x, I_o]]`` (link frame)."""
    if isinstance(spec, (tuple, list)) and len(spec) == 3:
        mass, com, Ic = spec
        return float(mass), np.asarray(com, dtype=float).reshape(3), np.asarray(Ic, dtype=float).reshape(3, 3)
    G = np.asarray(spec, dtype=float)
    if G.shape != (6, 6):
        raise ModelError(f"{where}: expected (mass, com, inertia) or a 6 x 6 generalized inertia matrix, got {spec!r}")
    mass = float(np.trace(G[:3, :3]) / 3.0)
    if not np.allclose(G[:3, :3], mass * np.eye(3), atol=1e-12 * max(1.0, abs(mass))) or not np.allclose(G, G.T):
        raise ModelError(f"{where}: a generalized inertia matrix is symmetric with m 1 in its linear block")
    h = np.array([G[5, 1], G[3, 2], G[4, 0]])  # m [c]x sits below the diagonal: (m c_x, m c_y, m c_z)
    com = h / mass if mass > 0 else np.zeros(3)
    Io = G[3:, 3:]
    return mass, com, Io - mass * (com @ com * np.eye(3) - np.outer(com, com))
