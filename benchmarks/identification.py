"""Identification benchmark on the Panda: regressor speed and the whole pipeline end to end.

    python benchmarks/identification.py [--states 10000] [--harmonics 5] [--maxiter 100] [--write]

1. Joint-torque regressor of ``--states`` random Panda states (one batched call; best of 5,
   after a warm-up call), and Pinocchio's ``computeJointTorqueRegressor`` looped over the
   same states when Pinocchio is installed.
2. Base parameters (with viscous and Coulomb friction columns) and their count.
3. Excitation: a Fourier series of ``--harmonics`` harmonics over 10 s optimised for the
   condition number of the base regressor (``--maxiter`` SLSQP iterations).
4. Data: torques by rnea along two periods sampled at 500 Hz (friction: viscous 0.3-0.6,
   Coulomb 0.5-0.9), noise-free and with noise (encoder 1e-4 rad, torque 0.2 N m),
   filtered at 4 Hz, differentiated and decimated by 2.
5. Estimation by OLS, WLS and the physically consistent fit: noise-free recovery error of the
   base parameters (relative, per parameter), RMS torque error on a different (random,
   feasible) trajectory against the noisy torques, and the inertia checks of the physical
   estimate.

``--write`` appends the printed section to ``benchmarks/RESULTS.md``.
"""

from __future__ import annotations

import argparse
import datetime
import platform
import time
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn import identification as ident
from robodyn.model import check_inertial_parameters


def best_of(f, repeat=5):
    f()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--states", type=int, default=10000)
    p.add_argument("--harmonics", type=int, default=5)
    p.add_argument("--maxiter", type=int, default=100)
    p.add_argument("--write", action="store_true", help="append the results to benchmarks/RESULTS.md")
    args = p.parse_args()
    out = []

    def say(line=""):
        print(line, flush=True)
        out.append(line)

    model = rd.models.load("panda")
    truth = model.replace(damping=np.linspace(0.3, 0.6, 7), coulomb=np.linspace(0.5, 0.9, 7))
    rng = np.random.default_rng(0)
    q, v, a = ident.base.random_states(model, args.states, rng)
    t_reg = best_of(lambda: rd.regressor(model, q, v, a))
    say(f"regressor of {args.states} Panda states (one batched call, best of 5): {t_reg:.4f} s "
        f"({t_reg / args.states * 1e6:.2f} us per state)")
    try:
        import pinocchio as pin

        pm = pin.buildModelFromUrdf(str(_panda_urdf())) if _panda_urdf() else None
    except ImportError:
        pm = None
    if pm is not None:
        data = pm.createData()
        n = min(args.states, 2000)
        urdf_model = rd.load_urdf(_panda_urdf(), physical="warn", mimic="independent")  # as Pinocchio reads it
        qp, vp, ap = (rng.standard_normal((n, pm.nv)) for _ in range(3))
        t_pin = best_of(lambda: [pin.computeJointTorqueRegressor(pm, data, qp[i], vp[i], ap[i]) for i in range(n)], 3)
        t_rd = best_of(lambda: rd.regressor(urdf_model, qp, vp, ap), 3)
        say(f"example-robot-data panda.urdf (9 dof, with fingers), {n} states: robodyn batch {t_rd / n * 1e6:.2f} us, "
            f"Pinocchio loop {t_pin / n * 1e6:.2f} us per state")

    t0 = time.perf_counter()
    base = ident.base_parameters(model, damping=True, coulomb=True)
    say(f"base parameters: {base.count - 14} inertial + 14 friction = {base.count} "
        f"(gap {base.gap:.3g}) in {time.perf_counter() - t0:.2f} s")

    t0 = time.perf_counter()
    exc = ident.optimize_excitation(model, base, period=10.0, harmonics=args.harmonics, samples=100,
                                    maxiter=args.maxiter)
    say(f"excitation ({args.harmonics} harmonics, 10 s, {args.maxiter} SLSQP iterations at most): condition number "
        f"{exc.initial_condition_number:.4g} -> {exc.condition_number:.4g} ({exc.iterations} iterations, "
        f"{time.perf_counter() - t0:.1f} s)")

    t, q, qd, qdd = exc.trajectory.sample(20.0, 500.0)
    tau = rd.rnea(truth, q, qd, qdd)
    exact = ident.Log(t, q, qd, qdd, tau)
    sigma_q, sigma_tau = 1e-4, 0.2
    noisy = ident.Log(t, q + sigma_q * rng.standard_normal(q.shape), tau=tau + sigma_tau * rng.standard_normal(tau.shape))
    log = ident.preprocess(noisy, cutoff=4.0, decimate=2)
    other = ident.feasible_trajectory(model, period=8.0, harmonics=3, seed=7)
    t2, q2, qd2, qdd2 = other.sample(16.0, 100.0)
    tau2 = rd.rnea(truth, q2, qd2, qdd2) + sigma_tau * rng.standard_normal((len(t2), 7))
    val = ident.Log(t2, q2, qd2, qdd2, tau2)
    expected = base.project(np.concatenate([truth.inertial_parameters(), truth.damping, truth.coulomb]))
    scale = np.maximum(np.abs(expected), 1e-3 * np.abs(expected).max())
    say(f"data: {len(t)} samples at 500 Hz; noise {sigma_q:g} rad on q, {sigma_tau:g} N m on tau; "
        f"filtered at 4 Hz, decimated by 2 -> {len(log)} samples")
    say("")
    say("  method     noise-free max rel. error   noisy: RMS on another trajectory [N m] (max / mean)   time")
    for method in ("ols", "wls", "physical"):
        r0 = ident.identify(model, exact, method=method, base=base)
        err = np.max(np.abs(r0.estimate.beta - expected) / scale)
        t0 = time.perf_counter()
        r = ident.identify(model, log, method=method, base=base)
        dt = time.perf_counter() - t0
        rms = np.sqrt(np.mean((r.predict(val) - val.tau) ** 2, axis=0))
        say(f"  {method:<9}  {err:25.3g}   {rms.max():.4f} / {rms.mean():.4f} (2 x noise = {2 * sigma_tau:g})"
            f"{'':>20} {dt:.2f} s")
        if method == "physical":
            for i in range(model.nbodies):
                check_inertial_parameters(r.estimate.theta[10 * i:10 * i + 10], f"body {i}")
            say("  physical estimate: every body passes check_inertial_parameters")
    text = "\n".join(out)
    if args.write:
        head = (f"\n## Identification, {datetime.date.today()}, {platform.machine()}, "
                f"Python {platform.python_version()}\n\nCommand: `python benchmarks/identification.py"
                f" --states {args.states} --harmonics {args.harmonics} --maxiter {args.maxiter} --write`\n\n")
        with open(Path(__file__).parent / "RESULTS.md", "a") as fh:
            fh.write(head + "```\n" + text + "\n```\n")


def _panda_urdf():
    import site
    for d in site.getsitepackages():
        p = Path(d) / "cmeel.prefix/share/example-robot-data/robots/panda_description/urdf/panda.urdf"
        if p.is_file():
            return p
    return None


if __name__ == "__main__":
    main()
