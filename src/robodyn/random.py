"""Seeded random models and states, for tests, benchmarks and experiments.

``random_model(nbodies, seed=0, floating_base=False, branching=0.3, joint_types=...)`` builds
a tree with revolute and prismatic joints (by default; spherical, helical (of random pitch)
and planar joints on request) on random
axes and placements, and random physically
consistent inertias (positive masses, principal moments satisfying the triangle
inequality). ``random_state(model, rng)`` draws ``(q, v, a)`` with unit quaternions.
"""

from __future__ import annotations

import numpy as np

from . import joints as J
from .coupling import is_coupled, reduce_q
from .model import Model, inertial_parameters_from


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random rotation matrix."""
    x, y, z, w = rng.standard_normal(4)
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def random_inertia(rng: np.random.Generator) -> np.ndarray:
    """10 inertial parameters of a random physically consistent body."""
    mass = rng.uniform(0.5, 3.0)
    com = rng.uniform(-0.3, 0.3, 3)
    d = rng.uniform(0.01, 0.2, 3)  # I = sum of m r^2 along two axes => triangle inequality
    principal = np.array([d[1] + d[2], d[0] + d[2], d[0] + d[1]]) * mass * 0.5
    R = random_rotation(rng)
    return inertial_parameters_from(mass, com, R @ np.diag(principal) @ R.T)


def random_model(nbodies: int, seed: int = 0, floating_base: bool = False, branching: float = 0.3,
                 joint_types=(J.REVOLUTE, J.PRISMATIC), gravity=(0.0, 0.0, -9.81)) -> Model:
    """A random tree of ``nbodies`` bodies (plus the free-flying base if ``floating_base``).

    Each body's parent is its predecessor, or with probability ``branching`` a random earlier
    body (or the world, for a fixed base), so chains and branches both occur.
    """
    rng = np.random.default_rng(seed)
    parent, jtype, axis, XR, Xp, theta, pitch = [], [], [], [], [], [], []
    if floating_base:
        parent.append(-1)
        jtype.append(J.FREE)
        axis.append(np.zeros(3))
        XR.append(np.eye(3))
        Xp.append(np.zeros(3))
        theta.append(random_inertia(rng))
        pitch.append(0.0)
    first = len(parent)
    for i in range(first, first + nbodies):
        lowest = 0 if floating_base else -1
        par = i - 1 if rng.random() > branching else int(rng.integers(lowest, i))
        parent.append(max(par, lowest) if i > 0 else -1)
        jtype.append(int(rng.choice(joint_types)))
        pitch.append(float(rng.uniform(-0.3, 0.3)) if jtype[-1] == J.HELICAL else 0.0)
        a = rng.standard_normal(3)
        axis.append(a / np.linalg.norm(a))
        XR.append(random_rotation(rng))
        Xp.append(rng.uniform(-0.5, 0.5, 3))
        theta.append(random_inertia(rng))
    nb = len(parent)
    names = [f"body{i}" for i in range(nb)]
    jnames = ["root_joint" if jtype[i] == J.FREE else f"joint{i}" for i in range(nb)]
    return Model(parent=parent, joint_type=jtype, joint_axis=np.array(axis), joint_pitch=pitch, X_tree_R=np.array(XR),
                 X_tree_p=np.array(Xp), theta=np.array(theta), link_names=names,
                 body_joint_names=jnames, gravity=gravity, name=f"random{nbodies}-seed{seed}")


def random_configuration(model: Model, rng: np.random.Generator, size=()) -> np.ndarray:
    """Random ``q`` (size + (nq,)): joints in [-pi, pi], positions in [-1, 1], unit quaternions
    (of a coupled model: the independent coordinates of its full tree's)."""
    size = (size,) if isinstance(size, int) else tuple(size)
    if is_coupled(model):
        return reduce_q(model, random_configuration(model.full, rng, size))
    q = rng.uniform(-np.pi, np.pi, size + (model.nq,))
    for i in np.flatnonzero(J.UNIT_SIZE[model.joint_type] > 0):
        k, jt = model.idx_q[i], model.joint_type[i]
        if jt in (J.FREE, J.PLANAR):
            n = 3 if jt == J.FREE else 2
            q[..., k:k + n] = rng.uniform(-1, 1, size + (n,))
        unit = rng.standard_normal(size + (J.UNIT_SIZE[jt],))
        k += J.UNIT_OFFSET[jt]
        q[..., k:k + J.UNIT_SIZE[jt]] = unit / np.linalg.norm(unit, axis=-1, keepdims=True)
    return q


def random_state(model: Model, rng: np.random.Generator, size=()):
    """Random ``(q, v, a)``; ``v`` and ``a`` standard normal."""
    size = (size,) if isinstance(size, int) else tuple(size)
    return (random_configuration(model, rng, size), rng.standard_normal(size + (model.nv,)),
            rng.standard_normal(size + (model.nv,)))
