"""The compilation settings of every kernel, in one place.

``kernel``: a compiled function, cached on disk. ``inline``: a small helper inlined into its
callers. ``parallel``: a batch driver whose ``prange`` loop runs on all threads.

``error_model="numpy"`` lets divisions by zero give inf/nan instead of raising (the kernels
check their inputs and pivots themselves); ``fastmath`` allows fused multiply-add and
reassociation but keeps NaN/Inf semantics, so the finiteness checks stay exact.
"""

from numba import njit

FASTMATH = {"contract", "reassoc", "arcp", "nsz"}
_BASE = dict(cache=True, error_model="numpy", fastmath=FASTMATH)

kernel = njit(**_BASE)
inline = njit(inline="always", **_BASE)
parallel = njit(parallel=True, **_BASE)
