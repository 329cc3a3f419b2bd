"""Mimic joints as true couplings: a model whose generalized coordinates are the independent joints.

A mimic joint ``j`` follows a source joint ``s`` (URDF ``<mimic joint="s" multiplier="r"
offset="o"/>``, Pinocchio's ``JointModelMimic``): ``q_j = r q_s + o``. It is not a degree of
freedom. A :class:`CoupledModel` holds the kinematic tree with every joint (``full``, a
:class:`~robodyn.model.Model` in which the mimic joints are ordinary joints) and the constant
map from the independent coordinates to the full ones::

    q_full = E(q) = P q + o,      v_full = G v,      a_full = G a,

``G`` (nv_full, nv) with a one in the row of each independent dof and ``r`` in the row of a
mimic dof (column of its source). The principle of virtual work gives the reduced dynamics
of the independent coordinates from the full tree's (Pinocchio's mimic support, MuJoCo's
joint equality made exact)::

    tau = G^T tau_full(E(q), G v, G a),   M = G^T M_full G,   C = G^T C_full G,
    J = J_full G,   dtau/dq = G^T (dtau_full/dq_full) G  (likewise for v),

so a mimic joint's own friction, armature and spring act through ``G^T``; the torque on the
source is the one the actuator sees. Forward dynamics solves ``M a = tau - h`` with the
reduced matrix. The public algorithms take a :class:`CoupledModel` wherever they take a
:class:`~robodyn.model.Model` and map their arguments and results with the functions of this
module; a function that does not (yet) says so (``kernel`` raises).

Chains of mimic joints (a mimic of a mimic) are resolved to the independent source. Mimic and
source joints must have one dof (revolute, prismatic, helical). The position limits of a
coupled model are those of the independent joints (a mimic joint's own limits are kept in
``full``, not enforced on its source).
"""

from __future__ import annotations

from typing import NamedTuple, Sequence

import numpy as np

from . import joints as J
from .errors import ModelError
from .model import Model, readonly


