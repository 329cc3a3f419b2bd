"""Status codes of the compiled kernels, their checks, and the errors they stand for.

Every kernel returns a status per state: ``OK``, ``NONFINITE`` for NaN/Inf in an input,
``BAD_QUATERNION`` for a free joint's quaternion farther than ``joints.QUAT_TOL`` from unit
norm (near-unit ones are normalised), ``WRONG_SIZE`` for arrays of the wrong length (the
single-state fast paths), ``NONFINITE_RESULT`` when the inputs are finite but the result
overflowed, ``NOT_POSITIVE_DEFINITE`` for the mass matrix of a model with mimic couplings in
its independent coordinates, or ``i + 1`` for a failure at body ``i`` (a singular articulated inertia).
:func:`raise_for_status` turns a failure into a ``ValueError`` that says what and where. The
checks run inside the kernels, where they cost nanoseconds; ``check_finite=False`` skips the
NaN/Inf checks of inputs and results. No public function returns NaN or Inf from finite
inputs: it raises instead.
"""

from __future__ import annotations

import numpy as np

from .._jit import inline
from .. import joints as J

OK = 0
NONFINITE = -1
BAD_QUATERNION = -2
WRONG_SIZE = -3
NONFINITE_RESULT = -4
NOT_POSITIVE_DEFINITE = -5  # a coupled model's reduced mass matrix (see ``raise_for_coupled``)

# Constant arguments of the compiled per-state functions, as NumPy scalars: a Python literal
# (``-1``, ``True``) in a call from compiled code makes Numba compile a separate copy of the
# callee for that constant (minutes for the ABA); these are typed int64/bool like the runtime
# values of the other callers, which then share one compiled copy.
NO_WRENCH = np.int64(-1)  # ``fcode`` without external wrenches
CHECKED = np.bool_(True)  # ``check``: the NaN/Inf checks on


@inline
def finite(x):
    """True when every entry of the 1-D array ``x`` is finite: ``sum(x * 0) == 0``, since
    ``inf * 0`` and ``nan * 0`` are NaN (a branch-free loop the compiler vectorises; the
    kernels' fast-math flags keep NaN/Inf semantics, so the product is never folded to 0)."""
    return zero_sum(x) == 0.0


@inline
def zero_sum(x):
    """``sum(x * 0)`` of a 1-D array: 0 when every entry is finite, NaN otherwise."""
    s = 0.0
    for k in range(x.shape[0]):
        s += x[k] * 0.0
    return s


@inline
def finite2(x):
    """True when every entry of the 2-D array ``x`` is finite (see :func:`finite`)."""
    s = 0.0
    for r in range(x.shape[0]):
        s += zero_sum(x[r])
    return s == 0.0


@inline
def result_status(check, ok):
    """The status of a computed result: ``OK``, or ``NONFINITE_RESULT`` when the value checks
    are on and ``ok`` (the result's finiteness) is False."""
    return NONFINITE_RESULT if check and not ok else OK


def raise_nonfinite_result(what: str, arrays: dict):
    """Raise the ``ValueError`` of a result that is not finite although its inputs are."""
    big = max((float(np.abs(a).max()) for a in arrays.values() if np.size(a)), default=0.0)
    raise ValueError(
        f"{what}: the result is not finite although every input is (largest input magnitude {big:.3g}): "
        "the computation overflowed or divided by zero; check the scale of the inputs and the model's "
        "masses and inertias")


def require_finite_result(what: str, out: np.ndarray, check: bool, arrays: dict) -> np.ndarray:
    """``out``, after checking (when ``check``) that it is finite (for results computed in NumPy)."""
    if check and not np.isfinite(out).all():
        raise_nonfinite_result(what, arrays)
    return out


def first_failure(status) -> int:
    """The status of the first state that failed (``OK`` when none did) of an int or an int
    array (a single state's array of one entry read as quickly as an int)."""
    if type(status) is int:
        return status
    if status.shape == (1,):
        return int(status[0])
    bad = np.flatnonzero(status)
    return int(status[bad[0]]) if bad.size else OK


