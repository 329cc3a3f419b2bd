"""Figures of motions and of the forces behind them (matplotlib, PNG and GIF files).

Every function returns the arrays it draws as a dict (so that they can be checked and
reused) and writes the figure to ``path`` when one is given. matplotlib is imported only when
a figure is drawn (``import robodyn`` does not load it); figures are drawn without pyplot,
so no display or GUI backend is needed.

* :func:`torque_contributions` (no figure) and :func:`plot_torques`: the joint forces of a
  motion split into inertial ``M(q) qdd``, Coriolis/centrifugal ``C(q, qd) qd`` and
  gravitational ``g(q)`` parts and their sum (the classic two-link-arm figure).
* :func:`plot_trajectory`: joint positions (and reference) and tracking errors.
* :func:`plot_energy`: kinetic, potential and total energy, and the controller's Lyapunov function.
* :func:`plot_simulation`: the three panels of a simulation in one figure.
* :func:`animate`: a stick-figure GIF of the robot, planar (2-D) when every point stays in one
  plane, else 3-D.
"""

from __future__ import annotations

import numpy as np


def torque_contributions(model, q, v, a) -> dict:
    """Joint forces of a motion ``(q, v, a)`` (each (N, n)) split by origin, each (N, nv):

    ``inertial = M(q) a`` (armature included), ``coriolis = C(q, v) v``, ``gravity = g(q)``,
    ``total = inertial + coriolis + gravity = rnea(q, v, a)`` without friction.
    """
    from .algorithms.crba import crba
    from .algorithms.rnea import rnea
    from .algorithms.terms import gravity, nonlinear_effects

    q, v, a = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, v, a))
    inertial = np.einsum("nij,nj->ni", crba(model, q), a)
    g = gravity(model, q)
    coriolis = nonlinear_effects(model, q, v) - g
    return dict(inertial=inertial, coriolis=coriolis, gravity=g, total=rnea(model, q, v, a, friction=False))


def _figure(rows: int, cols: int = 1, size=(8.0, 3.0)):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(size[0] * cols, size[1] * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    return fig, axes


def _save(fig, path) -> None:
    if path is not None:
        from .files import atomic_path

        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=100)


