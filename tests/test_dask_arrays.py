"""Dask arrays through every batched function (``robodyn.algorithms._lazy``).

Oracle: the same function on the NumPy arrays; a block runs the same per-state kernels, so the
results must be equal bit for bit, whatever the chunks. Dask's threaded scheduler here; the
cluster tests are in ``test_distributed.py``.
"""

import pickle

import numpy as np
import pytest

import dask
import dask.array as da

import robodyn as rd
from robodyn import joints as J
from robodyn._warmup import _algorithm_steps
from robodyn.random import random_model, random_state

MODEL = random_model(5, seed=3, floating_base=True, branching=0.4,
                     joint_types=(J.REVOLUTE, J.PRISMATIC, J.SPHERICAL, J.HELICAL))
BATCH = (3, 11)
Q, V, A = random_state(MODEL, np.random.default_rng(7), BATCH)
CHUNKS = (2, 4)  # uneven along both batch axes


def _lazy(x, chunks=CHUNKS):
    return da.from_array(x, chunks=chunks + (-1,) * (x.ndim - len(chunks)))


def _leaves(x):
    return [leaf for item in x for leaf in _leaves(item)] if isinstance(x, tuple) else [x]


NAMES = [name for name, _ in _algorithm_steps(rd, MODEL, Q, V, A) if name != "inertia_bounds"]


@pytest.mark.parametrize("name", NAMES)
def test_every_batched_function_equals_numpy_bit_for_bit(name):
    eager = dict(_algorithm_steps(rd, MODEL, Q, V, A))[name]()
    lazy = dict(_algorithm_steps(rd, MODEL, _lazy(Q), _lazy(V), _lazy(A)))[name]()
    assert type(lazy) is type(eager) or not isinstance(eager, tuple)  # tuples, named tuples kept
    for got, want in zip(_leaves(lazy), _leaves(eager), strict=True):
        assert isinstance(got, da.Array), name
        assert got.shape == np.shape(want) and got.chunks[:2] == ((2, 1), (4, 4, 3))
        assert got.dtype == np.asarray(want).dtype
        assert np.array_equal(got.compute(), want), name


def test_one_chunk_broadcasting_and_wrenches():
    f = np.random.default_rng(1).standard_normal(BATCH + (MODEL.nbodies, 6))
    want = rd.rnea(MODEL, Q, V[0], A, f_ext=f, frame="world")
    got = rd.rnea(MODEL, da.from_array(Q), V[0], _lazy(A), f_ext=_lazy(f, (1, 5)), frame="world")
    assert np.array_equal(got.compute(), want)  # q one chunk, v a NumPy row broadcast, f_ext chunked otherwise
    got = rd.aba(MODEL, da.from_array(Q[0, 0]), V, A[0])  # the batch comes from v alone
    assert got.shape == BATCH + (MODEL.nv,)
    assert np.array_equal(got.compute(), rd.aba(MODEL, Q[0, 0], V, A[0]))


def test_a_single_state_as_dask_array():
    got = rd.crba(MODEL, da.from_array(Q[0, 0]))
    assert isinstance(got, da.Array) and np.array_equal(got.compute(), rd.crba(MODEL, Q[0, 0]))


def test_the_model_is_one_key_of_the_graph():
    tau = rd.rnea(MODEL, _lazy(Q), _lazy(V), _lazy(A))
    graph = dict(tau.__dask_graph__())
    models = [k for k in graph if isinstance(k, str) and k.startswith("Model-")]
    assert len(models) == 1
    assert sum(1 for k in graph if isinstance(k, tuple) and k[0].startswith("block-")) == 6  # one task per block
    # a copy of the model (e.g. unpickled on another machine) is the same key
    again = rd.gravity(pickle.loads(pickle.dumps(MODEL)), _lazy(Q))
    assert models[0] in dict(again.__dask_graph__())


def test_model_pickles_and_tokens_follow_the_content():
    copy = pickle.loads(pickle.dumps(MODEL))
    assert not copy.theta.flags.writeable and copy.link_names == MODEL.link_names
    assert np.array_equal(rd.rnea(copy, Q, V, A), rd.rnea(MODEL, Q, V, A))
    with pytest.raises(AttributeError, match="immutable"):
        copy.nq = 3
    heavier = MODEL.with_inertial_parameters(MODEL.theta.ravel() * 1.01)
    assert dask.base.tokenize(copy) == dask.base.tokenize(MODEL) != dask.base.tokenize(heavier)


def test_an_error_names_the_block():
    bad = Q.copy()
    bad[2, 9, 1] = np.nan
    tau = rd.rnea(MODEL, _lazy(bad), _lazy(V), _lazy(A))
    with pytest.raises(ValueError, match=r"q contains NaN.*block of states \[2:3, 8:11\] of the batch \(3, 11\)"):
        tau.compute()


def test_bad_calls_are_refused():
    with pytest.raises(TypeError, match="out="):
        rd.crba(MODEL, _lazy(Q), out=np.empty(BATCH + (MODEL.nv, MODEL.nv)))
    with pytest.raises(ValueError, match=r"v: expected shape \(\.\.\., %d\)" % MODEL.nv):
        rd.rnea(MODEL, _lazy(Q), _lazy(V[..., :-1]), A)
    with pytest.raises(ValueError, match="do not broadcast"):
        rd.rnea(MODEL, _lazy(Q), _lazy(V[:2]), A)
    with pytest.raises(TypeError, match="must be in memory"):
        rd.center_of_mass(MODEL, _lazy(Q), check_finite=da.from_array(np.ones(1, bool)))
    from robodyn.algorithms import _inputs

    with pytest.raises(TypeError, match="Dask array"):  # a function without the dispatch never computes
        _inputs.states(MODEL, q=_lazy(Q))


def test_without_dask_nothing_changes():
    """``import robodyn`` and the in-memory calls never import Dask; asking for a part that
    needs it names the extra to install."""
    import subprocess
    import sys

    code = ("import sys, numpy as np, robodyn as rd\n"
            "m = rd.models.load('panda'); rd.rnea(m, np.zeros((3, 7)), np.zeros(7), np.zeros(7))\n"
            "rd.simulate_many(m, np.zeros(7), np.zeros(7), 0.002, 1e-3, runs=2)\n"
            "assert not [k for k in sys.modules if k.split('.')[0] in ('dask', 'distributed')], 'dask imported'\n"
            "sys.modules['distributed'] = None\n"
            "try:\n    rd.distributed.Warmup\nexcept ImportError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert 'pip install "robodyn[dask]"' in out.stdout
