"""The algorithms are pure: calls from several threads at once give the serial results."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import robodyn as rd
from robodyn.random import random_model, random_state

CALLS = {
    "rnea": lambda m, q, v, a: rd.rnea(m, q, v, a),
    "aba": lambda m, q, v, a: rd.aba(m, q, v, a),
    "crba": lambda m, q, v, a: rd.crba(m, q),
    "coriolis_matrix": lambda m, q, v, a: rd.coriolis_matrix(m, q, v),
    "jacobian": lambda m, q, v, a: rd.jacobian(m, q, m.nbodies - 1, "local"),
    "kinetic_energy": lambda m, q, v, a: rd.kinetic_energy(m, q, v),
}


@pytest.mark.parametrize("floating", [False, True])
@pytest.mark.parametrize("batch", [(), (16,)], ids=["single", "batch"])
def test_threads_reproduce_serial_results(floating, batch):
    models = [rd.models.load("panda"), random_model(8, seed=1, floating_base=floating)]
    rng = np.random.default_rng(7)
    jobs = []
    for _ in range(40):
        m = models[int(rng.integers(len(models)))]
        name = list(CALLS)[int(rng.integers(len(CALLS)))]
        jobs.append((name, m, *random_state(m, rng, batch)))
    serial = [CALLS[name](m, q, v, a) for name, m, q, v, a in jobs]
    with ThreadPoolExecutor(max_workers=4) as pool:
        for _ in range(3):
            threaded = list(pool.map(lambda job: CALLS[job[0]](*job[1:]), jobs))
            for s, t in zip(serial, threaded):
                np.testing.assert_array_equal(t, s)
