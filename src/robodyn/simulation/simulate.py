"""Forward simulation of a robot, free or under a controller.

    (M(q) + armature) qdd + C(q, qd) qd + g(q) + friction(qd) = clip(tau(t, q, qd), -tau_max, tau_max)

integrated from ``(q0, v0)`` on the configuration manifold (see ``_kernels``): every
integrator steps in a chart centred at the current configuration, so a floating base's
quaternion stays of unit norm. The controller is evaluated at every stage of the integrator
(a continuous-time control law), its command clipped to the model's effort limits
(``Model.effort_limit``; infinite for no limit), and the model's joint friction
(``damping``, ``coulomb``) and armature act on the motion.
"""

from __future__ import annotations

import sys
import time
import warnings
from typing import NamedTuple

import numpy as np

from .._deprecated import renamed_keyword
from .. import joints as J
from ..coupling import is_coupled, joint_tree
from ..algorithms.rnea import external_wrenches, rnea
from ..algorithms.status import NOT_POSITIVE_DEFINITE, OK, raise_for_status, raise_not_positive_definite
from ..contact import solver as CS
from ..control.laws import CONSTANT
from ..errors import RobodynWarning, user_stacklevel
from . import _contact_runs as CR
from . import _contact_step as CK
from . import _coupled_contact_step as CCK
from . import _kernels as K
from . import coupled
from .stiction import run_stiction
from .trajectory import Trajectory

INTEGRATORS = ("semi_implicit_euler", "rk4")
SYMPLECTIC = "symplectic"  # Störmer-Verlet in momentum form (simulation/symplectic.py), fixed bases
SCIPY_INTEGRATORS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")

# Runs of at least this many steps show a progress bar (when stderr is a terminal).
PROGRESS_STEPS = 20000


class Progress:
    """A one-line progress bar on stderr: ``[#####     ]  50%  1.2 s``, shown only when
    ``enabled`` (by default when stderr is a terminal)."""

    def __init__(self, total: int, enabled: bool | None = None, width: int = 30, stream=None):
        self.stream = sys.stderr if stream is None else stream
        self.enabled = self.stream.isatty() if enabled is None else bool(enabled)
        self.total, self.width, self.start, self.shown = max(int(total), 1), width, time.perf_counter(), -1

    def update(self, done: int) -> None:
        if not self.enabled:
            return
        pct = int(100 * done / self.total)
        if pct == self.shown:
            return
        self.shown = pct
        filled = self.width * pct // 100
        elapsed = time.perf_counter() - self.start
        self.stream.write(f"\r[{'#' * filled}{' ' * (self.width - filled)}] {pct:3d}%  {elapsed:.1f} s")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.update(self.total)
            self.stream.write("\n")
            self.stream.flush()


def _vector(name: str, x, n: int) -> np.ndarray:
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(x).__name__}") from None
    if a.shape != (n,):
        raise ValueError(f"{name}: expected shape ({n},), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or Inf")
    return a


def positive_number(name: str, x) -> float:
    """``x`` as a finite float > 0, or a ``ValueError`` naming ``name``."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {x!r}") from None
    if not (np.isfinite(x) and x > 0):
        raise ValueError(f"{name}: must be finite and > 0, got {x}")
    return x


def positive_integer(name: str, x) -> int:
    """``x`` as an int >= 1 (an integer, not a bool), or a ``ValueError`` naming ``name``."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < 1:
        raise ValueError(f"{name}: expected a positive integer, got {x!r}")
    return int(x)


class _Law:
    """The controller as the integrators see it: ``torque(t, q, v, z)`` and the rate of its
    internal state ``z`` (empty for a stateless callable ``(t, q, v) -> tau``)."""

    def __init__(self, controller, model):
        self.controller = controller
        if controller is None:
            zero = np.zeros(model.nv)
            self.controller = lambda t, q, v: zero
        z0 = getattr(controller, "state0", None)
        self.stateful = z0 is not None
        self.z0 = np.zeros(0) if z0 is None else _vector("controller.state0", z0, np.size(z0))
        self.nz = self.z0.shape[0]

    def torque(self, t, q, v, z):
        return self.controller.torque(t, q, v, z) if self.stateful else self.controller(t, q, v)

    def rate(self, t, q, v, z, out):
        if self.stateful:
            r = np.asarray(self.controller.state_rate(t, q, v, z), dtype=float)
            if r.shape != (self.nz,):
                raise ValueError(f"controller: state_rate returned shape {r.shape} at t = {t}, expected ({self.nz},)")
            out[:] = r