class CoupledModel:
    """A :class:`~robodyn.model.Model` with mimic joints that follow other joints.

    ``CoupledModel(full, mimic)``: ``mimic`` a sequence of ``(joint, source, multiplier,
    offset)``, the joints by name (``full.body_joint_names``). ``nq``, ``nv``,
    ``joint_names``, ``q_names``, ``dof_names`` and the per-dof limits describe the
    independent coordinates; bodies, links, frames and inertial parameters are ``full``'s.
    ``G`` (nv_full, nv), ``P`` (nq_full, nq) and ``offset`` (nq_full,) map them:
    ``q_full = P q + offset``, ``v_full = G v`` (see the module docstring).
    """

    __slots__ = ("full", "mimic", "G", "P", "offset", "nq", "nv", "independent_q", "independent_v",
                 "joint_names", "lower", "upper", "velocity_limit", "effort_limit", "tables")

    def __init__(self, full: Model, mimic: Sequence[tuple]):
        if not isinstance(full, Model):
            raise TypeError(f"full must be a robodyn Model, got {type(full).__name__}")
        setattr_ = object.__setattr__
        body_of = {name: i for i, name in enumerate(full.body_joint_names)}
        entries = []
        for entry in mimic:
            if len(entry) != 4:
                raise ModelError(f"mimic entries are (joint, source, multiplier, offset), got {entry!r}")
            entries.append((entry[0], entry[1], float(entry[2]), float(entry[3])))
        resolved = follow_chains(full.name, full.body_joint_names, entries)
        for joint, source, r, o in entries:
            for role, name in (("mimic joint", joint), ("source joint", source)):
                jt = full.joint_type[body_of[name]]
                if J.NV[jt] != 1:
                    raise ModelError(f"{full.name}: {role} {name!r} is a {J.NAMES[jt]} joint; mimic couplings "
                                     f"take joints of one dof (revolute, prismatic, helical)")
            if not (np.isfinite(r) and np.isfinite(o)):
                raise ModelError(f"{full.name}: mimic joint {joint!r}: multiplier {r} and offset {o} must be finite")
        dependent = np.zeros(full.nbodies, bool)
        for joint in resolved:
            dependent[body_of[joint]] = True
        ind_q = np.concatenate([np.arange(full.idx_q[i], full.idx_q[i] + J.NQ[full.joint_type[i]])
                                for i in np.flatnonzero(~dependent)] or [np.zeros(0, np.int64)]).astype(np.int64)
        ind_v = np.concatenate([np.arange(full.idx_v[i], full.idx_v[i] + J.NV[full.joint_type[i]])
                                for i in np.flatnonzero(~dependent)] or [np.zeros(0, np.int64)]).astype(np.int64)
        col_q = {int(k): c for c, k in enumerate(ind_q)}
        col_v = {int(k): c for c, k in enumerate(ind_v)}
        G = np.zeros((full.nv, len(ind_v)))
        P = np.zeros((full.nq, len(ind_q)))
        offset = np.zeros(full.nq)
        G[ind_v, np.arange(len(ind_v))] = 1.0
        P[ind_q, np.arange(len(ind_q))] = 1.0
        for joint, (source, r, o) in resolved.items():
            i, s = body_of[joint], body_of[source]
            G[full.idx_v[i], col_v[int(full.idx_v[s])]] = r
            P[full.idx_q[i], col_q[int(full.idx_q[s])]] = r
            offset[full.idx_q[i]] = o
        setattr_(self, "full", full)
        setattr_(self, "mimic", tuple((j, *resolved[j]) for j in resolved))
        for key, a in (("G", G), ("P", P), ("offset", offset), ("independent_q", ind_q), ("independent_v", ind_v)):
            setattr_(self, key, readonly(a, a.dtype))
        setattr_(self, "nq", int(len(ind_q)))
        setattr_(self, "nv", int(len(ind_v)))
        setattr_(self, "joint_names", tuple(n for n in full.joint_names if n not in resolved))
        for key in ("lower", "upper", "velocity_limit", "effort_limit"):
            setattr_(self, key, readonly(getattr(full, key)[ind_v]))
        setattr_(self, "tables", CouplingTables.of(G, P, offset))

    def __setattr__(self, key, value):
        raise AttributeError("CoupledModel is immutable")

    def __getstate__(self) -> dict:
        return {"full": self.full, "mimic": self.mimic}

    def __setstate__(self, state: dict) -> None:
        self.__init__(state["full"], state["mimic"])

    def __dask_tokenize__(self) -> str:
        return self.full.__dask_tokenize__() + repr(self.mimic)

    # -- what the bodies share with ``full`` -------------------------------------------
    def __getattr__(self, key):
        if key in _BODY_FIELDS:
            return getattr(self.full, key)
        if key in _TREE_FIELDS:  # indexed by the full tree's coordinates: code that reads them does not map
            raise CouplingError(self.full.name, "this function", (key,))
        raise AttributeError(f"'CoupledModel' object has no attribute {key!r}")

    @property
    def q_names(self) -> list[str]:
        return [self.full.q_names[k] for k in self.independent_q]

    @property
    def dof_names(self) -> list[str]:
        return [self.full.dof_names[k] for k in self.independent_v]

    def frame_index(self, name: str):
        return self.full.frame_index(name)

    def body_index(self, body) -> int:
        return self.full.body_index(body)

    def inertial_parameters(self) -> np.ndarray:
        return self.full.inertial_parameters()

    def with_inertial_parameters(self, theta) -> "CoupledModel":
        return CoupledModel(self.full.with_inertial_parameters(theta), self.mimic)

    def replace(self, **changes) -> "CoupledModel":
        """A new coupled model with fields of ``full`` changed (:meth:`Model.replace`)."""
        return CoupledModel(self.full.replace(**changes), self.mimic)

    def rigid(self) -> "CoupledModel":
        return CoupledModel(self.full.rigid(), self.mimic)

    def __repr__(self) -> str:
        rules = ", ".join(f"{j} = {r:g} {s}" + (f" {'+' if o >= 0 else '-'} {abs(o):g}" if o else "")
                          for j, s, r, o in self.mimic)
        return (f"CoupledModel: nq={self.nq}, nv={self.nv} independent (mimic: {rules})\n" + repr(self.full))


