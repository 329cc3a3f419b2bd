"""The compilation settings of every kernel, in one place.

``kernel``: a compiled function that may allocate (workspaces, single-state drivers), cached
on disk. ``parallel``: a batch driver whose ``prange`` loop runs on all threads.
``core``: an algorithm's per-state body, and ``inline``: a small helper inlined into its
callers; both run without Numba's reference counting (``_nrt=False``), which would
otherwise add atomic increments and decrements of every array passed to a helper (a
several-fold slowdown of the inner loops). They must not allocate: workspaces come from
their callers.

``fast(*argtypes)``: a single-state entry point compiled for exactly one argument signature
(C-contiguous float64 arrays ``VEC``/``MAT`` for the state and the output, the model's
``MODEL_INTS``/``MODEL_PACKED`` arrays (writeable: see ``Model._pack``), a ``bool``).
Compilation happens (or the cache is loaded) when the module defining it is imported, and the
dispatcher compiles nothing else: any other argument types (lists, integers, strided or read-only arrays, batches) raise
``TypeError``, on which the public function takes its general path.

All release the GIL (``nogil``), so Python threads run them concurrently (they share no
state: every call allocates its own workspace). ``error_model="numpy"`` lets divisions by zero give inf/nan instead of raising (the kernels
check their inputs and pivots themselves); ``fastmath`` allows fused multiply-add and
reassociation but keeps NaN/Inf semantics, so the finiteness checks stay exact.
"""

from numba import njit
from numba import types as _types

FASTMATH = {"contract", "reassoc", "arcp", "nsz"}
_BASE = dict(cache=True, error_model="numpy", fastmath=FASTMATH, nogil=True)

kernel = njit(**_BASE)
parallel = njit(parallel=True, **_BASE)
core = njit(_nrt=False, **_BASE)
inline = njit(inline="always", _nrt=False, **_BASE)
# ``exact``: contraction (fused multiply-add) only, for code whose order of operations
# carries its accuracy (``sincos``); LLVM may still inline it, the flags stay per operation.
exact = njit(_nrt=False, **{**_BASE, "fastmath": {"contract"}})


VEC = _types.Array(_types.float64, 1, "C")
MAT = _types.Array(_types.float64, 2, "C")
MODEL_INTS = _types.Array(_types.int64, 2, "C")
MODEL_PACKED = _types.Array(_types.float64, 1, "C")


def fast(*argtypes):
    """Decorator: a kernel returning an int64 status, compiled for ``argtypes`` only."""
    return njit([_types.int64(*argtypes)], **_BASE)
