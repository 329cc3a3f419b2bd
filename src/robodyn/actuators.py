"""Actuators: geared DC motors driven by voltage.

The course model of a voltage-controlled geared motor on joint ``k`` (gear ratio ``N``, motor
angle ``N q``): the winding current ``i`` follows

    L di/dt = V - R i - k_e N v                   (armature circuit, back-EMF of the rotor)

and the joint receives ``tau = eta N k_t i`` (efficiency ``eta``) while the rotor adds its
inertia and friction, reflected through the gear: ``N^2 J_m`` on the joint's armature,
``N^2 B_m`` viscous and ``N F_c`` Coulomb friction. So that ``rnea``, ``aba``, ``crba``,
``simulate`` and identification (armature and friction columns) all see the motors, the
reflected terms go into the model: :meth:`DCMotor.plant` returns it; the electrical part is a
controller with an internal state (the currents), :class:`VoltageDrive`, that
:func:`robodyn.simulate` integrates with the robot::

    motor = actuators.DCMotor(torque_constant=0.05, back_emf=0.05, resistance=1.0,
                              inductance=1e-3, gear_ratio=50.0, rotor_inertia=1e-5)
    plant = motor.plant(model)
    drive = actuators.VoltageDrive(plant, motor, lambda t, q, v: 12.0 * np.ones(plant.nv))
    traj = rd.simulate(plant, q0, v0, 1.0, 1e-3, controller=drive, integrator="Radau")
    traj.controller_state                             # the currents (A)

The electrical time constant ``L / R`` is usually far shorter than the mechanical one: use an
implicit integrator (``"Radau"``) or a step well below ``L / R``. The supply saturates the
command at ``+-max_voltage``. Reference: Spong, Hutchinson & Vidyasagar (2006), section 6.1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .control.controllers import Controller

FIELDS = ("torque_constant", "back_emf", "resistance", "inductance", "gear_ratio", "efficiency", "rotor_inertia",
          "viscous", "coulomb", "max_voltage")


@dataclass(frozen=True)
class DCMotor:
    """A geared DC motor per joint (numbers, or one per dof): ``torque_constant`` ``k_t``
    (N m/A), ``back_emf`` ``k_e`` (V s/rad), ``resistance`` ``R`` (ohm), ``inductance`` ``L``
    (H), ``gear_ratio`` ``N``, ``efficiency`` ``eta`` (0, 1], ``rotor_inertia`` ``J_m``
    (kg m^2), ``viscous`` ``B_m`` (N m s/rad) and ``coulomb`` ``F_c`` (N m) on the rotor side,
    ``max_voltage`` of the supply (V)."""

    torque_constant: float
    back_emf: float
    resistance: float
    inductance: float
    gear_ratio: float = 1.0
    efficiency: float = 1.0
    rotor_inertia: float = 0.0
    viscous: float = 0.0
    coulomb: float = 0.0
    max_voltage: float = np.inf

    def arrays(self, nv: int) -> dict:
        """Every field as an (nv,) array, checked."""
        out = {}
        for name in FIELDS:
            try:
                x = np.broadcast_to(np.asarray(getattr(self, name), dtype=float), (nv,)).copy()
            except (TypeError, ValueError):
                raise ValueError(f"DCMotor.{name}: expected a number or {nv} numbers") from None
            positive = name in ("torque_constant", "back_emf", "resistance", "inductance", "gear_ratio",
                                "efficiency", "max_voltage")
            if np.any(np.isnan(x)) or (np.any(x <= 0) if positive else np.any(x < 0)) or (
                    name != "max_voltage" and not np.all(np.isfinite(x))):
                raise ValueError(f"DCMotor.{name}: expected {'> 0' if positive else '>= 0'} finite values, "
                                 f"got {x.tolist()}")
            out[name] = x
        if np.any(out["efficiency"] > 1):
            raise ValueError(f"DCMotor.efficiency: expected values in (0, 1], got {out['efficiency'].tolist()}")
        return out

    def plant(self, model):
        """``model`` with the rotors reflected through the gears: armature ``+ N^2 J_m``,
        damping ``+ N^2 B_m``, Coulomb friction ``+ N F_c``."""
        m = self.arrays(model.nv)
        N = m["gear_ratio"]
        return model.replace(armature=model.armature + N * N * m["rotor_inertia"],
                             damping=model.damping + N * N * m["viscous"],
                             coulomb=model.coulomb + N * m["coulomb"])


class VoltageDrive(Controller):
    """The motors' electrical dynamics driven by a voltage command (module docstring).

    ``voltage``: a callable ``(t, q, v) -> V`` (nv,) (a voltage-level controller, clipped to
    ``+-max_voltage``). The state is the winding currents (``state0``: ``current0``, default 0);
    the joint torque is ``eta N k_t i``.
    """

    def __init__(self, model, motor: DCMotor, voltage, current0=None):
        super().__init__(model)
        if not callable(voltage):
            raise ValueError(f"voltage: expected a callable (t, q, v) -> (nv,), got {type(voltage).__name__}")
        self.motor, self.voltage = motor, voltage
        self.m = motor.arrays(model.nv)
        self.state0 = np.zeros(model.nv) if current0 is None else np.array(current0, dtype=float).reshape(model.nv)

    def command(self, t, q, v) -> np.ndarray:
        """The supply voltage ``V`` (nv,) after saturation."""
        V = np.asarray(self.voltage(t, q, v), dtype=float)
        return np.clip(V, -self.m["max_voltage"], self.m["max_voltage"])

    def torque(self, t, q, v, z):
        m = self.m
        return m["efficiency"] * m["gear_ratio"] * m["torque_constant"] * z

    def state_rate(self, t, q, v, z):
        m = self.m
        return (self.command(t, q, v) - m["resistance"] * z - m["back_emf"] * m["gear_ratio"] * v) / m["inductance"]


class FlexibleJoints(Controller):
    """Elastic joints (Spong 1987): each joint's motor, of inertia ``B`` (reflected), drives
    its link through a spring of stiffness ``K`` (and damping ``D``):

        M(q) a + C(q, v) v + g(q) = K (theta - q) + D (theta' - v)      (the links: the plant)
        B theta'' + K (theta - q) + D (theta' - v) = u                   (the motors: the state)

    The motor angles and rates ``z = [theta, theta']`` are this controller's state, which
    :func:`robodyn.simulate` integrates with the robot; the torque it applies to the links is
    the spring's. ``u = motor_law(t, q, v, theta, theta')`` is the motor torque (nv,), e.g.
    :func:`motor_pd_gravity`. Large ``K`` makes the system stiff: use an implicit integrator
    (``"Radau"``) or a step well below ``sqrt(B / K)``. Reference: M. W. Spong, "Modeling and
    control of elastic joint robots", J. Dyn. Sys., Meas., Control 109 (1987).

    ``backlash`` ``b`` (rad, per joint, default 0): play in the gears, a dead zone of width
    ``2 b`` in the coupling. The teeth touch only when the twist ``x = theta - q`` leaves it,

        tau = K dz(x) + D (theta' - v) [|x| > b],    dz(x) = x - b sgn(x) if |x| > b else 0,

    so that the motor turns freely through the gap and the springs store ``K dz(x)^2 / 2``
    (Nordin & Gutman, "Controlling mechanical systems with backlash: a survey", Automatica
    38(10), 2002: the dead-zone model).
    """

    def __init__(self, model, stiffness, motor_inertia, motor_law=None, *, damping=0.0, backlash=0.0, theta0=None):
        super().__init__(model)
        nv = model.nv
        self.K = np.broadcast_to(np.asarray(stiffness, dtype=float), (nv,)).copy()
        self.B = np.broadcast_to(np.asarray(motor_inertia, dtype=float), (nv,)).copy()
        self.D = np.broadcast_to(np.asarray(damping, dtype=float), (nv,)).copy()
        self.backlash = np.broadcast_to(np.asarray(backlash, dtype=float), (nv,)).copy()
        for name, x, strict in (("stiffness", self.K, True), ("motor_inertia", self.B, True), ("damping", self.D, False),
                                ("backlash", self.backlash, False)):
            if not np.all(np.isfinite(x)) or (np.any(x <= 0) if strict else np.any(x < 0)):
                raise ValueError(f"{name}: expected finite values {'> 0' if strict else '>= 0'}, got {x.tolist()}")
        if motor_law is not None and not callable(motor_law):
            raise ValueError(f"motor_law: expected a callable (t, q, v, theta, theta_dot) -> u, got {motor_law!r}")
        self.motor_law = motor_law
        theta = np.zeros(nv) if theta0 is None else np.array(theta0, dtype=float).reshape(nv)
        self.state0 = np.concatenate([theta, np.zeros(nv)])

    def twist(self, q, z) -> np.ndarray:
        """``dz(theta - q)`` (nv,): the springs' deflection beyond the backlash gap."""
        x = z[:self.model.nv] - q
        return x - np.clip(x, -self.backlash, self.backlash)

    def spring(self, q, v, z) -> np.ndarray:
        """The joint torque the motors apply to the links, ``K dz(theta - q) + D (theta' - v)``
        (the damping while the teeth touch)."""
        n = self.model.nv
        d = self.twist(q, z)
        touch = (d != 0) | (self.backlash == 0)  # beyond the gap (everywhere without one)
        return self.K * d + self.D * (z[n:] - v) * touch

    def torque(self, t, q, v, z):
        return self.spring(q, v, z)

    def state_rate(self, t, q, v, z):
        n = self.model.nv
        u = np.zeros(n) if self.motor_law is None else np.asarray(self.motor_law(t, q, v, z[:n], z[n:]), dtype=float)
        return np.concatenate([z[n:], (u - self.spring(q, v, z)) / self.B])

    def energy(self, q, v, z) -> float:
        """The motors' kinetic energy and the springs' potential energy (add the links' energy
        for the whole system's)."""
        n = self.model.nv
        return float(0.5 * self.B @ (z[n:] ** 2) + 0.5 * self.K @ (self.twist(q, z) ** 2))


def motor_pd_gravity(model, q_desired, stiffness, kp, kd, backlash=0.0):
    """Tomei's regulator for elastic joints (1991): ``u = Kp (theta_d - theta) - Kd theta' +
    g(q_d)`` with the motor set point ``theta_d = q_d + K^-1 g(q_d)`` (the spring then holds
    the links at ``q_d`` against gravity); globally asymptotically stable for ``Kp`` large
    enough. With gear ``backlash`` ``b`` the set point also crosses the gap on the loaded side,
    ``+ b sgn(g(q_d))``, so that the teeth carry the gravity torque. A motor law for
    :class:`FlexibleJoints`."""
    from .algorithms.terms import gravity

    q_d = np.asarray(q_desired, dtype=float)
    g_d = gravity(model, q_d)
    theta_d = q_d + g_d / np.asarray(stiffness, dtype=float) + np.asarray(backlash, dtype=float) * np.sign(g_d)
    kp, kd = np.asarray(kp, dtype=float), np.asarray(kd, dtype=float)
    return lambda t, q, v, theta, theta_dot: kp * (theta_d - theta) - kd * theta_dot + g_d


def composite_tracking(model, reference, motor_inertia, kp, kd, kv):
    """Singular-perturbation (composite) tracking for elastic joints: ``u = u_s + u_f``.

    The slow law ``u_s`` is computed torque for the rigid robot the elastic one approaches
    as ``K`` grows, the motors' inertia ``B`` on its joints: ``(M(q) + B) q'' + C v + g = u_s``,
    ``u_s = rnea_B(q, v, q_d'' + Kd e' + Kp e)``. The fast law ``u_f = Kv (v - theta')``
    damps the elastic mode, whose variable ``z = K (theta - q)`` otherwise oscillates at
    ``sqrt(K (B^-1 + M^-1))`` without decaying. With ``Kv > 0`` the link error follows the
    rigid error dynamics ``e'' + Kd e' + Kp e = 0`` up to ``O(1 / K)``. A motor law for
    :class:`FlexibleJoints`; ``reference`` as in :class:`robodyn.control.ComputedTorque`.
    Reference: M. W. Spong, K. Khorasani and P. V. Kokotovic, "An integral manifold approach
    to the feedback control of flexible joint robots", IEEE J. Robot. Autom. 3(4), 1987;
    Spong, Hutchinson & Vidyasagar (2006), section 9.4.
    """
    from .control.controllers import ComputedTorque, gain

    B = gain("motor_inertia", motor_inertia, model.nv)
    kv = gain("kv", kv, model.nv)
    slow = ComputedTorque(model.replace(armature=model.armature + B), reference, kp, kd)
    return lambda t, q, v, theta, theta_dot: slow(t, q, v) + kv * (v - theta_dot)


def position_servo(q_desired, kp, kd):
    """A voltage law for :class:`VoltageDrive`: a PD on the motor side, ``V = kp (q_d - q) -
    kd v`` (V/rad, V s/rad), the hobby servo's loop. With gravity the joint settles where the
    motor torque ``eta N k_t V / R`` holds the load: an offset that shrinks as ``kp`` grows."""
    q_d = np.asarray(q_desired, dtype=float)
    kp, kd = np.asarray(kp, dtype=float), np.asarray(kd, dtype=float)
    return lambda t, q, v: kp * (q_d - q) - kd * v
