"""Compiled runs of the contact time stepping under a compiled control law: the rollouts of a
batch (``rollout``) and the pieces of one simulation (``simulate``), both by one compiled
worker (:data:`batch` for a tree, :data:`coupled_batch` for a coupled model) whose state is
:func:`rollout_at`: Numba optimises and emits the whole contact step once per compiled
function that contains it, so one worker for both halves what a first ``simulate`` and
``rollout`` compile.

A run steps ``(q, v)`` with :func:`._contact_step.step`, the command from the law
(``control.laws.law_torque``) at each step. A model with mimic couplings
(:class:`~robodyn.coupling.CoupledModel`) is run on its full tree's state with
:func:`._coupled_contact_step.step`: its law sees the independent coordinates
``(q[independent_q], v[independent])`` and commands their forces, zero on the mimic dofs. The
coupling arguments ``cmap, cscale, independent, independent_q`` are None for a tree: Numba
then prunes the coupled branch at compile time (a test of an argument that is None). It
prunes nothing on ``cmap is None`` for an array, so for a coupled model the tree's step is
cut by a second argument, :func:`tree_marker`'s None (the coupled worker compiled the tree's
whole contact step otherwise).
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.extending import overload

from .._jit import by_address, core, inline, scratch, splice
from ..algorithms.driver import threaded_batch_kernel
from ..algorithms.status import OK
from ..contact.solver import INFO_SIZE
from ..coupling import joint_tree
from ..control.laws import law_torque, law_workspace
from . import _contact_step as CK
from . import _coupled_contact_step as CCK


@scratch
def run_workspace(nb, nv, npairs, law_nb, law_nq, law_nv, nq):
    """Scratch of :func:`run_steps` for a tree: the step's, the control law's (a model of
    ``law_nb`` bodies, its tree of sizes ``law_nq``, ``law_nv``), the command, the next state,
    and (unused) the coupled runs' reduced state and step workspace."""
    none = np.empty(0)
    return (CK.workspace(nb, nv, npairs), law_workspace(law_nb, nv, law_nq, law_nv), np.empty(nv), np.empty(nq),
            np.empty(nv), (none, none, none), none)


@scratch
def coupled_run_workspace(nb, nv, nr, npairs, law_nb, law_nq, law_nv, nq, nqr):
    """Scratch of :func:`run_steps` for a coupled model of ``nr`` (``nqr``) independent dofs
    (coordinates) on a tree of ``nv`` (``nq``): as :func:`run_workspace`, with the coupled
    step's workspace and the independent state and command."""
    return (CK.workspace(0, 0, 0), law_workspace(law_nb, nr, law_nq, law_nv), np.empty(nv), np.empty(nq),
            np.empty(nv), (np.empty(nqr), np.empty(nr), np.empty(nr)), CCK.workspace(nb, nv, nr, npairs))


def tree_marker(cmap):
    """0 for a tree (``cmap`` None), None for a coupled model: an argument whose test ``is
    None`` Numba prunes in the coupled kernels (see the module docstring)."""
    return 0 if cmap is None else None


@overload(tree_marker)
def _tree_marker_by_type(cmap):
    if isinstance(cmap, types.NoneType):
        return lambda cmap: 0
    return lambda cmap: None