def plot_torques(model, t, q, v, a, path=None) -> dict:
    """One panel per joint: inertial, Coriolis/centrifugal, gravity and total joint force
    over time. Returns ``{"t", "inertial", "coriolis", "gravity", "total"}``."""
    data = dict(t=np.asarray(t, dtype=float), **torque_contributions(model, q, v, a))
    nv = model.nv
    cols = 1 if nv <= 3 else 2
    rows = -(-nv // cols)
    fig, axes = _figure(rows, cols, size=(6.0, 2.4))
    labels = model.dof_names
    for k in range(nv):
        ax = axes[k // cols, k % cols]
        for key, style in (("inertial", "-"), ("coriolis", "--"), ("gravity", ":"), ("total", "-")):
            ax.plot(data["t"], data[key][:, k], style, lw=2.0 if key == "total" else 1.2,
                    color="k" if key == "total" else None, label={"coriolis": "Coriolis/centrifugal"}.get(key, key))
        ax.set_title(labels[k], fontsize=9)
        ax.set_ylabel("N m or N")
        ax.grid(alpha=0.3)
    for k in range(nv, rows * cols):
        axes[k // cols, k % cols].set_visible(False)
    axes[0, 0].legend(fontsize=8)
    for c in range(cols):
        axes[rows - 1, c].set_xlabel("t [s]")
    fig.suptitle(f"{model.name}: joint forces M qdd + C qd + g")
    _save(fig, path)
    return data


def _draw_trajectory(ax_q, ax_e, traj) -> dict:
    data = dict(t=traj.t, q=traj.q, q_desired=traj.q_desired, error=traj.tracking_error)
    names = traj.model.q_names
    for k in range(traj.q.shape[1]):
        line, = ax_q.plot(traj.t, traj.q[:, k], label=names[k])
        if traj.q_desired is not None:
            ax_q.plot(traj.t, traj.q_desired[:, k], "--", color=line.get_color(), lw=0.8)
            ax_e.plot(traj.t, traj.tracking_error[:, k], color=line.get_color())
    ax_q.set_ylabel("q" + (" (dashed: reference)" if traj.q_desired is not None else ""))
    ax_q.legend(fontsize=7, ncol=4)
    ax_e.set_ylabel("q - q_desired")
    if traj.q_desired is None:
        ax_e.text(0.5, 0.5, "no reference", ha="center", va="center", transform=ax_e.transAxes)
    for ax in (ax_q, ax_e):
        ax.grid(alpha=0.3)
    ax_e.set_xlabel("t [s]")
    return data


def _draw_energy(ax, traj) -> dict:
    data = dict(t=traj.t, kinetic=traj.kinetic, potential=traj.potential, energy=traj.energy,
                lyapunov=traj.lyapunov)
    ax.plot(traj.t, traj.kinetic, label="kinetic")
    ax.plot(traj.t, traj.potential, label="potential")
    ax.plot(traj.t, traj.energy, "k", label="total")
    ax.set_ylabel("energy [J]")
    ax.set_xlabel("t [s]")
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if traj.lyapunov is not None:  # on its own scale (right axis)
        right = ax.twinx()
        handles += right.plot(traj.t, traj.lyapunov, "r--", label="Lyapunov V (right axis)")
        labels.append("Lyapunov V (right axis)")
        right.set_ylabel("V", color="r")
    ax.legend(handles, labels, fontsize=8)
    return data


def plot_trajectory(traj, path=None) -> dict:
    """Joint positions (reference dashed) and tracking errors of a :class:`Trajectory`.
    Returns ``{"t", "q", "q_desired", "error"}`` (the last two None without reference)."""
    fig, axes = _figure(2)
    data = _draw_trajectory(axes[0, 0], axes[1, 0], traj)
    _save(fig, path)
    return data


def plot_energy(traj, path=None) -> dict:
    """Energies and the Lyapunov function of a :class:`Trajectory` over time.
    Returns ``{"t", "kinetic", "potential", "energy", "lyapunov"}``."""
    fig, axes = _figure(1)
    data = _draw_energy(axes[0, 0], traj)
    _save(fig, path)
    return data


def plot_simulation(traj, path=None) -> dict:
    """Joint positions, tracking errors, applied torques, energies and Lyapunov function in
    one figure. Returns the data of :func:`plot_trajectory` and :func:`plot_energy` and ``tau``."""
    fig, axes = _figure(4)
    data = _draw_trajectory(axes[0, 0], axes[1, 0], traj)
    for k in range(traj.tau.shape[1]):
        axes[2, 0].plot(traj.t, traj.tau[:, k])
    axes[2, 0].set_ylabel("tau applied")
    axes[2, 0].grid(alpha=0.3)
    data.update(_draw_energy(axes[3, 0], traj), tau=traj.tau)
    fig.suptitle(f"{traj.model.name}: simulation ({traj.integrator})")
    _save(fig, path)
    return data


def plot_contacts(traj, path=None) -> dict:
    """The contact forces of a :class:`Trajectory` simulated with contacts: each pair's
    normal force, its friction force, and the share of its friction cone used,
    ``|f_t| / (mu f_n)`` (1: sliding or about to; pairs apart are left blank). Returns
    ``{"t", "names", "normal", "friction", "cone_usage"}``."""
    if traj.contact_force is None:
        raise ValueError("plot_contacts: the trajectory has no contacts (simulate with contacts=...)")
    normal, friction = traj.normal_force, traj.friction_force
    with np.errstate(divide="ignore", invalid="ignore"):
        usage = np.where(normal > 0, friction / (traj.contact_friction * normal), np.nan)
    data = dict(t=traj.t, names=traj.contact_names, normal=normal, friction=friction, cone_usage=usage)
    fig, axes = _figure(3)
    for k, name in enumerate(traj.contact_names):
        axes[0, 0].plot(traj.t, normal[:, k], label=name)
        axes[1, 0].plot(traj.t, friction[:, k])
        axes[2, 0].plot(traj.t, usage[:, k])
    axes[0, 0].plot(traj.t, normal.sum(axis=1), "k--", label="sum")
    axes[0, 0].legend(fontsize=7, ncol=2)
    for ax, label in zip(axes[:, 0], ("normal force [N]", "friction force [N]", "|f_t| / (mu f_n)")):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[2, 0].set_ylim(0.0, 1.05)
    axes[2, 0].set_xlabel("t [s]")
    _save(fig, path)
    return data


def stick_points(model, q) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """World points (N, P, 3) of the stick figure and its segments ``(i, j)``.

    Points: the world origin, every body origin (its joint), every named frame fixed to a
    body (e.g. the tool flange). Segments join each body origin to its parent's (a fixed root
    to the world origin) and each frame to its body.
    """
    from .algorithms.kinematics import forward_kinematics

    T = forward_kinematics(model, np.atleast_2d(np.asarray(q, dtype=float)))
    nb = model.nbodies
    frames = [k for k in range(len(model.frame_names)) if model.frame_body[k] >= 0]
    pts = [np.zeros((T.shape[0], 3)), *(T[:, i, :3, 3] for i in range(nb))]
    from .joints import FREE, PLANAR

    segments = [(0 if model.parent[i] < 0 else model.parent[i] + 1, i + 1) for i in range(nb)  # a floating
                if not (model.parent[i] < 0 and model.joint_type[i] in (FREE, PLANAR))]  # base flies free
    for k in frames:
        b = model.frame_body[k]
        pts.append(T[:, b, :3, 3] + T[:, b, :3, :3] @ model.frame_p[k])
        segments.append((b + 1, len(pts) - 1))
    return np.stack(pts, axis=1), segments


def _surface_outlines(surfaces, mid, half) -> list[np.ndarray]:
    """World polylines (K, 3) outlining each contact surface near ``mid``: a square of side
    ``2 half`` in a plane, the twelve edges of a static box (NaN-separated)."""
    from .builder import rpy_to_matrix
    from .contact.geometry import Plane, StaticBox

    out = []
    for s in surfaces:
        if isinstance(s, Plane):
            n = s.normal
            p0 = mid + (s.height - n @ mid) * n
            a = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
            a /= np.linalg.norm(a)
            b = np.cross(n, a)
            corners = ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))
            out.append(np.array([p0 + half * (i * a + j * b) for i, j in corners]))
        elif isinstance(s, StaticBox):  # (a sphere on a body moves: not drawn)
            R, h = rpy_to_matrix(s.rpy), 0.5 * s.size
            c = [s.center + R @ (h * (2 * np.array(k) - 1)) for k in np.ndindex(2, 2, 2)]
            edges = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
            out.append(np.vstack([np.vstack([c[i], c[j], np.full(3, np.nan)]) for i, j in edges]))
    return out


def animate(model, t, q, path=None, fps: int = 20, planar: bool | None = None, contacts=None) -> dict:
    """Stick-figure animation (GIF written by Pillow, matplotlib's image library) of the
    motion ``q`` (N, nq) at times ``t`` (N,), played in real time at ``fps`` frames per
    second. The axes are drawn once and the robot over them in each frame (blitting).

    ``planar``: draw in 2-D (None: when every point stays in a world coordinate plane).
    ``contacts``: the :class:`robodyn.contact.Contacts` of the simulation: its surfaces are
    drawn (planes as a square or a line, static boxes by their edges) and its contact spheres'
    centres as red dots.
    Returns ``{"t", "points", "segments", "axes", "contact_points"}``: the frame times (F,),
    the drawn points (F, P, 2 or 3), the segments, the names of the drawn world axes, and the
    drawn contact sphere centres (F, C, 2 or 3) or None.
    """
    t = np.asarray(t, dtype=float)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    if t.ndim != 1 or t.shape[0] != q.shape[0] or t.shape[0] < 1:
        raise ValueError(f"t: expected shape ({q.shape[0]},), got {t.shape}")
    if not (isinstance(fps, (int, np.integer)) and fps > 0):
        raise ValueError(f"fps: expected a positive integer, got {fps!r}")
    duration = t[-1] - t[0]
    nframes = max(1, min(t.shape[0], int(duration * fps) + 1))
    sel = np.unique(np.searchsorted(t, t[0] + np.arange(nframes) / fps).clip(0, t.shape[0] - 1))
    pts, segments = stick_points(model, q[sel])
    touch = None
    if contacts is not None:
        from .algorithms.kinematics import forward_kinematics

        (bodies, centers, _), _, _, _ = contacts.pack(model)
        T = forward_kinematics(model, q[sel])
        Tc = T[:, bodies]
        touch = np.einsum("fcij,cj->fci", Tc[..., :3, :3], centers) + Tc[..., :3, 3]
    spread = pts.reshape(-1, 3).max(0) - pts.reshape(-1, 3).min(0)
    flat = np.flatnonzero(spread <= 1e-9 * max(spread.max(), 1e-12))
    if planar is None:
        planar = flat.size >= 1
    names = ("x", "y", "z")
    if planar:
        drop = int(flat[0]) if flat.size else int(np.argmin(spread))
        keep = [k for k in range(3) if k != drop]
        drawn = pts[..., keep]
    else:
        keep = [0, 1, 2]
        drawn = pts
    touch_drawn = None if touch is None else touch[..., keep]
    data = dict(t=t[sel], points=drawn, segments=segments, axes=tuple(names[k] for k in keep),
                contact_points=touch_drawn)
    if path is None:
        return data

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from PIL import Image

    fig = Figure(figsize=(5, 5))
    FigureCanvasAgg(fig)
    lo, hi = drawn.reshape(-1, drawn.shape[-1]).min(0), drawn.reshape(-1, drawn.shape[-1]).max(0)
    outlines = []
    if contacts is not None:  # the surfaces near the robot, and the room to see them
        world = pts.reshape(-1, 3)
        w_mid, w_half = (world.min(0) + world.max(0)) / 2, max((world.max(0) - world.min(0)).max() / 2 * 1.1, 0.1)
        outlines = [o[:, keep] for o in _surface_outlines(contacts.surfaces, w_mid, w_half)]
        below = [o[np.isfinite(o[:, 0])] for o in outlines] or [lo[None], hi[None]]
        lo = np.minimum(lo, np.min([b.min(0) for b in below], axis=0)) if planar else lo
        hi = np.maximum(hi, np.max([b.max(0) for b in below], axis=0)) if planar else hi
        if not planar and outlines:
            lo[2] = min(lo[2], min(b[:, 2].min() for b in below))
    mid, half = (lo + hi) / 2, max((hi - lo).max() / 2 * 1.1, 0.1)
    if planar:
        fig.subplots_adjust(left=0.16, bottom=0.11, right=0.96, top=0.92)
        ax = fig.add_subplot()
        ax.set_aspect("equal")
    else:
        ax = fig.add_subplot(projection="3d")
        ax.set_zlim(mid[2] - half, mid[2] + half)
        ax.set_zlabel(names[keep[2]])
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_xlabel(names[keep[0]])
    ax.set_ylabel(names[keep[1]])
    # every segment in one line, separated by NaN: one artist to draw per frame
    order = np.array([[i, j, i] for i, j in segments], dtype=int).reshape(-1)
    gap = np.zeros(order.shape[0], dtype=bool)
    gap[2::3] = True

    def polyline(f):
        xyz = drawn[f, order].copy()
        xyz[gap] = np.nan
        return xyz

    for o in outlines:
        ax.plot(*o.T, color="0.5", lw=1)
    line, = ax.plot(*polyline(0).T, "o-", color="C0", lw=3, ms=4, animated=True)
    dots = None
    if touch_drawn is not None:
        dots, = ax.plot(*touch_drawn[0].T, "o", color="C3", ms=5, animated=True)
    title = ax.set_title("", animated=True)
    # the axes do not change: draw them once, then only the robot and the time (blitting)
    canvas = fig.canvas
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    frames = []
    for f in range(drawn.shape[0]):
        canvas.restore_region(background)
        xyz = polyline(f)
        line.set_data(xyz[:, 0], xyz[:, 1])
        if not planar:
            line.set_3d_properties(xyz[:, 2])
        title.set_text(f"{model.name}  t = {data['t'][f]:.2f} s")
        if dots is not None:
            dots.set_data(touch_drawn[f, :, 0], touch_drawn[f, :, 1])
            if not planar:
                dots.set_3d_properties(touch_drawn[f, :, 2])
            ax.draw_artist(dots)
        ax.draw_artist(line)
        ax.draw_artist(title)
        w, h = canvas.get_width_height()
        frames.append(Image.frombuffer("RGBA", (w, h), bytes(canvas.buffer_rgba()), "raw", "RGBA", 0, 1).convert(
            "RGB").quantize(colors=64))
    from .files import atomic_path

    with atomic_path(path) as tmp:
        frames[0].save(tmp, save_all=True, append_images=frames[1:], duration=round(1000 / fps), loop=0)
    return data