# Per-body and model-wide fields a coupled model shares with its full tree.
_BODY_FIELDS = frozenset((
    "name", "parent", "joint_type", "joint_axis", "joint_pitch", "X_tree_R", "X_tree_p", "theta",
    "link_names", "body_joint_names", "gravity", "frame_names", "frame_body", "frame_R", "frame_p",
    "physical", "coulomb_smoothing", "nbodies", "floating_base", "total_mass",
))


# Model fields in the full tree's coordinates (per dof, per coordinate, the kernel tables).
_TREE_FIELDS = frozenset(set(Model.__slots__) - _BODY_FIELDS - set(CoupledModel.__slots__))


class CouplingTables(NamedTuple):
    """The coupling in the compiled kernels' form. ``G`` and ``P`` have one entry per row (an
    independent coordinate's 1, or a mimic joint's multiplier in its source's column), so::

        v_full[k] = dof_scale[k] v[dof_map[k]],     q_full[k] = q_scale[k] q[q_map[k]] + q_offset[k]

    ``ints`` (2 + nv_full + nq_full,) int64 ``[nq, nv, dof_map, q_map]``; ``floats``
    (nv_full + 2 nq_full,) ``[dof_scale, q_scale, q_offset]`` (writeable, as the kernels'
    signatures take them; nothing writes them). The compiled maps are in
    :mod:`robodyn.coupling_kernels`."""

    ints: np.ndarray
    floats: np.ndarray

    @classmethod
    def of(cls, G: np.ndarray, P: np.ndarray, offset: np.ndarray) -> "CouplingTables":
        dof_map, q_map = np.abs(G).argmax(axis=1), np.abs(P).argmax(axis=1)
        dof_scale, q_scale = G[np.arange(G.shape[0]), dof_map], P[np.arange(P.shape[0]), q_map]
        ints = np.concatenate([[P.shape[1], G.shape[1]], dof_map, q_map]).astype(np.int64)
        return cls(ints, np.concatenate([dof_scale, q_scale, offset]).astype(np.float64))


class CouplingError(ModelError, AttributeError):
    """A function that does not take mimic couplings was given a :class:`CoupledModel` (an
    ``AttributeError`` too, so that ``hasattr`` and ``getattr`` with a default see no field).
    ``CouplingError(model name, what, why)``; the message is formatted when it is read: the
    algorithms' fast paths try ``model.kernel`` and take the coupled path on this error."""

    def __str__(self) -> str:
        name, what, why = self.args
        if not isinstance(why, str):  # a field of the full tree's coordinates (CoupledModel.__getattr__)
            why = f"CoupledModel: {why[0]!r} is the full tree's, not of the independent coordinates"
        return (f"{name}: {what} does not take a model with mimic couplings ({why}) yet; pass model.full (the "
                f"mimic joints as independent joints) or load the file with mimic='independent'")


def not_supported(model: CoupledModel, what: str, why: str) -> CouplingError:
    """The error of a function (``what``) that does not take a model with mimic couplings yet."""
    return CouplingError(model.full.name, what, why)


