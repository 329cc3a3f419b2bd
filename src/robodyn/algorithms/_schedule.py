"""Dynamic scheduling of the batch loops: worker threads claim chunks of states.

A batch of ``B`` states is cut into ``nchunk`` chunks of consecutive states (:func:`chunks`).
Each iteration of a batch kernel's ``prange`` loop is a worker that claims the next
unclaimed chunk from a shared counter, an atomic fetch-and-add (:func:`claim`), until none is
left; a thread's first worker so takes chunks until the batch is done, its later ones find
none left::

    counter = np.zeros(1, np.int64)
    for _ in prange(nchunk):
        ws = workspace(...)                   # one workspace per worker
        lo, hi = claim(counter, B, nchunk)
        while lo < hi:
            ...                               # states lo <= s < hi
            lo, hi = claim(counter, B, nchunk)

On a shared machine one core often runs slower than the other for a while (another
process, the hypervisor). With one fixed share of the batch per thread, the fast thread
would then wait for the slow one; with claimed chunks it takes more of the batch. Which
thread computes a state never changes the result: every state is computed alone.
"""

from __future__ import annotations

import numba
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from .._jit import inline

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
