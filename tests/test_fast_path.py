"""The single-state fast paths of rnea, aba, crba, coriolis_matrix, inverse_mass_matrix and
hybrid_dynamics (compiled for contiguous float64 vectors only) and the general path they fall
back to: every other kind of input gives the same result (float32 input is converted to
float64, and so is the result), results written into ``out`` equal the returned ones, and the
workspaces carved from one buffer never overrun it."""

from __future__ import annotations

import numba
import numpy as np
import pytest

import robodyn as rd
from helpers import assert_rel
from robodyn.algorithms._workspace import take
from robodyn.random import random_model, random_state

MODELS = [rd.models.load("panda"), random_model(6, seed=3, floating_base=True, branching=0.5)]
CALLS = {
    "rnea": lambda m, q, v, a, **kw: rd.rnea(m, q, v, a, **kw),
    "aba": lambda m, q, v, a, **kw: rd.aba(m, q, v, a, **kw),
    "crba": lambda m, q, v, a, **kw: rd.crba(m, q, **{k: x for k, x in kw.items() if k == "armature"}),
    "coriolis_matrix": lambda m, q, v, a, **kw: rd.coriolis_matrix(m, q, v),
}


def variants(x):
    """The same vector as a list, a read-only array, a strided view and a (1, n) batch (whose
    result has a leading dimension of one); float32 input: see test_float32_input_is_computed_in_float64."""
    ro = x.copy()
    ro.flags.writeable = False
    strided = np.zeros(2 * x.size)[::2]
    strided[:] = x
    return {"list": x.tolist(), "read-only": ro, "strided": strided, "batch of one": x[None]}


def _hybrid(m, q, v, a, **kw):
    """hybrid_dynamics, the accelerations of the second half of the dofs known: (a, tau) side by side."""
    known = np.arange(m.nv) >= m.nv // 2
    return np.concatenate(rd.hybrid_dynamics(m, q, v, a, a, known, **kw), axis=-1)


# the fast paths taken when ``_inputs.vectors`` accepts every argument
VECTOR_CALLS = {
    "inverse_mass_matrix": lambda m, q, v, a, **kw: rd.inverse_mass_matrix(m, q, **kw),
    "hybrid_dynamics": _hybrid,
}


@pytest.mark.parametrize("model", MODELS, ids=["panda", "floating tree"])
@pytest.mark.parametrize("name", list(CALLS) + list(VECTOR_CALLS))
def test_every_input_kind_gives_the_fast_result(model, name):
    call = {**CALLS, **VECTOR_CALLS}[name]
    q, v, a = random_state(model, np.random.default_rng(7))
    expected = call(model, q, v, a)
    for kind, (qx, vx, ax) in zip(variants(q), zip(*(variants(x).values() for x in (q, v, a)))):
        got = call(model, qx, vx, ax)
        if kind == "batch of one":
            assert got.shape == (1,) + expected.shape
            got = got[0]
        assert_rel(got, expected, 1e-14, f"{name} with {kind} input")


# float32 input carries a relative rounding of 2**-24 (6e-8) per entry; these well-conditioned
# maps amplify it a few times (at most 4x measured on both models): the tolerance allows 50x.
FLOAT32_TOL = 50 * 2.0 ** -24


@pytest.mark.parametrize("model", MODELS, ids=["panda", "floating tree"])
@pytest.mark.parametrize("name", list(CALLS))
def test_float32_input_is_computed_in_float64(model, name):
    """float32 arrays, one state and a batch of three, with and without ``out``: the result is
    float64, equals the float64 call on the same (float32-rounded) values, and differs from the
    call on the unrounded state only by the input rounding."""
    call = CALLS[name]
    for size in ((), (3,)):
        state = random_state(model, np.random.default_rng(9), size)
        f32 = [x.astype(np.float32) for x in state]
        widened = [x.astype(np.float64) for x in f32]
        got = call(model, *f32)
        assert got.dtype == np.float64, f"{name}: {got.dtype} from float32 input"
        assert_rel(got, call(model, *widened), 1e-14, f"{name}: float32 vs the same values in float64")
        assert_rel(got, call(model, *state), FLOAT32_TOL, f"{name}: float32 vs unrounded float64")
        if name in OUT_CALLS:
            out = np.full(got.shape, np.nan)
            assert OUT_CALLS[name](model, *f32, out=out) is out
            assert_rel(out, got, 1e-15, f"{name} into out from float32 input")