class _Plant:
    """The model's kernel arrays and the Python-driven stages of the integrators, with the
    external wrenches (``f_ext``: None, an (nb, 6) array, or a callable ``(t, q, v) -> (nb, 6)``
    in ``frame``) and bilateral ``constraints`` (Baumgarte ``(alpha, beta)``)."""

    def __init__(self, model, f_ext=None, frame="local", constraints=(), baumgarte=(0.0, 0.0)):
        k = model.kernel
        self.model, self.frame = model, frame
        self.wrench = f_ext if callable(f_ext) else None
        fext, fcode = external_wrenches(model, None if callable(f_ext) else f_ext, frame)
        self.args = (k.ints, k.body, k.dofs[True, True], k.params[True], fext, fcode,
                     np.ascontiguousarray(model.effort_limit))
        self.constraints, self.baumgarte = tuple(constraints), baumgarte
        self.constraint_force = None
        self.ws, self.R = K.stage_workspace(model.nbodies, model.nq, model.nv)

    def keep(self, s: int) -> None:
        """Sample ``s``'s constraint forces (those of its first stage), when constrained."""
        if self.constraints:
            self.CF[s] = self.constraint_force

    @property
    def compiled(self) -> bool:
        """True when the whole run may be compiled (no Python callable on the way)."""
        return self.wrench is None and not self.constraints

    def args_at(self, t, q, v):
        """The kernel arguments at ``(t, q, v)``: the callable wrenches evaluated there."""
        if self.wrench is None:
            return self.args
        try:
            fext, fcode = external_wrenches(self.model, self.wrench(t, q, v), self.frame)
        except ValueError as e:
            raise ValueError(f"f_ext at t = {t:.6g}: {e}") from None
        return self.args[:4] + (fext, fcode) + self.args[6:]

    # The kernels take C-contiguous arrays only (SciPy's integrators hand over strided views),
    # so that each compiles once.
    def point(self, q0, theta, q):
        K.point(self.args[0], q0, np.ascontiguousarray(theta), q)

    def rate(self, q, theta, v, out):
        K.rate(self.args[0], q, np.ascontiguousarray(theta), np.ascontiguousarray(v), self.R, out)

    def derivative(self, t, q, theta, v, law, z, tau, thetadot, a, zdot):
        """``(theta', a, z')`` into the given arrays; the applied torque into ``tau``."""
        law.rate(t, q, v, z, zdot)
        cmd = _command(law, t, q, v, z, self.model.nv)
        args = self.args_at(t, q, v)
        if self.constraints:
            self._constrained(args, t, q, theta, v, cmd, tau, thetadot, a)
            return
        status = K.stage(*args, q, np.ascontiguousarray(theta), np.ascontiguousarray(v), cmd, tau, thetadot, a,
                         self.ws, self.R)
        if status != OK:
            raise_at(self.model, status, t, q, v, cmd)

    def _constrained(self, args, t, q, theta, v, cmd, tau, thetadot, a):
        """The constrained stage: ``a`` of :func:`constrained_dynamics` under the clipped command
        plus the external wrenches' joint forces ``sum J^T f = rnea(q, 0, 0) - rnea(q, 0, 0, f)``;
        the constraint forces into ``self.constraint_force``."""
        from ..algorithms.constrained import constrained_dynamics

        model, zero = self.model, np.zeros(self.model.nv)
        np.clip(cmd, -args[6], args[6], out=tau)
        total = tau.copy()
        if args[5] >= 0:
            total += rnea(model, q, zero, zero) - rnea(model, q, zero, zero, args[4], self.frame)
        try:
            res = constrained_dynamics(model, q, v, total, self.constraints, self.baumgarte)
        except ValueError as e:
            raise ValueError(f"simulate at t = {t:.6g}: {e}; the motion diverged or the controller returned NaN/Inf") \
                from None
        a[:] = res.a
        self.constraint_force = np.concatenate([np.ravel(f) for f in res.forces])
        self.rate(q, theta, v, thetadot)


def raise_at(model, status, t, q, v, tau, coupled: bool = False):
    """The error of a step's status at time ``t`` (``coupled``: the step of a model with mimic
    couplings on its full tree ``model``)."""
    if status == NOT_POSITIVE_DEFINITE:
        raise_not_positive_definite(model, f"simulate at t = {t:.6g}", " in its independent coordinates" if coupled
                                    else "")
    try:
        bad = raise_for_status(model, status, {"q": q, "v": v, "tau (controller output)": tau},
                               f"simulate at t = {t:.6g}")
    except ValueError as e:
        raise ValueError(f"{e}; the motion diverged or the controller returned NaN/Inf") from None
    raise ValueError(f"simulate at t = {t:.6g}: the articulated inertia of body {bad - 1} "
                     f"({model.link_names[bad - 1]!r}) is singular; the forward dynamics is undefined")


