"""The ``simulate`` and ``torques`` commands of the ``robodyn`` command line.

    robodyn simulate MODEL [--controller none|pd-gravity|computed-torque|stand] [--duration 5] [--dt 0.001]
                     [--integrator rk4] [--plot out.png] [--gif out.gif] [--csv out.csv]
                     [--ground [--contacts LINK,...] [--contact-radius 0.02] [--friction 1] [--drop 0.2]
                      [--contact-plot contacts.png]]
    robodyn torques MODEL traj.csv [--plot contributions.png]

``simulate`` starts at rest at ``--q0`` (default: every joint at 0, or mid-range when 0 is
outside its limits; without a controller, 0.5 rad or m from there, since the default pose is
often an equilibrium where nothing would move) and drives the robot to ``--target`` (default:
``q0 + 0.5`` rad or m per joint, kept inside the limits): ``pd-gravity`` regulates to the target, ``computed-torque``
tracks a quintic from ``q0`` to the target in the first half of the run, or the trajectory
of a CSV file given with ``--reference`` (interpolated by a cubic spline). The gains follow
from one natural frequency ``--omega`` (PD gains scaled by the diagonal of the mass matrix,
so that light wrist joints do not make the closed loop too stiff for the fixed step). ``--csv`` writes
the trajectory in robodyn's tabular format (:mod:`robodyn.io.log`), which ``torques``
reads (or any CSV with a ``t`` column and ``q:<joint>`` columns) to plot the joint forces
split into inertial, Coriolis/centrifugal and gravity parts.

``--ground`` drops the robot onto the plane z = 0 (a URDF is loaded with a floating base):
contact spheres at ``--contacts`` (default: the tip of each leaf of the tree, the feet of a
legged robot), the lowest ``--drop`` above the ground, under ``stand`` (joint PD about the
start posture, gains from ``--omega``, the mass matrix's diagonal and the robot's weight
(:func:`standing_inertia`), the base unactuated).
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from .. import models
from ..coupling import expand_q, independent_q, is_coupled, joint_tree
from .common import add_model_arguments, check_output_file, load_model, loaded, save, written

CONTROLLERS = ("none", "pd-gravity", "computed-torque", "stand")


def _vector(text: str | None, n: int, name: str):
    if text is None:
        return None
    try:
        x = np.array([float(s) for s in text.split(",")])
    except ValueError:
        raise ValueError(f"{name}: expected {n} comma-separated numbers, got {text!r}") from None
    if x.shape != (n,):
        raise ValueError(f"{name}: expected {n} comma-separated numbers, got {x.shape[0]}")
    return x


def start_and_target(model, q0=None, target=None):
    """Default start (0, or mid-range outside the limits) and target (``q0 + 0.5`` inside the
    limits) of the 1-dof joints; a floating base starts at the origin, upright (a model with
    mimic joints: the independent coordinates of its tree's start)."""
    from ..joints import FREE, PLANAR, SPHERICAL

    if q0 is None:
        tree = joint_tree(model)
        q0 = np.zeros(tree.nq)
        for i in range(tree.nbodies):
            k, kv = tree.idx_q[i], tree.idx_v[i]
            if tree.joint_type[i] == FREE:
                q0[k + 6] = 1.0
            elif tree.joint_type[i] == SPHERICAL:
                q0[k + 3] = 1.0
            elif tree.joint_type[i] == PLANAR:
                q0[k + 2] = 1.0
            elif not tree.lower[kv] <= 0.0 <= tree.upper[kv]:
                q0[k] = 0.5 * (tree.lower[kv] + tree.upper[kv])
        q0 = independent_q(model, q0)
    if target is None and model.nq == model.nv:
        margin = 0.05 * np.where(np.isfinite(model.upper - model.lower), model.upper - model.lower, 0.0)
        lo, hi = model.lower + margin, model.upper - margin
        target = np.clip(q0 + 0.5, lo, hi)
    return q0, target


def leaf_tips(model) -> list:
    """The tip of each leaf of the kinematic tree: for every body without child bodies, its
    frame farthest from the body's origin (a foot, a fingertip), or the body itself."""
    tips = []
    for b in range(model.nbodies):
        if np.any(model.parent == b):
            continue
        frames = [k for k in range(len(model.frame_names)) if model.frame_body[k] == b]
        far = max(frames, key=lambda k: np.linalg.norm(model.frame_p[k]), default=None)
        tips.append(model.frame_names[far] if far is not None and np.linalg.norm(model.frame_p[far]) > 0
                    else model.link_names[b])
    return tips


def ground_contacts(model, args):
    """The contacts of ``--ground`` on the plane z = 0 with ``--friction`` and ``--restitution``:
    at each of ``--contacts`` (default :func:`leaf_tips`), a URDF's collision spheres, boxes
    and cylinders (as capsules) on that link when it has some, else a sphere of
    ``--contact-radius``."""
    import warnings

    from ..contact import Contacts, Plane, Sphere, shapes_from_urdf
    from ..errors import RobodynWarning

    names = leaf_tips(model) if args.contacts is None else [n.strip() for n in args.contacts.split(",") if n.strip()]
    if not names:
        raise ValueError("--contacts: give at least one link or frame name")
    urdf = []
    if str(args.model).endswith(".urdf"):
        with warnings.catch_warnings():  # a mesh-only link gets the sphere instead
            warnings.simplefilter("ignore", RobodynWarning)
            urdf = shapes_from_urdf(args.model, names, meshes="skip")
    given = {s.body for s in urdf}
    try:
        contacts = Contacts(urdf + [Sphere(n, args.contact_radius) for n in names if n not in given],
                            surfaces=[Plane(friction=args.friction, restitution=args.restitution)])
        contacts.pack(model)  # the names resolve on this model
        return contacts
    except ValueError as e:
        raise ValueError(f"--ground: {e}") from None


def lift(model, q0, contacts, height: float):
    """``q0`` with a root free joint raised or lowered so that the lowest contact sphere is
    ``height`` above the ground (unchanged without a free root)."""
    from ..joints import FREE

    tree = joint_tree(model)  # with mimic joints: lift the tree's configuration, read it back
    roots = [i for i in range(tree.nbodies) if tree.parent[i] < 0 and tree.joint_type[i] == FREE]
    if not roots:
        return q0
    from ..algorithms.kinematics import forward_kinematics

    (body, center, radius), _, _, _ = contacts.pack(model)
    poses = forward_kinematics(model, q0)
    lowest = min(float(poses[b, 2, :3] @ c + poses[b, 2, 3]) - r for b, c, r in zip(body, center, radius))
    q = expand_q(model, q0) if is_coupled(model) else q0.copy()
    for i in roots:
        q[tree.idx_q[i] + 2] += height - lowest
    return independent_q(model, q)


def standing_inertia(model, q0, contacts=None):
    """Per actuated joint, ``(own, load)``: its own inertia ``M_jj(q0)`` and the inertia the
    ``stand`` stiffness is scaled by, ``M_jj`` plus, with contacts, ``m r_j^2`` (``m`` the
    robot's mass, ``r_j`` the distance from the joint to the farthest contact sphere beyond
    it: the whole robot standing on that branch), so that the posture holds the weight
    whatever the limbs' own inertia. ``stand`` uses ``Kp = w^2 load`` and the damping that is
    critical for the limb alone, ``Kd = 2 sqrt(Kp own)`` (an explicit step stays stable
    while ``dt sqrt(Kp / own)`` is small)."""
    from ..algorithms.crba import crba
    from ..algorithms.kinematics import forward_kinematics
    from ..control import JointPD

    actuated = JointPD(model, q0, 1.0, 1.0).actuated
    own = np.diag(crba(model, q0))[actuated]
    inertia = own.copy()
    if contacts is None:
        return own, inertia
    (bodies, centers, _), _, _, _ = contacts.pack(model)
    poses = forward_kinematics(model, q0)
    tips = [(b, poses[b, :3, :3] @ c + poses[b, :3, 3]) for b, c in zip(bodies, centers)]
    tree = joint_tree(model)  # a coupled model's dofs are the tree's independent ones
    tree_dof = np.asarray(getattr(model, "independent_v", np.arange(model.nv)))
    dof_body = {k: i for i in range(tree.nbodies) for k in range(tree.idx_v[i], tree.idx_v[i] + 1)}
    for j, k in enumerate(actuated):
        i = dof_body[int(tree_dof[k])]
        reach = 0.0
        for b, x in tips:
            a = b
            while a >= 0 and a != i:
                a = tree.parent[a]
            if a == i:
                reach = max(reach, float(np.linalg.norm(x - poses[i, :3, 3])))
        inertia[j] += model.total_mass * reach * reach
    return own, inertia


def cmd_simulate(args) -> int:
    from .. import control
    from ..plots import animate, plot_contacts, plot_simulation
    from ..simulation import simulate

    for option in ("csv", "plot", "gif", "contact_plot"):
        check_output_file(getattr(args, option), f"--{option.replace('_', '-')}")
    if args.controller is None:
        args.controller = "stand" if args.ground else "none"
    urdf = args.model not in models.names() and not args.model.lower().endswith((".xml", ".mjcf"))
    model = load_model(args.model, args.floating_base or (args.ground and urdf), args.physical, args.mimic)
    contacts = ground_contacts(model, args) if args.ground else None
    if args.contact_plot and contacts is None:
        raise ValueError("--contact-plot applies to --ground")
    if args.reference and args.controller != "computed-torque":
        raise ValueError("--reference applies to --controller computed-torque")
    q_start = _vector(args.q0, model.nq, "--q0")
    if args.reference and q_start is None:
        from ..io.log import read_trajectory

        q_start = read_trajectory(args.reference, model)[1][0]
    q0, target = start_and_target(model, q_start, _vector(args.target, model.nv, "--target"))
    if args.controller == "none" and contacts is None and q_start is None and model.nq == model.nv:
        q0 = target  # a free run starts 0.5 from the default pose (often an equilibrium), so it moves
    if contacts is not None and q_start is None:
        if not (np.isfinite(args.drop) and args.drop >= 0):
            raise ValueError(f"--drop: must be finite and >= 0, got {args.drop}")
        q0 = lift(model, q0, contacts, args.drop)
    w = args.omega
    if not (np.isfinite(w) and w > 0):
        raise ValueError(f"--omega: must be finite and > 0, got {w}")
    if args.controller == "none":
        controller = None
    elif args.controller == "stand":
        own, load = standing_inertia(model, q0, contacts)
        kp = w * w * load
        controller = control.JointPD(model, q0, kp, 2.0 * np.sqrt(kp * own))
    elif args.controller == "pd-gravity":
        from ..algorithms.crba import crba

        m = np.diag(crba(model, q0)) if model.nq == model.nv else np.ones(model.nv)
        controller = control.PDGravity(model, target, w * w * m, 2.0 * w * m)
    else:
        if model.nq != model.nv:
            raise ValueError("--controller computed-torque needs a fixed-base model")
        if args.reference:
            reference = control.Sampled.from_csv(args.reference, model)
        else:
            reference = control.quintic(q0, target, args.duration / 2)
        controller = control.ComputedTorque(model, reference, w * w, 2.0 * w)
    integrator = args.integrator or ("semi_implicit_euler" if contacts is not None else "rk4")
    traj = simulate(model, q0, np.zeros(model.nv), args.duration, args.dt, controller, integrator, contacts=contacts)
    drift = np.abs(traj.energy - traj.energy[0]).max()
    print(f"robodyn simulate {model.name!r}: {traj.t.shape[0] - 1} steps of {args.dt:g} s ({integrator}), "
          f"controller {args.controller}")
    if contacts is not None:
        fn, ft = traj.normal_force[-1], traj.friction_force[-1]
        touching = fn > 0
        usage = (ft[touching] / (args.friction * fn[touching])).max() if touching.any() and args.friction > 0 else 0.0
        bodies = Counter(n.split(":")[0] for n in traj.contact_names)
        print(f"  contacts: {len(traj.contact_names)} on the ground ("
              + ", ".join(b if k == 1 else f"{b} x{k}" for b, k in bodies.items())
              + f"); at the end {int(touching.sum())} touch, "
              f"normal forces sum to {fn.sum():.6g} N (weight {model.total_mass * 9.81:.6g} N), largest share of "
              f"a friction cone {usage:.3g}; deepest penetration {max(-traj.contact_distance.min(), 0.0):.3g} m; "
              f"largest solver residual {traj.solver_residual.max():.3g} m/s")
    print(f"  energy: start {traj.energy[0]:.6g} J, end {traj.energy[-1]:.6g} J, max |E - E0| {drift:.3g} J")
    if traj.tracking_error is not None:
        error = np.abs(traj.tracking_error)
        print(f"  tracking error: max {error.max():.3g}, final {error[-1].max():.3g}")
    if traj.lyapunov is not None:
        print(f"  Lyapunov function: start {traj.lyapunov[0]:.6g}, end {traj.lyapunov[-1]:.6g}, "
              f"largest increase over a step {max(np.diff(traj.lyapunov).max(), 0.0):.3g}")
    print(f"  applied torques: max |tau| {np.abs(traj.tau).max():.4g}")
    if args.csv:
        save(traj.to_csv, args.csv, "--csv")
        print(f"  wrote {written(args.csv)}")
    if args.plot:
        save(lambda path: plot_simulation(traj, path), args.plot, "--plot")
        print(f"  wrote {written(args.plot)}")
    if args.gif:
        save(lambda path: animate(model, traj.t, traj.q, path, fps=args.fps, contacts=contacts), args.gif, "--gif")
        print(f"  wrote {written(args.gif)}")
    if args.contact_plot:
        save(lambda path: plot_contacts(traj, path), args.contact_plot, "--contact-plot")
        print(f"  wrote {written(args.contact_plot)}")
    return 0


def cmd_torques(args) -> int:
    from ..plots import plot_torques
    from ..io.log import read_trajectory

    check_output_file(args.plot, "--plot")
    model = loaded(args)
    t, q, v, a = read_trajectory(args.trajectory, model)
    data = save(lambda path: plot_torques(model, t, q, v, a, path), args.plot, "--plot")
    print(f"robodyn torques {model.name!r}: {t.shape[0]} samples from {args.trajectory}")
    print(f"  {'joint':<24} {'max|inertial|':>14} {'max|coriolis|':>14} {'max|gravity|':>14} {'max|total|':>14}")
    for k, name in enumerate(model.dof_names):
        vals = [np.abs(data[key][:, k]).max() for key in ("inertial", "coriolis", "gravity", "total")]
        print(f"  {name:<24} " + " ".join(f"{x:14.4g}" for x in vals))
    if args.plot:
        print(f"  wrote {written(args.plot)}")
    return 0


def add_commands(sub) -> None:
    """Register ``simulate`` and ``torques`` on the ``robodyn`` subcommand parser."""
    from ..simulation import INTEGRATORS, SCIPY_INTEGRATORS, SYMPLECTIC

    p = sub.add_parser("simulate", help="simulate the robot, free or under a controller; plots, GIF, CSV")
    add_model_arguments(p)
    p.add_argument("--controller", choices=CONTROLLERS, default=None,
                   help="none (default), pd-gravity, computed-torque, or stand: joint PD about q0 for any robot, "
                        "the floating base unactuated (the default with --ground)")
    p.add_argument("--duration", type=float, default=5.0, help="seconds (default 5)")
    p.add_argument("--dt", type=float, default=1e-3, help="sample time and fixed step, seconds (default 0.001)")
    p.add_argument("--integrator", choices=INTEGRATORS + (SYMPLECTIC,) + SCIPY_INTEGRATORS, default=None,
                   help="rk4 (default), semi_implicit_euler (the default and only one with --ground), symplectic "
                        "(energy bounded over long runs; fixed bases), or SciPy's")
    p.add_argument("--ground", action="store_true",
                   help="drop the robot onto the ground plane z = 0 (a URDF is loaded with a floating base)")
    p.add_argument("--contacts", help="--ground: links or frames touching it, comma-separated (default: the tip "
                                      "of each leaf of the tree, e.g. the feet)")
    p.add_argument("--contact-radius", type=float, default=0.02, help="--ground: radius of the contact spheres, m")
    p.add_argument("--friction", type=float, default=1.0, help="--ground: Coulomb friction coefficient (default 1)")
    p.add_argument("--restitution", type=float, default=0.0, help="--ground: restitution coefficient (default 0)")
    p.add_argument("--drop", type=float, default=0.2,
                   help="--ground: height of the lowest contact above the ground at the start, m (default 0.2)")
    p.add_argument("--contact-plot", help="--ground: PNG of the contact forces and friction cones used")
    p.add_argument("--q0", help="initial configuration, comma-separated (default: see the module doc)")
    p.add_argument("--target", help="target joint positions, comma-separated (default q0 + 0.5)")
    p.add_argument("--reference", help="computed-torque: track this trajectory CSV (t and q:<joint> columns, "
                                       "cubic spline) instead of the quintic; starts at its first sample")
    p.add_argument("--omega", type=float, default=10.0,
                   help="closed-loop natural frequency w, rad/s (default 10), critically damped: computed torque "
                        "Kp = w^2, Kd = 2 w; pd-gravity Kp = w^2 m_jj, Kd = 2 w m_jj with m_jj = diag M(q0)")
    p.add_argument("--plot", help="PNG: joints, tracking errors, torques, energy and Lyapunov function")
    p.add_argument("--gif", help="GIF animation of the robot as a stick figure")
    p.add_argument("--fps", type=int, default=20, help="frames per second of the GIF (default 20)")
    p.add_argument("--csv", help="write the trajectory (t, q, v, a, tau, energy, ...) as CSV")
    p.set_defaults(func=cmd_simulate)
    p = sub.add_parser("torques", help="joint forces of a trajectory split into inertial, Coriolis, gravity")
    add_model_arguments(p)
    p.add_argument("trajectory", help="CSV file with a 't' column and 'q:<joint>' columns (e.g. simulate --csv)")
    p.add_argument("--plot", help="PNG of the contributions per joint")
    p.set_defaults(func=cmd_torques)
