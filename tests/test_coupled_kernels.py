"""The compiled paths of a model with mimic couplings: ``rnea``, ``crba`` and ``aba`` of a
:class:`robodyn.CoupledModel` run the full tree's kernels between the coupling's maps, per
state. Checked against the maps written here from the joint names (``full_state`` of
``test_mimic``: ``q_full = E(q)``, the columns of ``G`` as ``E``'s velocities), with every
input form the public functions take (batches, broadcasting, wrenches in each frame, ``out``,
lists, strided and read-only arrays), and their errors.
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import dask.array as da
import numpy as np
import pytest

import robodyn as rd
from robodyn import joints as J
from helpers import assert_rel, rng_for, states
from numba.core.dispatcher import Dispatcher

from robodyn import _jit
from robodyn.algorithms import coupled, crba, rnea
from test_mimic import IDS, MODELS, full_state

coupled_models = pytest.mark.parametrize("model", MODELS, ids=IDS)
FRAMES = (None, "local", "world", "local_world_aligned")


def reference(model, q, v, a, tau, f_ext, frame):
    """``(tau, M, qdd)`` of one state by the definitions: the full tree at ``(E(q), G v)``
    and ``G`` built column by column from :func:`full_state`."""
    qf, vf = full_state(model, q, v)
    _, af = full_state(model, q, a)
    G = np.stack([full_state(model, q, np.eye(model.nv)[j])[1] for j in range(model.nv)], axis=1)
    kw = {} if f_ext is None else dict(f_ext=f_ext, frame=frame)
    tau_r = G.T @ rd.rnea(model.full, qf, vf, af, **kw)
    M = G.T @ rd.crba(model.full, qf) @ G
    h = G.T @ rd.rnea(model.full, qf, vf, np.zeros(model.full.nv), **kw)
    return tau_r, M, np.linalg.solve(M, tau - h)


@coupled_models
@pytest.mark.parametrize("frame", FRAMES, ids=["no-wrench", *FRAMES[1:]])
def test_single_states_and_batches_are_the_full_trees_mapped(model, frame):
    rng = rng_for(model.name, "compiled", frame)
    q, v, a = states(model, "compiled", frame, size=(3,))
    tau = rng.standard_normal((3, model.nv))
    F = None if frame is None else rng.standard_normal((3, model.nbodies, 6))
    kw = {} if frame is None else dict(frame=frame)
    batch = (rd.rnea(model, q, v, a, None if F is None else F, **kw), rd.crba(model, q),
             rd.aba(model, q, v, tau, None if F is None else F, **kw))
    for s in range(3):
        f = None if F is None else F[s]
        expected = reference(model, q[s], v[s], a[s], tau[s], f, frame)
        single = (rd.rnea(model, q[s], v[s], a[s], f, **kw), rd.crba(model, q[s]),
                  rd.aba(model, q[s], v[s], tau[s], f, **kw))
        for name, one, many, ref in zip(("rnea", "crba", "aba"), single, batch, expected):
            assert_rel(one, ref, 1e-10, f"{name} of state {s}")
            assert_rel(many[s], one, 1e-13, f"{name}: batch element {s}")


@coupled_models
def test_options_and_broadcasting(model):
    q, v, a = states(model, "options", size=(4,))
    for friction in (False, True):
        for armature in (False, True):
            qf, vf = full_state(model, q[0], v[0])
            _, af = full_state(model, q[0], a[0])
            tau = rd.rnea(model, q[0], v[0], a[0], friction=friction, armature=armature)
            assert_rel(tau, model.G.T @ rd.rnea(model.full, qf, vf, af, friction=friction, armature=armature),
                       1e-12, f"rnea friction={friction} armature={armature}")
            assert_rel(rd.aba(model, q[0], v[0], tau, friction=friction, armature=armature), a[0], 1e-9,
                       f"aba inverts rnea, friction={friction} armature={armature}")
            assert_rel(rd.crba(model, q[0], armature=armature),
                       model.G.T @ rd.crba(model.full, qf, armature=armature) @ model.G, 1e-12)
    # one q against four velocities, batch shape (2, 2)
    wide = rd.rnea(model, q[0], v.reshape(2, 2, -1), a.reshape(2, 2, -1))
    assert wide.shape == (2, 2, model.nv)
    assert_rel(wide[1, 0], rd.rnea(model, q[0], v[2], a[2]), 1e-13)


def test_every_input_form_gives_the_same_result():
    """Lists, float32, strided and read-only arrays take the general path (the compiled single
    state takes contiguous float64 vectors only and compiles nothing else)."""
    model = MODELS[3]
    q, v, a = states(model, "forms")
    tau, M, qdd = rd.rnea(model, q, v, a), rd.crba(model, q), rd.aba(model, q, v, a)
    ro = [x.copy() for x in (q, v, a)]
    for x in ro:
        x.flags.writeable = False
    wide = [np.repeat(x, 2)[::2] for x in (q, v, a)]
    for form in ([x.tolist() for x in (q, v, a)], ro, wide):
        assert_rel(rd.rnea(model, *form), tau, 0.0, "rnea")
        assert_rel(rd.crba(model, form[0]), M, 0.0, "crba")
        assert_rel(rd.aba(model, *form), qdd, 0.0, "aba")
    assert_rel(rd.rnea(model, *(x.astype(np.float32) for x in (q, v, a))),
               rd.rnea(model, *(x.astype(np.float32).astype(float) for x in (q, v, a))), 0.0)
    for fn in (rnea._rnea_coupled_one, crba._crba_coupled_one, coupled._aba_coupled_one):
        assert isinstance(fn, Dispatcher), "the first call did not put the compiled kernel in its module"
        assert len(fn.signatures) == 1, "a second specialisation was compiled"
        with pytest.raises(TypeError):
            fn(*([q.tolist()] * len(fn.signatures[0])))


def test_the_first_concurrent_calls_compile_once():
    """Threads making the first call together: one compiles, the others wait and then run the
    compiled kernel (none calls the compiler after it was closed to other signatures)."""
    model = MODELS[3]
    q = states(model, "threads")[0]
    compiled = []

    class SlowDispatcher:  # the real dispatcher, its compile slowed to widen the race
        def __init__(self, real):
            self.real = real

        def compile(self, signature):
            compiled.append(signature)
            time.sleep(0.05)
            self.real.compile(signature)

        def disable_compile(self):
            self.real.disable_compile()

        def __call__(self, *args):
            return self.real(*args)

    one = crba._crba_coupled_one  # the placeholder, or the dispatcher in its place after a first call
    signature = one.signature if isinstance(one, _jit._FirstCall) else one.nopython_signatures[0]
    fresh = _jit._FirstCall(getattr(one, "py_func", None) or one.__wrapped__, signature)
    fresh.dispatcher = SlowDispatcher(fresh.dispatcher)
    k, tables = model.full.kernel, model.tables
    outs = [np.empty((model.nv, model.nv)) for _ in range(4)]
    start = threading.Barrier(4)

    def first_call(out):
        start.wait()
        return fresh(crba._crba_coupled_batch.one_address, k.ints, k.packed[False, False], tables.ints, tables.floats,
                     q, False, out)

    with ThreadPoolExecutor(4) as pool:
        statuses = list(pool.map(first_call, outs))
    assert compiled == [signature], "compiled more than once"
    assert statuses == [0] * 4
    for out in outs:
        assert_rel(out, rd.crba(model, q, armature=False), 0.0, "a concurrent first call")


def test_out():
    model = MODELS[1]
    q, v, a = states(model, "out", size=(2,))
    for call, shape in ((lambda out: rd.rnea(model, q[0], v[0], a[0], out=out), (model.nv,)),
                        (lambda out: rd.crba(model, q[0], out=out), (model.nv, model.nv)),
                        (lambda out: rd.aba(model, q[0], v[0], a[0], out=out), (model.nv,)),
                        (lambda out: rd.rnea(model, q, v, a, out=out), (2, model.nv)),
                        (lambda out: rd.aba(model, q, v, a, out=out), (2, model.nv))):
        out = np.empty(shape)
        assert call(out) is out
        assert_rel(out, call(None), 0.0)
        with pytest.raises(ValueError, match="out"):
            call(np.empty(shape[:-1] + (shape[-1] + 1,)))
    with pytest.raises(ValueError, match="overlap|share"):
        rd.rnea(model, q[0], v[0], a[0], out=v[0])


def test_errors_name_the_input():
    model = MODELS[3]  # floating base, a spherical joint
    q, v, a = states(model, "errors")
    for name, args in (("q", (np.full(model.nq, np.nan), v, a)), ("v", (q, v + np.nan, a)),
                       ("a", (q, v, a + np.inf))):
        with pytest.raises(ValueError, match=f"rnea: {name} contains NaN"):
            rd.rnea(model, *args)
    with pytest.raises(ValueError, match="aba: tau contains NaN"):
        rd.aba(model, q, v, np.full(model.nv, np.nan))
    with pytest.raises(ValueError, match="crba: q contains NaN"):
        rd.crba(model, np.full((2, model.nq), np.nan))
    with pytest.raises(ValueError, match="f_ext"):
        rd.rnea(model, q, v, a, np.full((model.nbodies, 6), np.nan))
    bad = q.copy()
    bad[3:7] *= 2.0  # the free joint's quaternion
    for call in (lambda: rd.rnea(model, bad, v, a), lambda: rd.crba(model, bad), lambda: rd.aba(model, bad, v, a),
                 lambda: rd.aba(model, np.stack([q, bad]), v, a)):
        with pytest.raises(ValueError, match="quaternion of free joint .* has norm 2"):
            call()
    with pytest.raises(ValueError, match=rf"q: expected shape \(\.\.\., {model.nq}\)"):
        rd.crba(model, np.zeros(model.full.nq))
    full, column = model.full, model.independent_q.tolist()
    ball = [column.index(full.idx_q[i]) for i in range(full.nbodies) if full.joint_type[i] == J.SPHERICAL]
    k = max(ball)  # a spherical joint after a mimic joint: its index differs in the full tree
    assert full.idx_q[full.joint_type == J.SPHERICAL].max() != k
    bad = q.copy()
    bad[k:k + 4] *= 3.0
    with pytest.raises(ValueError, match=rf"quaternion of spherical joint .* \(q\[{k}:{k + 4}\]\) has norm 3"):
        rd.rnea(model, bad, v, a)


def test_a_coupling_that_overflows_is_a_nonfinite_result():
    """Finite independent coordinates whose image ``r q + o`` on a mimic joint overflows."""
    model = MODELS[1]  # joint7 mimics joint1 (q[7]) with multiplier 3.03
    assert ("joint7", "joint1") == model.mimic[1][:2] and model.mimic[1][2] > 2.0
    q, v, a = states(model, "overflow")
    q[7] = 1e308
    for call in (lambda: rd.rnea(model, q, v, a), lambda: rd.crba(model, q), lambda: rd.aba(model, q, v, a),
                 lambda: rd.rnea(model, np.stack([q, q]), v, a)):
        with pytest.raises(ValueError, match="the result is not finite although every input is"):
            call()


def test_a_mass_matrix_that_is_not_positive_definite_is_an_error():
    """Massless bodies and no armature: ``G^T M G = 0``, and the forward dynamics is undefined."""
    model = MODELS[0]
    full = model.full
    massless = rd.CoupledModel(full.replace(theta=np.zeros_like(full.theta), armature=np.zeros(full.nv)), model.mimic)
    q, v, a = states(model, "massless", size=(2,))
    for args in ((q[0], v[0], a[0]), (q, v, a)):
        with pytest.raises(ValueError, match="aba: the mass matrix of .* independent coordinates is not positive "
                                             "definite"):
            rd.aba(massless, *args)


def test_dask_arrays_are_computed_block_by_block():
    model = MODELS[1]
    q, v, a = states(model, "dask", size=(6,))
    lazy = [da.from_array(x, chunks=(4, -1)) for x in (q, v, a)]
    for fn, args in ((rd.rnea, (0, 1, 2)), (rd.aba, (0, 1, 2)), (rd.crba, (0,))):
        result = fn(model, *(lazy[i] for i in args))
        assert isinstance(result, da.Array)
        assert_rel(result.compute(), fn(model, *((q, v, a)[i] for i in args)), 0.0, fn.__name__)