def simulate(model, q0, v0, duration: float, dt: float, controller=None, integrator: str | None = None, *,
             contacts=None, f_ext=None, frame: str = "local", constraints=None, baumgarte=None,
             rtol: float = 1e-8, atol: float = 1e-10, progress: bool | None = None, stiction: bool = False,
             f_ext_frame=None) -> Trajectory:
    """Simulate the robot from ``(q0, v0)`` for ``duration`` seconds, sampled every ``dt``.

    Args:
        q0: (nq,) initial configuration (unit quaternions). v0: (nv,) initial velocity.
        duration, dt: seconds, ``> 0``; ``round(duration / dt)`` steps, samples at ``k dt``.
        controller: None (no joint forces), or a callable ``(t, q, v) -> tau`` (nv,) such as
            the controllers of :mod:`robodyn.control` (which may use another model than
            ``model``: model mismatch). Its ``lyapunov(t, q, v)`` (when it has one) and its
            reference ``desired(t) -> (q_d, v_d, a_d)`` are sampled into the trajectory.
            The command is clipped to ``[-model.effort_limit, model.effort_limit]``.
            A controller with an internal state (``state0`` (nz,), e.g. integral action or
            parameter estimates) is called as ``torque(t, q, v, z)``, and its state is
            integrated with the robot from ``z' = state_rate(t, q, v, z)``.
        integrator: ``"rk4"`` (classic 4th-order Runge-Kutta in the manifold chart; the
            default without contacts), ``"semi_implicit_euler"`` (the default and the only
            one with contacts) (``v+ = v + dt a(q, v)``, ``q+ = q ⊞ dt v+``), ``"symplectic"``
            (Störmer-Verlet in momentum form, :mod:`robodyn.simulation.symplectic`: second
            order, the energy of an unforced robot stays bounded over any number of steps;
            fixed bases of 1-dof joints, from Python), or a SciPy
            ``solve_ivp`` method (``"RK45"``, ``"DOP853"``, ``"Radau"``, ...), adaptive between
            samples with tolerances ``rtol``, ``atol``, restarted in a new chart at each sample.
        contacts: a :class:`robodyn.contact.Contacts` (shapes on the bodies, surfaces of the
            world, solver settings), or None. With contacts, every step solves the contact
            impulses (unilateral, Coulomb friction cones, impacts: see
            :mod:`robodyn.contact.solver`), and the trajectory holds each pair's contact
            force and distance and the solver's sweeps and residual at every sample; a step
            whose solve did not reach the tolerance is reported in one warning.
        f_ext: external wrenches ``[force, torque]`` on the bodies, (nbodies, 6) in
            ``frame`` (``"local"``, ``"world"``, ``"local_world_aligned"``, as
            :func:`robodyn.rnea`): an array (constant, compiled runs stay compiled) or a callable
            ``(t, q, v) -> (nbodies, 6)`` evaluated at every stage (a push, a spring to the
            world, an interaction force).
        constraints: bilateral constraints (:class:`robodyn.PointConstraint`,
            ``WeldConstraint``, ``LoopConstraint``, ``DistanceConstraint``, ``CouplingConstraint``;
            a closed chain, a pinned point) held by :func:`robodyn.constrained_dynamics` at every
            stage with Baumgarte stabilisation ``baumgarte = (alpha, beta)`` (1/s; default
            ``(0.1 / dt, 0.1 / dt)``, position errors decaying critically damped over about ten
            steps), so that the loop stays closed over long runs; the constraint forces are
            sampled into ``traj.constraint_force``. Not with contacts.
        progress: show a progress bar on stderr (None: when stderr is a terminal and the run
            has at least ``PROGRESS_STEPS`` steps).
        stiction: exact stiction: the joints' dry friction (``coulomb`` with the Stribeck
            effect) as a set-valued force solved at every step of ``"semi_implicit_euler"``
            (:mod:`robodyn.simulation.stiction`): a joint stops and stays at rest exactly while
            the torque on it stays below its breakaway level ``coulomb + stribeck``, where the
            smooth law (``coulomb_smoothing``) creeps and the sign law chatters; the friction
            torques are sampled into ``traj.joint_friction``. Not with contacts or
            constraints; from Python. A model with mimic couplings solves it in its
            independent coordinates (see ``stiction.run_stiction``).

    Returns:
        :class:`Trajectory` (t, q, v, a, tau, energies, Lyapunov function, reference).

    Without controller, and with the built-in :class:`robodyn.control.PDGravity` and
    :class:`robodyn.control.ComputedTorque` (on a ``cubic``/``quintic``/``Sampled``
    reference), the fixed-step integrators run entirely in compiled code; other callables
    are called from a Python loop.
    Reference: Hairer, Lubich, Wanner, *Geometric Numerical Integration* (2006), IV.8
    (Runge-Kutta methods in local charts of a manifold).
    """
    if f_ext_frame is not None:  # the old spelling of ``frame``
        frame = renamed_keyword("f_ext_frame", f_ext_frame, "frame", frame, "simulate()")
    q0 = _vector("q0", q0, model.nq)
    v0 = _vector("v0", v0, model.nv)
    duration, dt = positive_number("duration", duration), positive_number("dt", dt)
    if dt > duration:
        raise ValueError(f"dt: must not exceed duration ({duration}), got {dt}")
    if contacts is not None:
        from ..contact.geometry import Contacts

        if not isinstance(contacts, Contacts):
            raise ValueError(f"contacts: expected a robodyn.contact.Contacts or None, got {type(contacts).__name__}")
        if integrator not in (None, "semi_implicit_euler"):
            raise ValueError(f"integrator: {integrator!r} cannot step through impacts; with contacts the time "
                             f"stepping is 'semi_implicit_euler' (the default)")
    if stiction and (integrator not in (None, "semi_implicit_euler") or contacts is not None or constraints):
        raise ValueError("stiction: the set-valued joint friction is solved by the 'semi_implicit_euler' time "
                         "stepping, without contacts or constraints"
                         + (f"; got integrator {integrator!r}" if integrator not in (None, "semi_implicit_euler")
                            else ""))
    if integrator is None:
        integrator = "rk4" if contacts is None and not stiction else "semi_implicit_euler"
    if integrator not in INTEGRATORS + SCIPY_INTEGRATORS + (SYMPLECTIC,):
        raise ValueError(f"integrator: unknown {integrator!r}; choose one of "
                         f"{INTEGRATORS + (SYMPLECTIC,) + SCIPY_INTEGRATORS}")
    if integrator == SYMPLECTIC and (model.nq != model.nv or constraints):
        raise ValueError("integrator 'symplectic': fixed-base models of 1-dof joints without constraints only "
                         f"(this one has nq = {model.nq}, nv = {model.nv}{', constraints' if constraints else ''}); "
                         "use 'rk4'")
    if controller is not None and not callable(controller):
        raise ValueError(f"controller: expected None or a callable (t, q, v) -> tau, got {type(controller).__name__}")
    cmodel = getattr(controller, "model", None)
    sizes = (getattr(cmodel, "nq", model.nq), getattr(cmodel, "nv", model.nv))
    if cmodel is not None and sizes != (model.nq, model.nv):
        raise ValueError(f"controller: its model has nq={cmodel.nq}, nv={cmodel.nv}; the simulated model has "
                         f"nq={model.nq}, nv={model.nv}")
    options = dict(contacts=contacts, f_ext=f_ext, frame=frame, constraints=constraints, baumgarte=baumgarte,
                   rtol=rtol, atol=atol, progress=progress, stiction=stiction)
    if is_coupled(model):
        return _simulate_coupled(model, q0, v0, duration, dt, controller, integrator, **options)
    return _simulate_tree(model, q0, v0, duration, dt, controller, integrator, **options)