def follow_chains(name: str, joint_names, mimic) -> dict:
    """``{joint: (source, multiplier, offset)}`` of the ``mimic`` entries ``(joint, source, r,
    o)`` (``q_joint = r q_source + o``), in their order, each source followed to its
    independent joint (a mimic of a mimic: ``q_j = r (r2 q_s + o2) + o``). The multipliers and
    offsets may be numbers or sympy expressions. ``ModelError`` (naming the model ``name``) for
    joints not in ``joint_names``, a joint that mimics itself or two joints, and cycles."""
    known = set(joint_names)
    rule = {}
    for joint, source, r, o in mimic:
        for role, j in (("mimic joint", joint), ("source joint", source)):
            if j not in known:
                raise ModelError(f"{name}: {role} {j!r} is not a joint of the model")
        if joint == source:
            raise ModelError(f"{name}: joint {joint!r} mimics itself")
        if joint in rule:
            raise ModelError(f"{name}: joint {joint!r} mimics two joints ({rule[joint][0]!r}, {source!r})")
        rule[joint] = (source, r, o)
    resolved = {}
    for joint in rule:
        source, r, o = rule[joint]
        seen = [joint]
        while source in rule:
            if source in seen:
                raise ModelError(f"{name}: mimic joints form a cycle: {' -> '.join(seen + [source])}")
            seen.append(source)
            s2, r2, o2 = rule[source]
            source, r, o = s2, r * r2, r * o2 + o
        resolved[joint] = (source, r, o)
    return resolved


def is_coupled(model) -> bool:
    """True for a :class:`CoupledModel` (the algorithms map through it)."""
    return isinstance(model, CoupledModel)


def joint_tree(model) -> Model:
    """The tree of every joint: ``model.full`` of a coupled model, else the model itself."""
    return model.full if isinstance(model, CoupledModel) else model


def independent_q(model, q_tree) -> np.ndarray:
    """The model's coordinates of a configuration of :func:`joint_tree` (the independent
    entries of a coupled model's; otherwise ``q_tree`` itself)."""
    return reduce_q(model, q_tree) if isinstance(model, CoupledModel) else q_tree


def expand_q(model: CoupledModel, q) -> np.ndarray:
    """``q_full = P q + offset`` (..., nq_full) of independent coordinates ``q`` (..., nq)."""
    q = _last(q, model.nq, "q")
    return q @ model.P.T + model.offset


def expand_v(model: CoupledModel, v, name: str = "v") -> np.ndarray:
    """``v_full = G v`` (..., nv_full) of independent velocities (or accelerations) ``v`` (..., nv)."""
    return _last(v, model.nv, name) @ model.G.T


def reduce_q(model: CoupledModel, q_full) -> np.ndarray:
    """The independent coordinates (..., nq) of a full configuration (..., nq_full)."""
    return np.asarray(q_full)[..., model.independent_q]


def reduce_force(model: CoupledModel, tau_full) -> np.ndarray:
    """``G^T tau_full``: generalized forces (..., nv) of the independent coordinates."""
    return np.asarray(tau_full) @ model.G


def reduce_matrix(model: CoupledModel, M_full) -> np.ndarray:
    """``G^T M_full G`` (..., nv, nv) of a (..., nv_full, nv_full) matrix (mass, Coriolis, derivatives)."""
    return model.G.T @ np.asarray(M_full) @ model.G


def reduce_columns(model: CoupledModel, J_full) -> np.ndarray:
    """``J_full G`` (..., m, nv): a Jacobian's columns for the independent velocities."""
    return np.asarray(J_full) @ model.G


def reduce_rows(model: CoupledModel, Y_full) -> np.ndarray:
    """``G^T Y_full`` (..., nv, m): rows of a map into generalized forces (a regressor)."""
    return model.G.T @ np.asarray(Y_full)


def into(out, result):
    """``result`` written into ``out`` when the caller passed one (shapes checked), else ``result``."""
    if out is None:
        return result
    if not isinstance(out, np.ndarray) or out.shape != np.shape(result):
        raise ValueError(f"out: expected an ndarray of shape {np.shape(result)}, got "
                         f"{getattr(out, 'shape', type(out).__name__)}")
    out[...] = result
    return out


def _last(x, n: int, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim == 0 or a.shape[-1] != n:
        raise ValueError(f"{name}: expected shape (..., {n}), got {a.shape}")
    return a