@core
def run_steps(ints, body, dofs, params, fext, fcode, limit, c, law, gains, breaks, coefs, tau_cmd, points, centers,
              radii, surf, settings, s0, dt, final, Q, V, A, T, Fc, D, info, warm, rws, cmap, cscale, independent,
              independent_q, tree):
    """Steps from ``(Q[0], V[0])`` at time ``s0 dt`` under a compiled control law (see
    ``simulate._run_contacts``), writing ``Q[1:], V[1:]`` and, for every sample but the last
    unless ``final``, the step's ``A``, ``T``, contact forces ``Fc``, distances ``D`` and
    solver ``info``; ``warm`` (npairs, 3) the impulses of the step before. ``rws``:
    :func:`run_workspace` (or :func:`coupled_run_workspace` with the coupling, see the module
    docstring; ``tree``: :func:`tree_marker`). Returns ``(status, sample)`` of the first
    failure (``(OK, -1)``)."""
    ws, law_ws, cmd, qn, vn = rws[0], rws[1], rws[2], rws[3], rws[4]
    qr, vr, cmdr = rws[5]
    cws = rws[6]
    n = Q.shape[0] - 1
    for s in range(n + 1 if final else n):
        q, v, t = Q[s], V[s], (s0 + s) * dt
        if cmap is None:
            if tree is None:  # never: a coupled model's kernel, where this cuts the tree's step
                return OK, -1
            st = law_torque(law, c, gains, breaks, coefs, t, q, v, tau_cmd, law_ws, cmd)
            if st == OK:
                st = CK.step(ints, body, dofs, params, fext, fcode, limit, points, centers, radii, surf, settings, q,
                             v, cmd, dt, T[s], A[s], qn, vn, Fc[s], D[s], warm, info[s], ws)
        else:
            for i in range(qr.shape[0]):
                qr[i] = q[independent_q[i]]
            for i in range(vr.shape[0]):
                vr[i] = v[independent[i]]
            st = law_torque(law, c, gains, breaks, coefs, t, qr, vr, tau_cmd, law_ws, cmdr)
            for k in range(cmd.shape[0]):
                cmd[k] = 0.0
            for i in range(cmdr.shape[0]):
                cmd[independent[i]] = cmdr[i]
            if st == OK:
                st = CCK.step(ints, body, dofs, params, fext, fcode, limit, cmap, cscale, independent, points, centers,
                              radii, surf, settings, q, v, cmd, dt, T[s], A[s], qn, vn, Fc[s], D[s], warm, info[s], cws)
        if st != OK:
            return st, s
        if s < n:
            for k in range(qn.shape[0]):
                Q[s + 1, k] = qn[k]
            for k in range(vn.shape[0]):
                V[s + 1, k] = vn[k]
    return OK, -1


# The run is called at its compiled code's address (once per piece of a run), not copied into
# the rollout worker (see ``_jit.by_address``); inside it, the step is a direct call (by
# address, its arguments passed on every step cost 3-5 % of a contact step).
_run_steps = by_address(run_steps)

@scratch
def segments(nv, nq, npairs, every):
    """The ``every + 1`` samples of one segment of a rollout (see :func:`rollout_at`)."""
    m = every + 1
    return (np.empty((m, nq)), np.empty((m, nv)), np.empty((m, nv)), np.empty((m, nv)), np.empty((m, npairs, 3)),
            np.empty((m, npairs, 4)), np.empty((m, INFO_SIZE)))


@scratch
def rollout_workspace(nb, nv, npairs, law_nb, law_nq, law_nv, nq, every):
    """Scratch of :func:`rollout_at` for a tree: :func:`run_workspace`'s and a segment's samples."""
    return run_workspace(nb, nv, npairs, law_nb, law_nq, law_nv, nq) + (segments(nv, nq, npairs, every),)


@scratch
def coupled_rollout_workspace(nb, nv, nr, npairs, law_nb, law_nq, law_nv, nq, nqr, every):
    """Scratch of :func:`rollout_at` for a coupled model (see :func:`coupled_run_workspace`)."""
    return coupled_run_workspace(nb, nv, nr, npairs, law_nb, law_nq, law_nv, nq, nqr) + (
        segments(nv, nq, npairs, every),)


@inline
def keep(Qs, Vs, As, Ts, Fs, Ds, Is, j, A, T, Fc, D, info, k):
    """Sample ``k`` of the outputs from row ``j`` of a segment (its step's results)."""
    for r in range(A.shape[1]):
        A[k, r], T[k, r] = As[j, r], Ts[j, r]
    for p in range(D.shape[1]):
        for r in range(3):
            Fc[k, p, r] = Fs[j, p, r]
        for r in range(4):
            D[k, p, r] = Ds[j, p, r]
    for r in range(info.shape[1]):
        info[k, r] = Is[j, r]