def _simulate_tree(model, q0, v0, duration, dt, controller, integrator, *, contacts, f_ext, frame, constraints,
                   baumgarte, rtol, atol, progress, stiction, coupling=None) -> Trajectory:
    """:func:`simulate` of a tree, its arguments checked; with ``coupling`` (a
    :class:`~robodyn.coupling.CoupledModel` whose ``full`` is ``model``), the contact steps of
    the coupled model on the full tree's state (:mod:`._coupled_contact_step`), or its
    stiction (the tree under the couplings, the friction in the independent coordinates)."""
    unit_configuration(model, q0)
    n = max(1, int(round(duration / dt)))
    t = np.arange(n + 1) * dt
    Q, V = np.empty((n + 1, model.nq)), np.empty((n + 1, model.nv))
    A, T = np.zeros((n + 1, model.nv)), np.zeros((n + 1, model.nv))
    bar = Progress(n, enabled=(n >= PROGRESS_STEPS and sys.stderr.isatty()) if progress is None else progress)
    if f_ext is not None and not callable(f_ext):
        f_ext = np.array(f_ext, dtype=float)
    constraints = () if constraints is None else (constraints if isinstance(constraints, (list, tuple))
                                                 else (constraints,))
    baumgarte = (0.1 / dt, 0.1 / dt) if baumgarte is None else baumgarte
    if constraints and contacts is not None:
        raise ValueError("constraints: not with contacts (bilateral constraints and contacts in one solve are not "
                         "supported yet); model the contacts or the constraints alone")
    dry = model.replace(coulomb=np.zeros(model.nv), stribeck=np.zeros(model.nv)) if stiction else model
    plant, law = _Plant(dry, f_ext, frame, constraints, baumgarte), _Law(controller, model)
    if constraints:
        from ..algorithms.constrained import constrained_dynamics

        held = constrained_dynamics(model, q0, v0, np.zeros(model.nv), constraints, baumgarte)  # checks them
        plant.CF = np.zeros((n + 1, sum(np.size(f) for f in held.forces)))
    Z = np.empty((n + 1, law.nz))
    Z[0] = law.z0
    compiled = None
    if integrator in INTEGRATORS and not law.stateful and plant.compiled:
        inner = controller.controller if isinstance(controller, coupled.ReducedLaw) else controller
        compiled = (CONSTANT, None, None, None, None) if inner is None else compiled_law(inner)
    touch = friction = None
    if stiction:
        friction = run_stiction(model, plant, law, q0, v0, dt, t, Q, V, Z, A, T, bar, coupling=coupling)[0]
    elif contacts is not None:
        touch = _run_contacts(plant, compiled, law, contacts, q0, v0, dt, t, Q, V, Z, A, T, bar, coupling)
    elif compiled is not None:
        _run_compiled(plant, compiled, integrator, q0, v0, dt, t, Q, V, A, T, bar)
    elif integrator == SYMPLECTIC:
        from .symplectic import run_symplectic

        run_symplectic(plant, law, q0, v0, dt, t, Q, V, Z, A, T, bar)
    elif integrator in INTEGRATORS:
        _run_fixed_step(plant, integrator, law, q0, v0, dt, t, Q, V, Z, A, T, bar)
    else:
        _run_scipy(plant, integrator, law, q0, v0, t, Q, V, Z, A, T, bar, rtol, atol)
    bar.close()
    traj = _trajectory(model, controller, law, integrator, t, Q, V, Z, A, T, touch, friction)
    if constraints:
        from dataclasses import replace

        traj = replace(traj, constraint_force=plant.CF)
    return traj


