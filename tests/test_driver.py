"""The one batch driver (``algorithms.driver``): results, scheduling, on-disk cache keys, and
that no algorithm writes its own parallel loop."""

import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from numba.core.caching import NullCache

from numba import int64
from numba.core.errors import TypingError

from robodyn._jit import MAT, inline, kernel, splice
from robodyn.algorithms import driver
from robodyn.algorithms._workspace import row
from robodyn.algorithms.driver import batch_kernel, chunks, threaded_batch_kernel

SRC = pathlib.Path(__file__).resolve().parent.parent / "src" / "robodyn"


@inline
def _affine_at(args, s, ws):
    """``Y[s] = 2 X[s] + ws[0]``, status -1 for a negative input."""
    X, Y = args
    if X[s, 0] < 0.0:
        return -1
    for k in range(X.shape[1]):
        Y[s, k] = 2.0 * X[s, k] + ws[0]
    return 0


@kernel
def _offset_workspace(n):
    ws = np.empty(n)
    ws[:] = 1.0
    return ws


@splice
def _shifted_views(args, ws):
    """A ``views`` that hands the state function a different workspace (spliced into its
    caller: a compiled function without reference counting returns no array, see ``_jit``)."""
    return ws[1:]


_affine_batch = batch_kernel(_affine_at, _offset_workspace)
_one_affine_batch = batch_kernel(_affine_at, _offset_workspace, one_state=((MAT, MAT), (int64,)))
_call_one = _one_affine_batch.call_one


@kernel
def _affine_one(address, x, y):
    """A single-state kernel: the batch's code at ``address`` for a batch of one."""
    return _call_one(address, (row(x), row(y)), _offset_workspace(2))
_shifted_batch = batch_kernel(_affine_at, _offset_workspace, _shifted_views)
_threaded_batch = threaded_batch_kernel(_affine_at, _offset_workspace)


@pytest.mark.parametrize("batch", [_affine_batch, _threaded_batch], ids=["prange", "threads"])
@pytest.mark.parametrize("B", [0, 1, 7, 1000])
def test_every_state_computed_once_with_its_status(B, batch):
    rng = np.random.default_rng(B)
    X = rng.standard_normal((B, 3))
    Y = np.full((B, 3), np.nan)
    status = np.full(B, 99, dtype=np.int64)
    batch((X, Y), (2,), status, chunks(B))
    bad = X[:, 0] < 0.0
    np.testing.assert_array_equal(status, np.where(bad, -1, 0))
    np.testing.assert_array_equal(Y[~bad], 2.0 * X[~bad] + 1.0)
    assert np.isnan(Y[bad]).all()  # a failed state writes nothing after its check


def test_more_chunks_than_states_and_views():
    X = np.abs(np.random.default_rng(0).standard_normal((5, 2)))
    Y = np.empty_like(X)
    status = np.empty(5, dtype=np.int64)
    _shifted_batch((X, Y), (3,), status, 64)
    assert (status == 0).all()
    np.testing.assert_array_equal(Y, 2.0 * X + 1.0)


def test_the_loop_calls_the_chunks_at_their_address_and_holds_no_copy():
    """``run_range`` is compiled once for the arguments' types and the parallel loop calls it
    at its address: the loop's code holds no copy of it (a direct call would link it into the
    loop's module, to be optimised and emitted again there)."""
    fresh = batch_kernel(_affine_at, _offset_workspace)
    fresh.loop._cache = NullCache()  # compiled here (the code of a cached loop is not shown)
    X = np.arange(6.0).reshape(3, 2)
    Y, status = np.empty_like(X), np.empty(3, np.int64)
    fresh((X, Y), (2,), status, chunks(3))
    np.testing.assert_array_equal(Y, 2.0 * X + 1.0)
    names = [c.fndesc.llvm_func_name for c in fresh.run_range.overloads.values()]
    code = "".join(fresh.loop.inspect_llvm().values())
    assert len(names) == 1 and names[0] not in code


def test_each_argument_type_gets_its_own_compiled_chunks():
    """Arguments of another type (a Fortran-ordered input) compile ``run_range`` again, and
    each call runs the code compiled for its own types."""
    fresh = batch_kernel(_affine_at, _offset_workspace)
    X = np.arange(12.0).reshape(6, 2)
    wide = np.zeros((6, 4))
    wide[:, ::2] = X
    for x in (X, np.asfortranarray(X), X, wide[:, ::2]):
        Y, status = np.empty((6, 2)), np.empty(6, np.int64)
        fresh((x, Y), (2,), status, chunks(6))
        np.testing.assert_array_equal(Y, 2.0 * X + 1.0)
    assert len(fresh.run_range.overloads) == 3  # C, F and A (every other column) layouts