@pytest.mark.parametrize("name", ["rnea", "aba", "crba"])
def test_integer_options_equal_booleans(name):
    """friction=0/1, armature=0/1 mean False/True (they miss the fast path's bool lookup)."""
    model = rd.models.load("puma560")
    q, v, a = random_state(model, np.random.default_rng(1))
    call = CALLS[name]
    for f in (0, 1):
        for arm in (0, 1):
            assert_rel(call(model, q, v, a, friction=f, armature=arm),
                       call(model, q, v, a, friction=bool(f), armature=bool(arm)), 0.0)
    assert not np.allclose(call(model, q, v, a, armature=0), call(model, q, v, a, armature=1))


def test_bad_sizes_and_values_still_raise_on_the_fast_path():
    model = MODELS[0]
    q, v, a = random_state(model, np.random.default_rng(2))
    with pytest.raises(ValueError, match=r"q: expected shape"):
        rd.rnea(model, np.zeros(model.nq + 1), v, a)
    bad = a.copy()
    bad[3] = np.nan
    with pytest.raises(ValueError, match=r"a contains NaN"):
        rd.rnea(model, q, v, bad)
    with pytest.raises(ValueError, match=r"tau contains NaN"):
        rd.aba(model, q, v, bad)


OUT_CALLS = {
    "rnea": lambda m, q, v, a, **kw: rd.rnea(m, q, v, a, **kw),
    "aba": lambda m, q, v, a, **kw: rd.aba(m, q, v, a, **kw),
    "crba": lambda m, q, v, a, **kw: rd.crba(m, q, **kw),
    "coriolis_matrix": lambda m, q, v, a, **kw: rd.coriolis_matrix(m, q, v, **kw),
}


@pytest.mark.parametrize("model", MODELS, ids=["panda", "floating tree"])
@pytest.mark.parametrize("name", list(OUT_CALLS))
@pytest.mark.parametrize("size", [(), (3,), (2, 2)], ids=["single", "batch", "2-D batch"])
def test_out_receives_the_result_and_is_returned(model, name, size):
    call = OUT_CALLS[name]
    q, v, a = random_state(model, np.random.default_rng(4), size)
    expected = call(model, q, v, a)
    out = np.full(expected.shape, np.nan)
    assert call(model, q, v, a, out=out) is out
    assert_rel(out, expected, 0.0, f"{name} into out")
    listed = call(model, q.tolist(), v.tolist(), a.tolist(), out=out)  # the general path
    assert listed is out
    # separately compiled code: whether the compiler inlines the shared per-state function
    # into it depends on which process compiled what first (the on-disk cache), which may
    # change the last bit
    assert_rel(out, expected, 1e-15, f"{name} into out, list inputs")


@pytest.mark.parametrize("name", list(OUT_CALLS))
def test_unusable_out_is_refused_and_left_alone(name):
    model = MODELS[0]
    call = OUT_CALLS[name]
    q, v, a = random_state(model, np.random.default_rng(5), (2,))
    shape = call(model, q, v, a).shape
    cases = {
        r"out: expected shape": np.zeros(shape[:-1] + (shape[-1] + 1,)),
        r"out: expected shape \(2, ": np.zeros(shape[1:]),  # a single result's shape for a batch
        r"out: expected a float64 ndarray, got ndarray of float32": np.zeros(shape, dtype=np.float32),
        r"out: expected a float64 ndarray, got list": np.zeros(shape).tolist(),
        r"out: must be C-contiguous": np.zeros(shape[::-1]).T,
    }
    read_only = np.zeros(shape)
    read_only.flags.writeable = False
    cases[r"out: must be C-contiguous and writeable"] = read_only
    for message, out in cases.items():
        for state in ((q, v, a), (q[0], v[0], a[0])):  # batch and single state
            if state[0].ndim == 1 and np.shape(out) == shape[1:]:
                continue  # a single result's shape is right for a single state
            with pytest.raises(ValueError, match=message if state[0].ndim == 2 else r"out: "):
                call(model, *state, out=out)
    if name in ("rnea", "aba"):  # the inputs and the output have the same shape: no aliasing
        with pytest.raises(ValueError, match=r"out: shares memory with the input v"):
            call(model, q, v, a, out=v)
        with pytest.raises(ValueError, match=r"out: shares memory with the input"):
            call(model, q[0], v[0], a[0], out=a[0])
        np.testing.assert_equal(a, random_state(model, np.random.default_rng(5), (2,))[2])


