"""The batch driver: one parallel loop over the states of a batch, for every algorithm.

An algorithm supplies three compiled pieces and gets its batch kernel from :func:`batch_kernel`:

``state_at(args, s, ws) -> status``
    computes state ``s`` of the batch: ``args`` is the algorithm's tuple of kernel tables,
    inputs and outputs (batched arrays indexed by ``s`` inside, per-state views taken there),
    ``ws`` the worker's workspace; returns the state's status (``status.OK`` or a failure).
``workspace(*sizes)``
    allocates one worker's scratch (called once per worker thread, never per state).
``views(args, ws) -> ws`` (optional)
    carves the workspace views once per chunk, where the compiler sees their constant
    shapes (see ``_workspace``; the workspace is then just the memory); without it the
    state function gets ``ws`` as allocated.

The kernel, ``batch(args, sizes, status, nchunk)``, runs all states ``s < status.shape[0]``
on all threads, ``nchunk = chunks(B)`` from Python. The batch is cut into ``nchunk`` chunks of
consecutive states; each iteration of the parallel loop is a worker that allocates a workspace,
then claims the next unclaimed chunk from a shared counter, an atomic fetch-and-add
(:func:`claim`), until none is left; a thread's first worker so takes chunks until the batch is
done, its later ones find none left. On a shared machine one core often runs slower than the
other for a while (another process, the hypervisor); with one fixed share of the batch per
thread, the fast thread would wait for the slow one, with claimed chunks it takes more of the
batch. Which worker computes a state never changes its result: every state is computed alone.
A chunk is computed by one compiled function called at its address (:class:`BatchKernel`),
so that the per-state code is compiled once, not once more inside each piece of the loop;
a single state runs that same function as a batch of one.

A batch whose one state is a whole simulation (``rollout``) uses :func:`threaded_batch_kernel`
instead: the same workers and chunks, on Python threads (see there for why).

The kernels are cached on disk like every other: Numba's own cache key of a closure pickles
the compiled functions it closes over, which differ in every process, so it would never hit;
:class:`ClosureCache` keys them by the source files they come from instead.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import threading

import numba
import numpy as np
from llvmlite import ir
from numba import prange, typeof, types
from numba._dispatcher import compute_fingerprint
from numba.core import cgutils
from numba.core.errors import TypingError
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


def batch_kernel(state_at, workspace, views=None, one_state=None):
    """The parallel batch kernel ``batch(args, sizes, status, nchunk)`` of an algorithm whose
    one state is ``state_at(args, s, ws)`` (see the module docstring): a :class:`BatchKernel`.
    ``one_state``: the Numba types of ``(args, sizes)`` that the algorithm's single-state
    kernel builds for a batch of one (see :meth:`BatchKernel.call_one`)."""

    if views is None:
        def run_range(args, status, lo, hi, ws):
            for s in range(lo, hi):
                status[s] = state_at(args, s, ws)
    else:
        def run_range(args, status, lo, hi, ws):
            ws = views(args, ws)
            for s in range(lo, hi):
                status[s] = state_at(args, s, ws)

    def loop(address, args, sizes, status, nchunk):
        B, counter = status.shape[0], np.zeros(1, np.int64)
        for _ in prange(nchunk):
            ws = workspace(*sizes)
            lo, hi = claim(counter, B, nchunk)
            while lo < hi:
                call_chunk(address, args, status, lo, hi, ws)
                lo, hi = claim(counter, B, nchunk)

    def here(address, args, sizes, status):
        call_chunk(address, args, status, 0, status.shape[0], workspace(*sizes))

    return BatchKernel(_cached(core(run_range)), workspace, _cached(parallel(loop)), _cached(kernel(here)), one_state)


STATUS = types.Array(types.int64, 1, "C")


class BatchKernel:
    """``batch(args, sizes, status, nchunk)``: the parallel ``loop`` over the chunks of a batch,
    each chunk computed by ``run_range(args, status, lo, hi, ws)``, called at its machine-code
    address (:func:`call_chunk`).

    Why by address: Numba copies the code of every compiled function a kernel calls into the
    kernel and optimises and emits it again there, and a parallel loop is several functions
    (the loop body, two gufunc wrappers, the kernel): an algorithm's whole per-state code was
    compiled four or five times for its batch kernel. Called by address, it is compiled once
    (``run_range`` for the arguments' types) and the loop alone is small (the ABA's batch
    kernel compiles in half the time, at the same speed: the call is once per chunk).
    ``run_range`` is compiled for each new combination of argument types (the key: Numba's
    fingerprint of the arguments, as its own dispatch uses), the workspace's type from
    ``workspace`` compiled for ``sizes``; both are cached on disk like every kernel.

    A single state is a batch of one and runs the same compiled ``run_range``, so that an
    algorithm's per-state code is compiled once for single calls and batches alike:
    :meth:`serial` from Python (the states in the calling thread, no parallel loop to start),
    :meth:`call_one` from a compiled single-state kernel (the fast paths), which gets the
    address, :attr:`one_address`, as an argument."""

    def __init__(self, run_range, workspace, loop, here, one_state=None):
        self.run_range, self.workspace, self.loop, self.here = run_range, workspace, loop, here
        self.one_state = one_state
        self.call_one = _one_state_call(self)
        self._addresses: dict = {}
        self._lock = threading.Lock()

    def __call__(self, args, sizes, status, nchunk):
        self.loop(self._address(args, sizes, status), args, sizes, status, nchunk)

    def run(self, args, sizes, status, batch: tuple):
        """A call's states: a single state (``batch == ()``, its arrays with a leading axis of
        one) in the calling thread (:meth:`serial`), a batch on all threads."""
        if batch == ():
            self.serial(args, sizes, status)
        else:
            self(args, sizes, status, chunks(status.shape[0]))

    def serial(self, args, sizes, status):
        """All states of the batch in the calling thread (for a single state: a batch of one,
        without starting the parallel loop's threads)."""
        self.here(self._address(args, sizes, status), args, sizes, status)

    def _address(self, args, sizes, status) -> int:
        try:
            key = compute_fingerprint((args, sizes, status))
        except NotImplementedError:  # a value Numba's fast path does not type: its full type
            key = typeof((args, sizes, status))
        address = self._addresses.get(key)
        if address is None:
            address = self._compile(key, typeof(args), tuple(typeof(sizes)), typeof(status))
        return address

    def _compile(self, key, args, sizes, status) -> int:
        """Compiles (or loads) ``run_range`` for these argument types; its address."""
        with self._lock:
            if key not in self._addresses:
                ws = self.workspace_type(sizes)
                signature = types.none(args, status, types.int64, types.int64, ws)
                self.run_range.compile(signature)
                compiled = self.run_range.overloads[signature.args]
                self._addresses[key] = compiled.library.get_pointer_to_function(compiled.fndesc.llvm_func_name)
            return self._addresses[key]

    def workspace_type(self, sizes):
        """The type of the workspace allocated for ``sizes`` (a tuple of Numba types)."""
        self.workspace.compile(sizes)
        return self.workspace.overloads[sizes].signature.return_type

    @functools.cached_property
    def one_address(self) -> int:
        """The address of ``run_range`` compiled for the single-state types ``one_state``
        (passed to the single-state kernel that calls :meth:`call_one`)."""
        args, sizes = self.one_state
        return self._compile(("one state",), types.Tuple(args), tuple(sizes), STATUS)


def _one_state_call(batch):
    """``call_one(address, args, ws) -> status``: the compiled single-state kernel's call of
    ``batch``'s ``run_range`` at ``address`` (:attr:`BatchKernel.one_address`) for the one
    state ``args`` (its arrays with a leading axis of one) with the workspace ``ws``; the
    status lives on the stack. The types of ``args`` and ``ws`` must be the declared
    ``one_state`` (a compile-time error otherwise: the address is of code compiled for
    those)."""

    @intrinsic
    def call_one(typingctx, address, args, ws):
        if batch.one_state is None:
            raise TypingError("call_one: the batch kernel declares no one_state types")
        declared, sizes = batch.one_state
        if args != types.Tuple(declared) or ws != batch.workspace_type(tuple(sizes)):
            raise TypingError(f"call_one: the single state's arguments are {args} with workspace {ws}, "
                              f"not the declared one_state {types.Tuple(declared)} for sizes {tuple(sizes)}")
        if not isinstance(address, types.Integer):
            return None

        def codegen(context, builder, signature, llargs):
            cell = cgutils.alloca_once(builder, ir.IntType(64))
            builder.store(ir.Constant(ir.IntType(64), 0), cell)
            status = context.make_array(STATUS)(context, builder)
            intp = context.get_value_type(types.intp)
            context.populate_array(status, data=cell, shape=cgutils.pack_array(builder, [ir.Constant(intp, 1)]),
                                   strides=cgutils.pack_array(builder, [ir.Constant(intp, 8)]),
                                   itemsize=ir.Constant(intp, 8), meminfo=None)
            zero, one = context.get_constant(types.int64, 0), context.get_constant(types.int64, 1)
            _call_at(context, builder, llargs[0], (args, STATUS, types.int64, types.int64, ws),
                     (llargs[1], status._getvalue(), zero, one, llargs[2]))
            return builder.load(cell)

        return types.int64(address, args, ws), codegen

    return call_one


def _call_at(context, builder, address, argtypes, llargs) -> None:
    """Emits the call of the compiled function ``(*argtypes) -> None`` at ``address`` (Numba's
    calling convention); an exception it raises propagates to the caller."""
    callee = builder.inttoptr(address, context.call_conv.get_function_type(types.none, argtypes).as_pointer())
    returned, _ = context.call_conv.call_function(builder, callee, types.none, argtypes, llargs)
    with cgutils.if_unlikely(builder, returned.is_error):
        context.call_conv.return_status_propagate(builder, returned)


@intrinsic
def call_chunk(typingctx, address, args, status, lo, hi, ws):
    """Calls the compiled ``run_range(args, status, lo, hi, ws)`` at machine-code ``address``
    (Numba's calling convention; see :class:`BatchKernel`, which compiled it for exactly these
    types); an exception it raises is returned to the caller as from a direct call."""
    if not (isinstance(address, types.Integer) and lo == types.int64 and hi == types.int64):
        return None
    argtypes = (args, status, lo, hi, ws)

    def codegen(context, builder, signature, llargs):
        _call_at(context, builder, llargs[0], argtypes, llargs[1:])
        return context.get_dummy_value()

    return types.none(address, *argtypes), codegen


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
