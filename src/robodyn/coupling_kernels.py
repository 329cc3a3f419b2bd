"""The maps of a model with mimic couplings in compiled form (``coupling.CouplingTables``):
``q_full = P q + o``, ``v_full = G v`` and their transposes ``G^T f``, ``G^T M G``, for the
kernels that run the full tree's algorithms in the independent coordinates (``rnea``,
``crba``, ``aba`` of a :class:`~robodyn.coupling.CoupledModel`, the compiled control laws).
"""

from __future__ import annotations

from ._jit import inline


@inline
def expand_positions(cints, cfloats, q, qf):
    """``qf = P q + offset`` (nq_full,) of the independent ``q`` (nq,) (:class:`CouplingTables`)."""
    nvf, nqf = cints.shape[0] - 2 - qf.shape[0], qf.shape[0]
    for k in range(nqf):
        qf[k] = cfloats[nvf + k] * q[cints[2 + nvf + k]] + cfloats[nvf + nqf + k]


@inline
def expand_velocity(cints, cfloats, v, vf):
    """``vf = G v`` (nv_full,) of independent velocities or accelerations ``v`` (nv,)."""
    for k in range(vf.shape[0]):
        vf[k] = cfloats[k] * v[cints[2 + k]]


@inline
def reduce_vector(cints, cfloats, ff, f):
    """``f = G^T ff`` (nv,): generalized forces of the independent coordinates."""
    for i in range(f.shape[0]):
        f[i] = 0.0
    for k in range(ff.shape[0]):
        f[cints[2 + k]] += cfloats[k] * ff[k]


@inline
def reduce_square(cints, cfloats, Mf, M):
    """``M = G^T Mf G`` (nv, nv) of a (nv_full, nv_full) matrix."""
    for i in range(M.shape[0]):
        for j in range(M.shape[1]):
            M[i, j] = 0.0
    nvf = Mf.shape[0]
    for k in range(nvf):
        ck, sk = cints[2 + k], cfloats[k]
        for l in range(nvf):
            M[ck, cints[2 + l]] += sk * cfloats[l] * Mf[k, l]
