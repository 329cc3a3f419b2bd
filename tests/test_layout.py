"""The kernel tables (``robodyn.layout``): every named column holds what its name says, and
no kernel reads a table by column number."""

import pathlib
import re

import numpy as np
import pytest

from robodyn import joints as J
from robodyn import layout as L
from robodyn.random import random_model

SRC = pathlib.Path(__file__).resolve().parent.parent / "src" / "robodyn"


ALL_TYPES = (J.REVOLUTE, J.PRISMATIC, J.HELICAL, J.SPHERICAL, J.PLANAR)


@pytest.mark.parametrize("seed", range(8))
def test_named_columns_hold_the_model(seed):
    """Every column against the per-body formulas of ``joints`` (``pack`` computes them for all
    bodies at once), for trees of every joint type (seeds 4-7) with friction and springs."""
    kinds = dict(joint_types=ALL_TYPES) if seed >= 4 else {}
    m = random_model(6, seed=seed, floating_base=bool(seed % 2), branching=0.5, **kinds)
    rng = np.random.default_rng(seed)
    one = np.repeat(J.NV[m.joint_type] == 1, J.NV[m.joint_type])
    m = m.replace(coulomb=rng.uniform(0, 1, m.nv), stribeck=rng.uniform(0, 1, m.nv),
                  stribeck_velocity=rng.uniform(0.1, 1, m.nv), stiffness=rng.uniform(0, 5, m.nv) * one,
                  spring_reference=rng.uniform(-1, 1, m.nv) * one)
    k = m.kernel
    assert k.ints.shape == (m.nbodies, L.INTS_COLUMNS) and k.body.shape == (m.nbodies, L.BODY_COLUMNS)
    np.testing.assert_array_equal(k.ints[:, L.PARENT], m.parent)
    np.testing.assert_array_equal(k.ints[:, L.JTYPE], m.joint_type)
    np.testing.assert_array_equal(k.ints[:, L.IQ], m.idx_q)
    np.testing.assert_array_equal(k.ints[:, L.IV], m.idx_v)
    np.testing.assert_array_equal(k.ints[:, L.NDOF], J.NV[m.joint_type])
    np.testing.assert_array_equal(k.body[:, L.XTREE_R:L.XTREE_R + 9], m.X_tree_R.reshape(-1, 9))
    np.testing.assert_array_equal(k.body[:, L.XTREE_P:L.XTREE_P + 3], m.X_tree_p)
    np.testing.assert_array_equal(k.body[:, L.JOINT_AXIS:L.JOINT_AXIS + 3], m.joint_axis)
    np.testing.assert_array_equal(k.body[:, L.INERTIA:L.INERTIA_END], m.theta)
    for i in range(m.nbodies):
        np.testing.assert_array_equal(k.body[i, L.JOINT_CONSTANTS:],
                                      J.joint_constants(int(m.joint_type[i]), m.joint_axis[i], m.X_tree_R[i],
                                                        m.joint_pitch[i]))
        S = J.motion_subspace(int(m.joint_type[i]), m.joint_axis[i], m.joint_pitch[i])
        rows = k.dofs[True, True][m.idx_v[i]:m.idx_v[i] + S.shape[0]]
        np.testing.assert_array_equal(rows[:, L.MOTION:L.MOTION + 6], S)
        unit = S.shape[0] == 1 and np.count_nonzero(S) == 1 and S.max() == 1.0
        assert k.ints[i, L.UNIT_AXIS] == (int(np.argmax(S)) if unit else -1)
    for friction in (False, True):
        for armature in (False, True):
            d = k.dofs[friction, armature]
            np.testing.assert_array_equal(d[:, L.ARMATURE], m.armature * armature)
            np.testing.assert_array_equal(d[:, L.DAMPING], m.damping * friction)
            np.testing.assert_array_equal(d[:, L.COULOMB], m.coulomb * friction)
            np.testing.assert_array_equal(d[:, L.STIFFNESS], m.stiffness * friction)
            np.testing.assert_array_equal(d[:, L.SPRING_REF], m.spring_reference)
            np.testing.assert_array_equal(d[:, L.STRIBECK], m.stribeck * friction)
            np.testing.assert_array_equal(d[:, L.STRIBECK_RATE], 1.0 / m.stribeck_velocity)
    np.testing.assert_array_equal(k.params[True][L.GRAVITY:L.GRAVITY + 3], m.gravity)
    np.testing.assert_array_equal(k.params[False][L.GRAVITY:L.GRAVITY + 3], 0.0)
    assert k.params[True][L.SMOOTHING] == m.coulomb_smoothing == k.params[False][L.SMOOTHING]
    assert k.multi_dof_bodies == tuple(np.flatnonzero(J.NV[m.joint_type] > 1))


def test_packed_array_is_the_tables_in_order():
    m = random_model(5, seed=3, floating_base=True)
    k = m.kernel
    for key, d in k.dofs.items():
        np.testing.assert_array_equal(k.packed[key], np.concatenate([k.body.ravel(), d.ravel(), k.params[True],
                                                                     k.zero_wrench.ravel()]))


def test_no_kernel_reads_a_table_by_column_number():
    """``ints[i, 3]`` or ``body[i, 15:25]`` in a kernel: the name from ``layout`` instead."""
    numbered = re.compile(r"\b(ints|body|dofs)\[[^\]\[]*,\s*(-?\d+\s*)?(:\s*\d+\s*)?\]|\bparams\[\d")
    offenders = []
    for path in SRC.rglob("*.py"):
        for n, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("#")[0]
            if numbered.search(code) and "``" not in code:
                offenders.append(f"{path.relative_to(SRC)}:{n}: {line.strip()}")
    assert offenders == []
