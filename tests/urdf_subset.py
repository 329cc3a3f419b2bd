"""A few example-robot-data URDFs for the tests that compare with Pinocchio beyond the core
(test_hybrid.py, test_minv.py, test_task_space.py): fixed and floating base, continuous
joints, branching humanoids and quadrupeds with arms. The full list runs in test_pinocchio.py."""

from __future__ import annotations

import pytest

from conftest import erd_id, example_robot_data_dir
from test_pinocchio import _pair

SUBSET = [
    "panda_description/urdf/panda.urdf",
    "ur_description/urdf/ur5_robot.urdf",
    "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
    "baxter_description/urdf/baxter.urdf",
    "solo_description/robots/solo12.urdf",
    "anymal_b_simple_description/robots/anymal-kinova.urdf",
    "talos_data/robots/talos_reduced.urdf",
]


def pairs():
    """``(id, floating_base)`` parameters: every subset URDF, fixed and floating."""
    return [pytest.param(path, fb, id=f"{path}-{'floating' if fb else 'fixed'}")
            for path in SUBSET for fb in (False, True)]


def load_pair(path: str, floating_base: bool):
    """The robodyn/Pinocchio ``Pair`` (see test_pinocchio.py) of a subset URDF."""
    full = example_robot_data_dir() / path
    assert full.is_file(), f"missing {erd_id(full)}"
    pair = _pair(full, floating_base)
    assert not isinstance(pair, Exception), pair
    return pair