def _simulate_coupled(model, q0, v0, duration, dt, controller, integrator, *, contacts, constraints, stiction,
                      **options) -> Trajectory:
    """:func:`simulate` of a model with mimic couplings: its full tree under the couplings
    (:mod:`robodyn.simulation.coupled`), with contacts by the coupled model's own contact step
    (:mod:`._coupled_contact_step`), read back in the independent coordinates."""
    if stiction:  # the friction solved in the independent coordinates (stiction.run_stiction)
        q0f, v0f, law, held = coupled.full_tree_problem(model, q0, v0, controller, ())
        traj = _simulate_tree(model.full, q0f, v0f, duration, dt, law, "semi_implicit_euler", contacts=None,
                              constraints=held, stiction=True, coupling=model, **options)
        return coupled.reduced_trajectory(model, traj, False)
    user = () if constraints is None else (constraints if isinstance(constraints, (list, tuple)) else (constraints,))
    if contacts is not None:  # the tree's checks refuse the caller's constraints with contacts
        q0f, v0f, law, _ = coupled.full_tree_problem(model, q0, v0, controller, ())
        traj = _simulate_tree(model.full, q0f, v0f, duration, dt, law, integrator, contacts=contacts,
                              constraints=user, stiction=False, coupling=model, **options)
        return coupled.reduced_trajectory(model, traj, False)
    q0f, v0f, law, held = coupled.full_tree_problem(model, q0, v0, controller, user)
    traj = simulate(model.full, q0f, v0f, duration, dt, law, integrator, constraints=held, **options)
    return coupled.reduced_trajectory(model, traj, bool(user))


def unit_configuration(model, q0: np.ndarray, name: str = "q0") -> None:
    """Normalise in place the unit parts of ``q0`` (..., nq) (quaternions, a planar joint's
    ``(cos, sin)``); an error names one that is farther than ``joints.QUAT_TOL`` from unit."""
    for i in np.flatnonzero(J.UNIT_SIZE[model.joint_type] > 0):
        k, size = model.idx_q[i] + J.UNIT_OFFSET[model.joint_type[i]], J.UNIT_SIZE[model.joint_type[i]]
        n = np.linalg.norm(q0[..., k:k + size], axis=-1, keepdims=True)
        if np.any(abs(n - 1.0) > J.QUAT_TOL):
            unit = "quaternion" if size == 4 else "(cos, sin)"
            bad = np.unravel_index(np.argmax(abs(n - 1.0)), n.shape)[:-1]
            where = f"{name}[{', '.join(map(str, bad)) + ', ' if bad else ''}{k}:{k + size}]"
            raise ValueError(f"{name}: {unit} {where} has norm {float(n[bad][0]):.6g}, not 1; normalise it")
        q0[..., k:k + size] /= n