def raise_for_status(model, status, arrays: dict, what: str) -> int:
    """Raise the ``ValueError`` a kernel status stands for; return the failing body + 1 (or 0).

    ``status`` is an int or an int array (a status per state); ``arrays`` are the inputs as
    given to the kernel, used to say where the problem is.
    """
    code = first_failure(status)
    if code == OK:
        return 0
    if code == WRONG_SIZE:
        raise AssertionError("sizes are checked before the kernels run")
    if code == NONFINITE:
        for name, a in arrays.items():
            idx = np.argwhere(~np.isfinite(a))
            if idx.size:
                raise ValueError(f"{what}: {name} contains NaN or Inf (first at index {tuple(idx[0].tolist())}); "
                                 "pass check_finite=False to skip this check")
        raise AssertionError("kernel reported a non-finite input that is not there")
    if code == NONFINITE_RESULT:
        raise_nonfinite_result(what, arrays)
    if code == BAD_QUATERNION:
        raise_bad_unit(model, arrays["q"], what)
    if code == NOT_POSITIVE_DEFINITE:
        raise_not_positive_definite(model, what, "")
    return code


def raise_bad_unit(model, q: np.ndarray, what: str, column=None) -> None:
    """Raise the ``ValueError`` of the first quaternion or planar ``(cos, sin)`` of ``q``
    (..., model.nq) that is not unit; ``column`` maps an index of ``q`` to the caller's (a
    coupled model's independent coordinates)."""
    name = (lambda k: k) if column is None else column
    for i in np.flatnonzero(J.UNIT_SIZE[model.joint_type] > 0):
        k, size = model.idx_q[i] + J.UNIT_OFFSET[model.joint_type[i]], J.UNIT_SIZE[model.joint_type[i]]
        n = np.linalg.norm(q[..., k:k + size], axis=-1)
        if np.any(~(np.abs(n - 1.0) <= J.QUAT_TOL)):
            worst = float(np.ravel(n)[np.argmax(np.ravel(np.abs(n - 1.0)))])
            kind = J.NAMES[model.joint_type[i]]
            unit = "quaternion" if size == 4 else "(cos, sin)"
            raise ValueError(
                f"{what}: q: {unit} of {kind} joint {model.body_joint_names[i]!r} (q[{name(k)}:{name(k) + size}]) "
                f"has norm {worst:.6g}, not 1 (tolerance {J.QUAT_TOL}); normalise it"
            )
    raise AssertionError("kernel reported a bad quaternion that is not there")


def raise_for_coupled(model, status, arrays: dict, what: str) -> int:
    """:func:`raise_for_status` of a kernel of a model with mimic couplings
    (``robodyn.coupling``): its inputs are the independent coordinates, checked there; a bad
    quaternion is found in the full tree's configuration (free and spherical joints are never
    mimic joints, so its entries are the caller's, named by their index there); a non-finite
    input of the full tree from finite independent coordinates is an overflow of ``P q + o``
    or ``G v``, a non-finite result."""
    status = first_failure(status)
    if status == BAD_QUATERNION:  # q[k] of the full tree is q[column[k]] of the caller's
        column = dict(zip(model.independent_q.tolist(), range(model.nq)))
        raise_bad_unit(model.full, arrays["q"] @ model.P.T + model.offset, what, column.__getitem__)
    if status == NOT_POSITIVE_DEFINITE:
        raise_not_positive_definite(model, what)
    if status == NONFINITE and all(np.isfinite(a).all() for a in arrays.values()):
        raise_nonfinite_result(what, arrays)  # the full tree's state on the coupling overflowed
    return raise_for_status(model, status, arrays, what)


def raise_not_positive_definite(model, what: str, coordinates: str = " in its independent coordinates"):
    """Raise the ``ValueError`` of a mass matrix that is not positive definite: a coupled
    model's in its independent coordinates (a mimic joint that moves no mass, say), or a
    tree's (``coordinates=""``)."""
    raise ValueError(f"{what}: the mass matrix of {model.name!r}{coordinates} is not "
                     "positive definite, so the forward dynamics is undefined; give the bodies the joints "
                     "move mass and inertia (or armature)")


def raise_singular(model, bad: int, what: str, consequence: str = "so the forward dynamics is undefined") -> None:
    """Raise the ``ValueError`` of a singular articulated inertia when ``bad`` (the failing body
    + 1, as :func:`raise_for_status` returns it) is not 0."""
    if bad:
        i = bad - 1
        raise ValueError(
            f"{what}: the articulated inertia of body {i} ({model.link_names[i]!r}, joint "
            f"{model.body_joint_names[i]!r}) is singular, {consequence}; give the bodies beyond it mass and "
            "inertia about the joint axis (or armature)")