def test_a_single_state_runs_the_batch_code_from_python_and_from_compiled_code():
    """``serial`` (Python) and ``call_one`` (a compiled single-state kernel) run the batch's
    compiled ``run_range`` for a batch of one: the single state's arrays with a leading axis
    of one have the batch's types, so its code is compiled once for both."""
    X = np.array([[1.0, 2.0], [3.0, 4.0], [-1.0, 0.0]])
    Y, status = np.zeros((3, 2)), np.full(3, 9, np.int64)
    _one_affine_batch((X, Y), (2,), status, chunks(3))
    one_y, one_status = np.zeros((1, 2)), np.full(1, 9, np.int64)
    _one_affine_batch.serial((X[:1], one_y), (2,), one_status)
    y = np.zeros(2)
    assert _affine_one(_one_affine_batch.one_address, X[1], y) == 0
    np.testing.assert_array_equal(one_y[0], Y[0])
    np.testing.assert_array_equal(y, Y[1])
    assert one_status[0] == 0 and _affine_one(_one_affine_batch.one_address, X[2], y) == -1  # its status returned
    assert len(_one_affine_batch.run_range.signatures) == 1


_undeclared_call_one = batch_kernel(_affine_at, _offset_workspace).call_one


@kernel
def _wrong_one(address, x, y):
    """A single-state kernel that passes ``x`` without its leading axis (not the declared types)."""
    return _call_one(address, (x, row(y)), _offset_workspace(2))


@kernel
def _undeclared_one(address, x, y):
    return _undeclared_call_one(address, (row(x), row(y)), _offset_workspace(2))


def test_call_one_refuses_arguments_other_than_the_declared_types():
    """The address is of code compiled for the declared ``one_state`` types: a single-state
    kernel that builds others is a compile-time error naming both (never a call of machine
    code with the wrong argument layout), as is one of a batch kernel that declares none."""
    with pytest.raises(TypingError, match="not the declared one_state"):
        _wrong_one(_one_affine_batch.one_address, np.zeros(2), np.zeros(2))
    with pytest.raises(TypingError, match="declares no one_state"):
        _undeclared_one(0, np.zeros(2), np.zeros(2))


class _CountedThread(driver.threading.Thread):
    started = 0

    def start(self):
        type(self).started += 1
        super().start()


@pytest.mark.parametrize("threads, nchunk, started", [(1, 8, 0), (2, 8, 1), (2, 1, 0)])
def test_threaded_workers_one_per_thread_and_chunk(monkeypatch, threads, nchunk, started):
    """The calling thread works too: ``min(threads, nchunk) - 1`` more; all states computed."""
    import numba

    monkeypatch.setattr(driver.threading, "Thread", _CountedThread)
    monkeypatch.setattr(_CountedThread, "started", 0)
    X = np.arange(40.0).reshape(20, 2)
    Y, status = np.empty_like(X), np.full(20, 99, np.int64)
    before = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        _threaded_batch((X, Y), (2,), status, nchunk)
    finally:
        numba.set_num_threads(before)
    assert _CountedThread.started == min(started, numba.config.NUMBA_NUM_THREADS - 1)
    assert (status == 0).all()
    np.testing.assert_array_equal(Y, 2.0 * X + 1.0)


@kernel
def _first_workspace_too_big(calls):
    """Numba's "array is too big" for the first worker that asks, a workspace for the others."""
    calls[0] += 1
    return np.empty(2 ** 62 if calls[0] == 1 else 1)


_first_fails_batch = threaded_batch_kernel(_affine_at, _first_workspace_too_big)


class _FinishedThread(driver.threading.Thread):
    """Runs to its end before the caller goes on: the spawned worker asks first."""

    def start(self):
        super().start()
        self.join()


def test_an_exception_in_a_threaded_worker_reaches_the_caller(monkeypatch):
    """Only the spawned thread fails (the caller's worker computes every state): its error is
    raised in the caller all the same."""
    monkeypatch.setattr(driver.threading, "Thread", _FinishedThread)
    monkeypatch.setattr(driver.numba, "get_num_threads", lambda: 2)
    X = np.ones((50, 2))
    Y, status, calls = np.empty_like(X), np.full(50, 99, np.int64), np.zeros(1, np.int64)
    with pytest.raises(ValueError, match="array is too big"):
        _first_fails_batch((X, Y), (calls,), status, 4)
    assert calls[0] == 2 and (status == 0).all()  # the caller's worker did the work


KEY = """
from robodyn.algorithms import rnea, crba
for b in (rnea._rnea_batch, crba._crba_batch):
    print("|".join(str(k._cache._index_key(("sig",), k.targetctx.codegen())) for k in (b.loop, b.run_range)))
"""


def test_cache_keys_are_stable_across_processes_and_differ_per_algorithm():
    """Numba's default key pickles the closed-over dispatchers, different in every process; the
    driver's key must be the same in a new process (so the on-disk cache hits) and differ
    between algorithms (so they never load each other's code)."""
    env = dict(os.environ)
    runs = [subprocess.run([sys.executable, "-c", KEY], capture_output=True, text=True, check=True, env=env).stdout
            for _ in range(2)]
    assert runs[0] == runs[1]
    rnea_keys, crba_keys = (line.split("|") for line in runs[0].strip().split("\n"))
    assert rnea_keys[0] != crba_keys[0] and rnea_keys[1] != crba_keys[1]  # the loops and the chunks


def test_no_parallel_loop_outside_the_driver():
    """Every batch kernel comes from ``driver.batch_kernel``: no other module runs ``prange``."""
    offenders = [str(p.relative_to(SRC)) for p in SRC.rglob("*.py")
                 if p.name != "driver.py" and "prange(" in p.read_text()]
    assert offenders == []
