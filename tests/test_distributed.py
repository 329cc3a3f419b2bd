"""Scale-out on a ``dask.distributed.LocalCluster`` of two worker processes: Dask arrays,
Monte Carlo simulation, compilation once per worker, a worker killed mid-job.

Oracles: the in-memory NumPy call (bit for bit) and a loop of :func:`robodyn.simulate`.
Fleet identification on the cluster: ``test_identification_fleet.py``.
"""

import os
import time

import numpy as np
import pytest

import dask.array as da
import distributed

import robodyn as rd
from robodyn.distributed import perturbed_model, simulate_many

PANDA = rd.models.load("panda")
Q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7])
PERTURB = {"mass": 0.2, "friction": 0.5}


def _controller():
    return rd.control.PDGravity(PANDA, Q0, kp=100.0, kd=20.0)


@pytest.fixture(scope="module")
def client():
    rd.warmup(only=["rnea", "aba_derivatives", "simulate"])  # fill the on-disk cache the workers load
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster) as c:
        c.register_plugin(rd.distributed.Warmup(only=["rnea"]))
        yield c


def _signatures():
    from robodyn.algorithms import rnea

    return len(rnea._rnea_batch.run_range.signatures)  # the per-state code, compiled per argument types


def test_arrays_on_the_cluster_equal_numpy_and_compile_once(client):
    assert set(client.run(_signatures).values()) == {1}  # the plugin compiled (loaded) it on each worker
    rng = np.random.default_rng(0)
    q, v, a = rng.standard_normal((3, 4000, PANDA.nv))
    lazy = [da.from_array(x, chunks=(300, -1)) for x in (q, v, a)]
    tau = rd.rnea(PANDA, *lazy)
    assert np.array_equal(client.compute(tau).result(), rd.rnea(PANDA, q, v, a))
    # the same kernels in another process: equal up to the order of the SIMD sums, which the
    # compiler may pick by the arrays' memory alignment (fastmath reassociation)
    got = client.gather(client.compute(list(rd.aba_derivatives(PANDA, *lazy))))
    for g, w in zip(got, rd.aba_derivatives(PANDA, q, v, a), strict=True):
        np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-12 * np.abs(w).max())
    assert set(client.run(_signatures).values()) == {1}  # 14 tasks, no new specialisation anywhere


def test_simulate_many_equals_a_loop_of_simulate(client, tmp_path):
    c = _controller()
    rng = np.random.default_rng(1)
    q0 = Q0 + 0.1 * rng.standard_normal((5, 7))
    local = simulate_many(PANDA, q0, np.zeros(7), 0.2, 1e-3, c, perturb=PERTURB, seed=4)
    remote = simulate_many(PANDA, q0, np.zeros(7), 0.2, 1e-3, c, perturb=PERTURB, seed=4, client=client, chunk=2,
                           out=tmp_path, format="parquet")
    for i in range(5):
        plant, mass, joint = perturbed_model(PANDA, PERTURB, 4, i)
        traj = rd.simulate(plant, q0[i], np.zeros(7), 0.2, 1e-3, c)
        for r in (local, remote):
            assert np.array_equal(r.q_final[i], traj.q[-1]) and np.array_equal(r.v_final[i], traj.v[-1])
            assert np.array_equal(r.max_torque[i], np.abs(traj.tau).max(axis=0))
            assert r.max_error[i] == np.abs(traj.tracking_error).max()
            assert np.array_equal(r.mass_scale[i], mass) and np.array_equal(r.joint_scale[i], joint)
        back = rd.Trajectory.from_csv(remote.paths[i], plant)
        assert np.array_equal(back.q, traj.q)
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"run-{i:06d}.parquet" for i in range(5)]
    assert 0.8 <= remote.mass_scale.min() and remote.mass_scale.max() <= 1.2 and remote.mass_scale.std() > 0.05
    # the same runs again (a retry): the same files, none added
    simulate_many(PANDA, q0, np.zeros(7), 0.2, 1e-3, c, perturb=PERTURB, seed=4, client=client, out=tmp_path)
    assert len(list(tmp_path.iterdir())) == 5


def test_simulate_many_keeps_failed_runs_and_checks_its_input():
    q0 = np.tile(Q0, (3, 1))
    q0[1, 2] = np.nan
    with pytest.warns(RuntimeWarning, match="1 of 3 runs did not finish"):
        r = simulate_many(PANDA, q0, np.zeros(7), 0.01, 1e-3)
    assert r.failed.tolist() == [1] and "run 1" in r.errors[1] and np.isnan(r.q_final[1]).all()
    assert np.isfinite(r.q_final[[0, 2]]).all()
    with pytest.raises(ValueError, match="perturb: unknown key 'masses'"):
        simulate_many(PANDA, Q0, np.zeros(7), 0.01, 1e-3, runs=2, perturb={"masses": 0.1})
    with pytest.raises(ValueError, match="q0: expected shape"):
        simulate_many(PANDA, np.zeros((2, 6)), np.zeros(7), 0.01, 1e-3)
    with pytest.raises(ValueError, match="runs: give it only"):
        simulate_many(PANDA, q0, np.zeros(7), 0.01, 1e-3, runs=3)


def test_a_worker_killed_mid_job_does_not_lose_the_result(client):
    rng = np.random.default_rng(2)
    q = rng.standard_normal((20 * 500, PANDA.nv))

    def slow(x):  # each block takes a while, so that the job is still running when a worker dies
        time.sleep(0.25)
        return x

    lazy = da.from_array(q, chunks=(500, -1)).map_blocks(slow)
    before = set(client.scheduler_info()["workers"])
    future = client.compute(rd.gravity(PANDA, lazy))
    time.sleep(0.6)
    assert not future.done()
    async def die():
        os._exit(1)

    client.run(die, workers=[sorted(before)[0]], wait=False)
    result = future.result(timeout=120)
    assert np.array_equal(result, rd.gravity(PANDA, q))
    assert set(client.scheduler_info()["workers"]) != before  # a worker did die (the nanny started a new one)


def test_warmup_only_names_known_functions():
    with pytest.raises(ValueError, match=r"only: no warm-up step for \['rneaa'\]"):
        rd.warmup(only=["rneaa"])
    done = []
    rd.warmup(progress=lambda k, n, name: done.append(name), only="crba")
    assert done[-1] == "" and {n.split(" ")[0] for n in done[:-1]} == {"crba"} and len(done) == 7  # 6 and the end


def test_simulate_many_shows_progress_on_the_cluster(client, capsys):
    r = simulate_many(PANDA, Q0, np.zeros(7), 0.01, 1e-3, _controller(), runs=4, chunk=1, client=client,
                      progress=True)
    assert np.isfinite(r.q_final).all()
    shown = capsys.readouterr()
    assert "100%" in shown.out + shown.err
