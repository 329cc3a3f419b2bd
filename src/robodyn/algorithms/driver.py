"""The batch driver: one parallel loop over the states of a batch, for every algorithm.

An algorithm supplies three compiled pieces and gets its batch kernel from :func:`batch_kernel`:

``state_at(args, s, ws) -> status``
    computes state ``s`` of the batch: ``args`` is the algorithm's tuple of kernel tables,
    inputs and outputs (batched arrays indexed by ``s`` inside, per-state views taken there),
    ``ws`` the worker's workspace; returns the state's status (``status.OK`` or a failure).
``workspace(*sizes)``
    allocates one worker's scratch (called once per worker thread, never per state).
``views(args, ws) -> ws`` (optional)
    rebuilds the workspace views once per chunk, where the compiler sees their constant
    shapes (see ``_workspace``); without it the state function gets ``ws`` as allocated.

The kernel, ``batch(args, sizes, status, nchunk)``, runs all states ``s < status.shape[0]``
on all threads, ``nchunk = chunks(B)`` from Python. The batch is cut into ``nchunk`` chunks of
consecutive states; each iteration of the parallel loop is a worker that allocates a workspace,
then claims the next unclaimed chunk from a shared counter, an atomic fetch-and-add
(:func:`claim`), until none is left; a thread's first worker so takes chunks until the batch is
done, its later ones find none left. On a shared machine one core often runs slower than the
other for a while (another process, the hypervisor); with one fixed share of the batch per
thread, the fast thread would wait for the slow one, with claimed chunks it takes more of the
batch. Which worker computes a state never changes its result: every state is computed alone.

A batch whose one state is a whole simulation (``rollout``) uses :func:`threaded_batch_kernel`
instead: the same workers and chunks, on Python threads (see there for why).

The kernels are cached on disk like every other: Numba's own cache key of a closure pickles
the compiled functions it closes over, which differ in every process, so it would never hit;
:class:`ClosureCache` keys them by the source files they come from instead.
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading

import numba
import numpy as np
from llvmlite import ir
from numba import prange, types
from numba.extending import intrinsic

from .._jit import SharedCache, core, inline, kernel, parallel

CHUNKS_PER_THREAD = 32
MIN_CHUNK = 64  # states: each worker allocates a workspace, so chunks of a small batch stay large


def chunks(B: int) -> int:
    """Number of chunks of a batch of ``B`` states: ``CHUNKS_PER_THREAD`` per thread for a
    large batch, fewer so that a chunk has at least ``MIN_CHUNK`` states, and at least one per
    thread (at most one per state)."""
    threads = numba.get_num_threads()
    return max(1, min(B, threads), min(-(-B // MIN_CHUNK), CHUNKS_PER_THREAD * threads))


@intrinsic
def _fetch_add(typingctx, counter):
    """``counter[0] += 1`` atomically; returns the value before the addition."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64):
        return None
    sig = types.int64(counter)

    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, args[0])
        return builder.atomic_rmw("add", array.data, ir.Constant(ir.IntType(64), 1), "monotonic")

    return sig, codegen


@inline
def claim(counter, B, nchunk):
    """The states ``lo <= s < hi`` of the next unclaimed chunk; ``lo >= hi`` when none is left."""
    c = _fetch_add(counter)
    return c * B // nchunk, min(c + 1, nchunk) * B // nchunk


class ClosureCache(SharedCache):
    """Numba's on-disk cache for a function that closes over other compiled functions.

    Numba keys a cached function by its source file and the pickled values of its closure
    cells; a compiled function pickles to a random identifier, different in every process.
    Here a cell that holds a compiled function is keyed by its module, its qualified name and
    the modification time and size of its source file (as Numba keys the function's own file),
    so that the cache hits in the next process and misses when that source changes.
    """

    def _index_key(self, sig, codegen):
        cells = []
        for cell in self._py_func.__closure__ or ():
            f = getattr(cell.cell_contents, "py_func", None)
            if f is None:
                cells.append(repr(cell.cell_contents))
                continue
            path = sys.modules[f.__module__].__file__
            st = os.stat(path)
            cells.append(f"{f.__module__}.{f.__qualname__}:{st.st_mtime_ns}:{st.st_size}")
        closure = hashlib.sha256("\n".join(cells).encode()).hexdigest()
        source = self._py_func.__code__.co_code
        return (sig, codegen.magic_tuple(), (hashlib.sha256(source).hexdigest(), closure))


def _cached(dispatcher):
    """``dispatcher`` with its compiled code cached on disk by :class:`ClosureCache`."""
    dispatcher._cache = ClosureCache(dispatcher.py_func)
    return dispatcher


def batch_kernel(state_at, workspace, views=None):
    """The parallel batch kernel ``batch(args, sizes, status, nchunk)`` of an algorithm whose
    one state is ``state_at(args, s, ws)`` (see the module docstring)."""

    if views is None:
        def run_range(args, status, lo, hi, ws):
            for s in range(lo, hi):
                status[s] = state_at(args, s, ws)
    else:
        def run_range(args, status, lo, hi, ws):
            ws = views(args, ws)
            for s in range(lo, hi):
                status[s] = state_at(args, s, ws)

    run_range = _cached(core(run_range))

    def batch(args, sizes, status, nchunk):
        B, counter = status.shape[0], np.zeros(1, np.int64)
        for _ in prange(nchunk):
            ws = workspace(*sizes)
            lo, hi = claim(counter, B, nchunk)
            while lo < hi:
                run_range(args, status, lo, hi, ws)
                lo, hi = claim(counter, B, nchunk)

    return _cached(parallel(batch))


def threaded_batch_kernel(state_at, workspace):
    """:func:`batch_kernel` for a heavy ``state_at`` (a whole simulation per state), its
    workers on Python threads instead of a ``prange`` loop: ``batch(args, sizes, status,
    nchunk)`` starts ``min(numba.get_num_threads(), nchunk) - 1`` threads and works in the
    calling one too, each running one compiled, GIL-free worker that allocates a workspace and
    claims chunks from the shared counter until none is left, as the workers of
    :func:`batch_kernel` do; the results are the same. An exception in a worker (a workspace
    that cannot be allocated) is raised in the caller once every worker has stopped.

    Why: Numba optimises and emits machine code for the whole of an inlined ``state_at`` once
    per compiled function that contains it, and a parallel loop wraps it in four (the loop
    body, two gufunc wrappers, the kernel) where a worker is one: the first rollout compiles in
    about half the time. For a light state (one ``rnea``) starting threads costs more than the
    state, and the ``prange`` loop stays (``benchmarks/RESULTS.md``, cold start)."""

    def work(args, sizes, status, counter, nchunk):
        B = status.shape[0]
        ws = workspace(*sizes)
        lo, hi = claim(counter, B, nchunk)
        while lo < hi:
            for s in range(lo, hi):
                status[s] = state_at(args, s, ws)
            lo, hi = claim(counter, B, nchunk)

    work = _cached(kernel(work))

    def batch(args, sizes, status, nchunk):
        counter, errors = np.zeros(1, np.int64), []

        def worker():
            try:
                work(args, sizes, status, counter, nchunk)
            except BaseException as e:  # raised in the caller below
                errors.append(e)

        threads = [threading.Thread(target=worker, daemon=True)
                   for _ in range(min(numba.get_num_threads(), nchunk) - 1)]
        for t in threads:
            t.start()
        worker()
        for t in threads:
            t.join()
        if errors:
            raise errors[0]

    return batch