def compiled_law(controller):
    """The compiled form of a built-in controller (``kernel_law``), with its model's arrays."""
    spec = getattr(controller, "kernel_law", None)
    spec = spec() if callable(spec) else None
    return None if spec is None else (spec[0], controller.model, *spec[1:])


def law_arrays(model, compiled):
    """``(c, law, gains, breaks, coefs)``: the arguments of ``laws.law_torque`` for a compiled law
    (its model's tree and, for a model with mimic couplings, its ``CouplingTables``)."""
    law, cmodel, gains, breaks, coefs = compiled
    if law == CONSTANT:
        nv = model.nv
        cmodel, gains, breaks, coefs = model, np.zeros((2, nv)), np.array([0.0, 1.0]), np.zeros((1, 1, nv))
    tables = cmodel.tables if is_coupled(cmodel) else NO_COUPLING
    k = joint_tree(cmodel).kernel
    return (k.ints, k.body, k.dofs[False, False], k.dofs[True, True], k.params[True], k.zero_wrench, *tables), law, \
        gains, breaks, coefs


NO_COUPLING = (np.zeros(0, np.int64), np.zeros(0))  # a law's model without mimic couplings (see law_torque)


def _run_compiled(plant, compiled, integrator, q0, v0, dt, t, Q, V, A, T, bar):
    """Compiled runs (no controller, or a built-in one), in pieces of about 1% of the run
    when the progress bar is shown."""
    model = plant.model
    nv = model.nv
    c, law, gains, breaks, coefs = law_arrays(model, compiled)
    n = Q.shape[0] - 1
    method = K.RK4 if integrator == "rk4" else K.SEMI_IMPLICIT_EULER
    zero = np.zeros(nv)
    piece = max(1, n // 100) if bar.enabled else n
    Q[0], V[0] = q0, v0
    for a in range(0, n, piece):
        b = min(n, a + piece)
        status, s = K.run(*plant.args, c, law, gains, breaks, coefs, zero, method, Q[a].copy(), V[a].copy(), a, dt,
                          Q[a:b + 1], V[a:b + 1], A[a:b + 1], T[a:b + 1])
        if status != OK:
            raise_at(model, status, t[a + s], Q[a + s], V[a + s], T[a + s])
        bar.update(b)


class Touch(NamedTuple):
    """The contact samples of a run: pair names, each pair's friction (npairs,), forces
    (N, npairs, 3), geometry (N, npairs, 4: signed distance and surface normal), solver info
    (N, 3)."""
    names: tuple
    friction: np.ndarray
    force: np.ndarray
    geometry: np.ndarray
    info: np.ndarray


def _run_contacts(plant, compiled, law, contacts, q0, v0, dt, t, Q, V, Z, A, T, bar, coupling=None):
    """Time stepping with contacts (see ``_contact_step``): compiled runs under a compiled
    law (in pieces of about 1% of the run when the progress bar is shown), else one compiled
    step per sample from a Python loop (with ``coupling``, the coupled model's step,
    ``_coupled_contact_step``, on the full tree's state, and a compiled law in its independent
    coordinates); warns when a solve did not converge."""
    model = plant.model
    (points, centers, radii), surf, settings, names = contacts.pack(model)
    N, nv, nz = Q.shape[0], model.nv, Z.shape[1]
    n = N - 1
    friction = surf[np.arange(len(names)) % surf.shape[0], CS.FRICTION]
    touch = Touch(names, friction, np.zeros((N, len(names), 3)), np.zeros((N, len(names), 4)),
                  np.zeros((N, CS.INFO_SIZE)))
    warm = np.zeros((len(names), 3))
    geometry = (points, centers, radii, surf, settings)
    Q[0], V[0] = q0, v0
    if compiled is not None:  # the rollouts' worker, on the pieces of this one run (``every`` 0)
        c, code, gains, breaks, coefs = law_arrays(model, compiled)
        ints, body, *rest = plant.args
        fixed = (ints, body[None], *rest, *c, code, gains, breaks, coefs, np.zeros(nv), *geometry, dt, 0)
        coupling_args = (None,) * 4 if coupling is None else coupled.run_coupling(coupling)
        law_model = model if compiled[0] == CONSTANT else compiled[1]  # (with a coupling: its coordinates)
        status, failed = np.zeros(1, np.int64), np.zeros(1, np.int64)
        piece = max(1, n // 100) if bar.enabled else n
        for a in range(0, n, piece):
            b = min(n, a + piece)
            pieces = (x[None, a:b + 1] for x in (Q, V, A, T, touch.force, touch.geometry, touch.info))
            CR.run_batch((*fixed, a, b == n, *pieces, warm[None], failed, *coupling_args), model, coupling, law_model,
                         len(names), 0, status, 1)
            if status[0] != OK:
                s = int(failed[0])
                raise_at(model, int(status[0]), t[a + s], Q[a + s], V[a + s], T[a + s], coupling is not None)
            bar.update(b)
    else:
        step, ws, extra = CK.step_kernel, CK.workspace(model.nbodies, nv, len(names)), ()
        if coupling is not None:
            step, ws, extra = CCK.step_kernel, CCK.workspace(model.nbodies, nv, coupling.nv, len(names)), \
                coupled.contact_coupling(coupling)
        every = max(1, n // 100)
        zdot = np.empty(nz)
        for s in range(N):
            q, v, z = Q[s], V[s], Z[s]
            cmd = _command(law, t[s], q, v, z, nv)
            law.rate(t[s], q, v, z, zdot)
            qn, vn = (Q[s + 1], V[s + 1]) if s < n else (np.empty(model.nq), np.empty(nv))
            status = step(*plant.args_at(t[s], q, v), *extra, *geometry, q, v, cmd, dt, T[s], A[s], qn, vn,
                          touch.force[s], touch.geometry[s], warm, touch.info[s], ws)
            if status != OK:
                raise_at(model, status, t[s], q, v, cmd, coupling is not None)
            if s < n:
                Z[s + 1] = z + dt * zdot
            if s % every == 0:
                bar.update(s)
    residual = touch.info[:, CS.RESIDUAL]
    bad = residual > contacts.warn_above
    if bad.any():
        worst = int(np.argmax(residual))
        warnings.warn(f"simulate: the contact solver stopped above {contacts.warn_above:g} m/s in {int(bad.sum())} of "
                      f"{N} steps (largest residual {residual[worst]:.3g} m/s at t = {t[worst]:.6g} after "
                      f"{int(touch.info[worst, CS.ITERATIONS])} iterations; the tolerance is "
                      f"{contacts.tolerance:g} m/s); raise Contacts.max_iterations or lower the time step",
                      RobodynWarning, stacklevel=user_stacklevel())
    return touch


def _command(law, t, q, v, z, nv):
    """The controller's command at ``(t, q, v, z)`` as a float64 (nv,) array."""
    cmd = law.torque(t, q, v, z)
    if type(cmd) is not np.ndarray or cmd.dtype != np.float64 or cmd.shape != (nv,):
        cmd = np.asarray(cmd, dtype=float)
        if cmd.shape != (nv,):
            raise ValueError(f"controller: returned shape {cmd.shape} at t = {t}, expected ({nv},)")
    return np.ascontiguousarray(cmd)


def _run_fixed_step(plant, integrator, law, q0, v0, dt, t, Q, V, Z, A, T, bar):
    nq, nv, nz = Q.shape[1], V.shape[1], Z.shape[1]
    n = Q.shape[0] - 1
    zero = np.zeros(nv)
    theta, qi, vi, zi, tau = np.empty(nv), np.empty(nq), np.empty(nv), np.empty(nz), np.empty(nv)
    kt, ka, kz = np.empty((4, nv)), np.empty((4, nv)), np.empty((4, nz))
    Q[0], V[0] = q0, v0
    every = max(1, n // 100)
    for s in range(n + 1):
        q, v, z = Q[s], V[s], Z[s]
        plant.derivative(t[s], q, zero, v, law, z, T[s], kt[0], A[s], kz[0])
        plant.keep(s)
        if s == n:
            break
        if integrator == "semi_implicit_euler":
            V[s + 1] = v + dt * A[s]
            Z[s + 1] = z + dt * kz[0]
            plant.rate(q, zero, V[s + 1], kt[1])
            plant.point(q, dt * kt[1], Q[s + 1])
        else:
            ka[0] = A[s]
            for j, h in ((1, 0.5 * dt), (2, 0.5 * dt), (3, dt)):
                np.multiply(kt[j - 1], h, out=theta)
                np.multiply(ka[j - 1], h, out=vi)
                vi += v
                np.multiply(kz[j - 1], h, out=zi)
                zi += z
                plant.point(q, theta, qi)
                plant.derivative(t[s] + h, qi, theta, vi, law, zi, tau, kt[j], ka[j], kz[j])
            V[s + 1] = v + dt / 6.0 * (ka[0] + 2.0 * ka[1] + 2.0 * ka[2] + ka[3])
            Z[s + 1] = z + dt / 6.0 * (kz[0] + 2.0 * kz[1] + 2.0 * kz[2] + kz[3])
            plant.point(q, dt / 6.0 * (kt[0] + 2.0 * kt[1] + 2.0 * kt[2] + kt[3]), Q[s + 1])
        if s % every == 0:
            bar.update(s)


def _run_scipy(plant, method, law, q0, v0, t, Q, V, Z, A, T, bar, rtol, atol):
    """``solve_ivp`` on ``(theta, v, z)`` between consecutive samples, in the chart of the first."""
    from scipy.integrate import solve_ivp

    nq, nv, nz = Q.shape[1], V.shape[1], Z.shape[1]
    n = Q.shape[0] - 1
    zero = np.zeros(nv)
    qi, tau = np.empty(nq), np.empty(nv)
    dy = np.empty(2 * nv + nz)
    Q[0], V[0] = q0, v0
    every = max(1, n // 100)
    for s in range(n + 1):
        q = Q[s]
        plant.derivative(t[s], q, zero, V[s], law, Z[s], T[s], dy[:nv], A[s], dy[2 * nv:])
        plant.keep(s)
        if s == n:
            break

        def f(ti, y, q=q):
            theta = y[:nv]
            plant.point(q, theta, qi)
            plant.derivative(ti, qi, theta, y[nv:2 * nv], law, y[2 * nv:], tau, dy[:nv], dy[nv:2 * nv], dy[2 * nv:])
            return dy.copy()

        y0 = np.concatenate([zero, V[s], Z[s]])
        sol = solve_ivp(f, (t[s], t[s + 1]), y0, method=method, rtol=rtol, atol=atol)
        if not sol.success:
            raise ValueError(f"simulate: solve_ivp ({method}) failed between t = {t[s]:.6g} and {t[s + 1]:.6g}: "
                             f"{sol.message}")
        plant.point(q, sol.y[:nv, -1], Q[s + 1])
        V[s + 1] = sol.y[nv:2 * nv, -1]
        Z[s + 1] = sol.y[2 * nv:, -1]
        if s % every == 0:
            bar.update(s)


def spring_energy(model, Q) -> np.ndarray:
    """``sum_k stiffness_k (q_k - spring_reference_k)^2 / 2`` (...,) of configurations ``Q``
    (..., nq): the energy stored in the joint springs (joints of one dof)."""
    one = np.flatnonzero(J.NV[model.joint_type] == 1)
    k, iq = model.idx_v[one], model.idx_q[one]
    return 0.5 * ((Q[..., iq] - model.spring_reference[k]) ** 2) @ model.stiffness[k]


def _trajectory(model, controller, law, integrator, t, Q, V, Z, A, T, touch=None, friction=None) -> Trajectory:
    from ..algorithms.energy import kinetic_energy, potential_energy

    kinetic = kinetic_energy(model, Q, V) + 0.5 * (V * V) @ model.armature
    potential = potential_energy(model, Q) + spring_energy(model, Q)
    lyapunov = q_d = v_d = None
    vectorized = getattr(controller, "vectorized", False) and not law.stateful
    if callable(getattr(controller, "lyapunov", None)):
        if vectorized:
            lyapunov = np.asarray(controller.lyapunov(t, Q, V), dtype=float)
        else:
            extra = (lambda k: (Z[k],)) if law.stateful else (lambda k: ())
            lyapunov = np.array([controller.lyapunov(t[k], Q[k], V[k], *extra(k)) for k in range(t.shape[0])],
                                dtype=float)
    if callable(getattr(controller, "desired", None)):
        if vectorized:
            q_d, v_d, _ = (np.asarray(x, dtype=float) for x in controller.desired(t))
        else:
            ref = [controller.desired(ti) for ti in t]
            q_d = np.array([r[0] for r in ref], dtype=float)
            v_d = np.array([r[1] for r in ref], dtype=float)
    return Trajectory(model=model, t=t, q=Q, v=V, a=A, tau=T, kinetic=kinetic, potential=potential,
                      energy=kinetic + potential, lyapunov=lyapunov, q_desired=q_d, v_desired=v_d,
                      controller_state=Z if law.stateful else None, integrator=integrator, joint_friction=friction,
                      **({} if touch is None else dict(
                          contact_names=touch.names, contact_normal=touch.geometry[..., 1:],
                          contact_friction=touch.friction, contact_force=touch.force,
                          contact_distance=touch.geometry[..., 0],
                          solver_iterations=touch.info[:, CS.ITERATIONS].astype(np.int64),
                          solver_residual=touch.info[:, CS.RESIDUAL])))