@pytest.mark.parametrize("name", list(OUT_CALLS))
def test_single_state_out_is_checked_by_the_fast_kernels(name):
    """For one state the compiled fast path checks ``out`` itself: the same number of entries
    in another shape, or an input that overlaps it by one entry, sends the call to the general
    path, which raises; ``out`` is not written."""
    model = MODELS[0]
    call = OUT_CALLS[name]
    state = random_state(model, np.random.default_rng(6))
    shape = call(model, *state).shape
    wrong = np.full((3, model.nv ** 2 // 3) if len(shape) == 2 else (model.nv - 1,), np.nan)
    with pytest.raises(ValueError, match=r"out: expected shape"):
        call(model, *state, out=wrong)
    assert np.isnan(wrong).all()
    size = int(np.prod(shape))
    read = {"crba": 1, "coriolis_matrix": 2}.get(name, 3)  # the inputs the call reads: q, v, a
    for k in range(read):
        buffer = np.zeros(size + state[k].size)
        out = buffer[:size].reshape(shape)
        x = buffer[size - 1:size - 1 + state[k].size]  # its first entry is out's last
        x[:] = state[k]
        before = buffer.copy()
        with pytest.raises(ValueError, match=r"out: shares memory with the input"):
            call(model, *(x if j == k else s for j, s in enumerate(state)), out=out)
        np.testing.assert_equal(buffer, before)


@numba.njit
def _carve(n_buffer, rows):
    buf = np.empty(n_buffer)
    first, o = take(buf, 0, (rows, 3))
    second, o = take(buf, o, (2,))
    first[rows - 1, 2] = 7.0
    second[1] = 5.0
    return buf, o


def test_workspace_views_share_the_buffer_and_never_overrun_it():
    buf, end = _carve(3 * 4 + 2, 4)
    assert end == 14 and buf[11] == 7.0 and buf[13] == 5.0
    with pytest.raises(IndexError, match="workspace buffer too small"):
        _carve(3 * 4 + 1, 4)


IMPORT_COMPILES_NOTHING = """
import importlib, pkgutil, sys
from numba.core.dispatcher import Dispatcher
import robodyn, robodyn.simulation, robodyn.control
from robodyn import _jit
import robodyn.algorithms as algorithms
for info in pkgutil.iter_modules(algorithms.__path__):
    importlib.import_module("robodyn.algorithms." + info.name)
mods = [m for name, m in list(sys.modules.items()) if name.startswith("robodyn")]
kernels = [getattr(m, n) for m in mods for n in dir(m) if isinstance(getattr(m, n), (Dispatcher, _jit._FirstCall))]
compiled = sorted({repr(k) for k in kernels if isinstance(k, Dispatcher) and k.signatures})
waiting = sum(isinstance(k, _jit._FirstCall) for k in kernels)
from robodyn.algorithms import rnea
rd = robodyn
model = rd.models.load("double_pendulum")
rd.rnea(model, [0.1, 0.2], [0.0, 0.0], [0.0, 0.0])
print(len(kernels), compiled, waiting, type(rnea._rnea_packed).__name__)
"""


def test_importing_compiles_nothing_and_the_first_call_compiles_its_fast_path(tmp_path):
    """Importing every module of the package compiles no kernel (the single-state fast paths
    wait for their first call); after ``rnea``'s first call its fast path is the compiled
    dispatcher itself in its module."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", IMPORT_COMPILES_NOTHING], env=env, capture_output=True, text=True,
                         check=True).stdout.split(maxsplit=1)[1]
    assert out.startswith("[] ") and out.split()[-1] == "CPUDispatcher", out
    assert int(out.split()[-2]) >= 6  # rnea, aba, crba, coriolis, both derivatives, the coupled ones


def test_a_compiled_helper_refuses_calls_from_python():
    """``inline`` helpers are compiled without the wrappers that Python calls go through (only
    compiled code calls them): a call from Python is a ``TypeError`` naming the helper."""
    from robodyn.algorithms.aba import pivot

    with pytest.raises(TypeError, match="pivot is a compiled helper"):
        pivot(np.eye(6), 0, 6, 0, 6, 1e-12)


def _coupled(model):
    """``model`` with its last one-dof joint mimicking its first (mimic couplings)."""
    from robodyn.joints import NV

    one = [name for name, t in zip(model.body_joint_names, model.joint_type) if NV[t] == 1]
    return rd.CoupledModel(model, [(one[-1], one[0], 1.0, 0.0)])


def _shared_code_cases():
    from robodyn.algorithms import (aba, aba_derivatives, coupled, crba, hybrid, kinematics, minv, rnea,
                                    rnea_derivatives)

    return {
        "aba": (aba._aba_batch, False, lambda m, q, v, a: rd.aba(m, q, v, a)),
        "crba": (crba._crba_batch, False, lambda m, q, v, a: rd.crba(m, q)),
        "rnea_derivatives": (rnea_derivatives._derivatives_batch, False,
                             lambda m, q, v, a: np.stack(rd.rnea_derivatives(m, q, v, a), axis=-3)),
        "aba_derivatives": (aba_derivatives._derivatives_batch, False,
                            lambda m, q, v, a: np.stack(rd.aba_derivatives(m, q, v, a), axis=-3)),
        "inverse_mass_matrix": (minv._minv_batch, False, lambda m, q, v, a: rd.inverse_mass_matrix(m, q)),
        "hybrid_dynamics": (hybrid._hybrid_batch, False,  # the base's acceleration unknown, the joints' known
                            lambda m, q, v, a: np.concatenate(rd.hybrid_dynamics(m, q, v, a, a, np.arange(m.nv) >= 6),
                                                              axis=-1)),
        "forward_kinematics": (kinematics._fk_batch, False, lambda m, q, v, a: rd.forward_kinematics(m, q)),
        "rnea (mimic couplings)": (rnea._rnea_coupled_batch, True, lambda m, q, v, a: rd.rnea(m, q, v, a)),
        "crba (mimic couplings)": (crba._crba_coupled_batch, True, lambda m, q, v, a: rd.crba(m, q)),
        "aba (mimic couplings)": (coupled._aba_coupled_batch, True, lambda m, q, v, a: rd.aba(m, q, v, a)),
    }


@pytest.mark.parametrize("name", list(_shared_code_cases()))
def test_the_fast_path_runs_the_code_the_batch_runs(name, monkeypatch):
    """A single state of contiguous float64 vectors runs, as a batch of one, the compiled code
    (``run_range``, at ``one_address``) that a batch of such states runs: an algorithm's
    per-state code is compiled once for both (``driver.BatchKernel``), and gives the same
    numbers. (Not ``rnea`` and ``coriolis_matrix``, whose fast paths keep their own copy for
    speed: see ``_rnea_packed``.)"""
    batch, mimic, call = _shared_code_cases()[name]
    model = random_model(5, seed=8, floating_base=True)
    model = _coupled(model) if mimic else model
    Q, V, A = random_state(model, np.random.default_rng(8), (3,))
    addresses, loop = [], batch.loop
    monkeypatch.setattr(batch, "loop", lambda address, *args: (addresses.append(address), loop(address, *args))[1])
    many = call(model, Q, V, A)
    assert addresses == [batch.one_address]
    for s in range(3):
        assert_rel(call(model, Q[s], V[s], A[s]), many[s], 0.0)