@splice
def rollout_at(args, b, rws):
    """Rollout ``b`` of a batch (``rollout``) from its first sample, keeping every ``every``-th
    sample (segments of ``every`` steps in the workspace), or with ``every`` 0 one piece of a
    simulation (``simulate._run_contacts``): every sample straight into ``Q[b]``, ... from
    step ``s0``, the last sample stepped too when ``final``. ``warm[b]`` (npairs, 3): the
    impulses of the step before the first (zero for a rollout), then of the last step. The
    failing step into ``failed[b]`` (a rollout's step number; a piece's sample). ``bodies``
    (B or 1, nb, BODY_COLUMNS): the body table of each rollout (its inertial parameters), or
    one for all; the last four arguments the coupling (None for a tree, see the module
    docstring)."""
    (ints, bodies, dofs, params, fext, fcode, limit, c0, c1, c2, c3, c4, c5, c6, c7, law, gains, breaks, coefs,
     tau_cmd, points, centers, radii, surf, settings, dt, every, s0, final, Q, V, A, T, Fc, D, info, warm_all, failed,
     cmap, cscale, independent, independent_q) = args
    c = (c0, c1, c2, c3, c4, c5, c6, c7)  # the law's model, flat in ``args``
    body = bodies[b if bodies.shape[0] > 1 else 0]
    warm = warm_all[b]
    Qs, Vs, As, Ts, Fs, Ds, Is = rws[7]
    kept = Q.shape[1]
    pieces = 1 if every == 0 else kept
    for k in range(pieces):
        last = k == pieces - 1
        if every == 0:  # straight into the outputs
            Qk, Vk, Ak, Tk, Fk, Dk, Ik, start, fin = Q[b], V[b], A[b], T[b], Fc[b], D[b], info[b], s0, final
        else:
            for r in range(Qs.shape[1]):
                Qs[0, r] = Q[b, k, r]
            for r in range(Vs.shape[1]):
                Vs[0, r] = V[b, k, r]
            m = 1 if last else every + 1
            Qk, Vk, Ak, Tk, Fk, Dk, Ik = Qs[:m], Vs[:m], As[:m], Ts[:m], Fs[:m], Ds[:m], Is[:m]
            start, fin = s0 + k * every, last
        st, s = _run_steps(ints, body, dofs, params, fext, fcode, limit, c, law, gains, breaks, coefs, tau_cmd, points,
                           centers, radii, surf, settings, start, dt, fin, Qk, Vk, Ak, Tk, Fk, Dk, Ik, warm, rws, cmap,
                           cscale, independent, independent_q, tree_marker(cmap))
        if st != OK:
            failed[b] = s if every == 0 else k * every + s
            return st
        if every != 0:
            keep(Qs, Vs, As, Ts, Fs, Ds, Is, 0, A[b], T[b], Fc[b], D[b], info[b], k)
            if not last:
                for r in range(Qs.shape[1]):
                    Q[b, k + 1, r] = Qs[every, r]
                for r in range(Vs.shape[1]):
                    V[b, k + 1, r] = Vs[every, r]
    failed[b] = -1
    return OK


batch = threaded_batch_kernel(rollout_at, rollout_workspace)
coupled_batch = threaded_batch_kernel(rollout_at, coupled_rollout_workspace)


def run_batch(args, tree, coupled, law_model, npairs: int, every: int, status, nchunk: int) -> None:
    """:data:`batch` (``coupled`` None) or :data:`coupled_batch` (``coupled`` the
    :class:`~robodyn.coupling.CoupledModel` on ``tree``) on ``args`` (see :func:`rollout_at`),
    the workspace sized for ``tree``, the control law's model ``law_model`` and ``npairs``."""
    law = joint_tree(law_model)
    per_law = (npairs, law.nbodies, law.nq, law.nv)
    if coupled is None:
        batch(args, (tree.nbodies, tree.nv, *per_law, tree.nq, every), status, nchunk)
    else:
        coupled_batch(args, (tree.nbodies, tree.nv, coupled.nv, *per_law, tree.nq, coupled.nq, every), status, nchunk)
