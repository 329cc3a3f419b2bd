"""The ``robodyn excite`` and ``robodyn identify`` commands.

    robodyn excite MODEL --duration 10 --out traj.csv      optimised excitation: CSV + PNG plot
    robodyn identify MODEL data.csv [--method ols|wls|physical] --out identified.urdf --report DIR
                                    [--no-friction] [--stiffness] [--offset]

The data CSV layout is described in :mod:`robodyn.identification.data`.
"""

from __future__ import annotations

from pathlib import Path

from .common import add_model_arguments, check_output_dir, check_output_file, loaded, save, written


def cmd_excite(args) -> int:
    from ..identification.base import base_parameters
    from ..identification.excitation import limits_of, optimize_excitation, write_excitation

    check_output_file(args.out, "--out")
    model = loaded(args)
    base = base_parameters(model, damping=not args.no_friction, coulomb=not args.no_friction,
                           stiffness=args.stiffness)
    period = args.period if args.period is not None else args.duration
    lim = limits_of(model, acceleration=args.acceleration)
    print(f"{model.name}: {base.count} base parameters; optimising {args.harmonics} harmonics over "
          f"{period:g} s ({args.maxiter} iterations at most)")
    result = optimize_excitation(model, base, period=period, harmonics=args.harmonics, samples=args.samples,
                                 limits=lim, maxiter=args.maxiter, seed=args.seed)
    print(f"condition number of the base regressor: {result.initial_condition_number:.4g} (initial) -> "
          f"{result.condition_number:.4g} after {result.iterations} iterations ({result.message})")
    for path in save(lambda out: write_excitation(out, model, result, args.duration, args.rate), args.out, "--out"):
        print(f"wrote {path}")
    return 0


def cmd_identify(args) -> int:
    from ..io.urdf_writer import write_urdf
    from ..identification.base import base_parameters
    from ..identification.data import preprocess, read_log
    from ..identification.identify import identify
    from ..identification.report import write_report

    check_output_file(args.out, "--out")
    check_output_dir(args.report, "--report")
    model = loaded(args)
    log = preprocess(read_log(args.data, model, require_tau=True), cutoff=args.cutoff, decimate=args.decimate)
    base = base_parameters(model, damping=not args.no_friction, coulomb=not args.no_friction,
                           stiffness=args.stiffness, offset=args.offset)
    result = identify(model, log, method=args.method, base=base)
    print(result.summary())
    if args.out:
        save(lambda out: write_urdf(result.identified_model(), out), args.out, "--out")
        print(f"wrote {written(args.out)}")
    if args.report:
        for path in save(lambda out: write_report(result, log, out), args.report, "--report"):
            print(f"wrote {path}")
    return 0


def add_commands(sub) -> None:
    """Register ``excite`` and ``identify`` on the subparsers of ``robodyn``."""
    p = sub.add_parser("excite", help="optimised excitation trajectory for identification (CSV + PNG)")
    add_model_arguments(p)
    p.add_argument("--duration", type=float, default=10.0, help="length of the CSV trajectory (s)")
    p.add_argument("--out", type=Path, required=True, help="CSV file; the plot goes next to it (.png)")
    p.add_argument("--period", type=float, default=None, help="period of the Fourier series (default: duration)")
    p.add_argument("--harmonics", type=int, default=5)
    p.add_argument("--samples", type=int, default=100, help="samples per period in the optimisation")
    p.add_argument("--rate", type=float, default=100.0, help="sampling rate of the CSV (Hz)")
    p.add_argument("--acceleration", type=float, default=10.0, help="acceleration limit (rad/s^2 or m/s^2)")
    p.add_argument("--maxiter", type=int, default=100, help="SLSQP iterations")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--no-friction", action="store_true", help="no viscous/Coulomb friction columns")
    p.add_argument("--stiffness", action="store_true", help="joint spring stiffness columns too")
    p.set_defaults(func=cmd_excite)
    p = sub.add_parser("identify", help="identify inertial parameters and friction from a CSV log")
    add_model_arguments(p)
    p.add_argument("data", type=Path, help="log (CSV, or Parquet for .parquet): t, q:<joint>, [v:<joint>, a:<joint>,] "
                                             "tau:<joint>, as written by simulate --csv")
    p.add_argument("--method", choices=("ols", "wls", "physical"), default="ols")
    p.add_argument("--out", type=Path, help="identified model as URDF")
    p.add_argument("--report", type=Path, help="directory for report.txt and plots")
    p.add_argument("--cutoff", type=float, default=None, help="zero-phase low-pass cutoff (Hz); default none")
    p.add_argument("--decimate", type=int, default=1, help="keep every N-th sample after filtering")
    p.add_argument("--no-friction", action="store_true", help="do not identify viscous/Coulomb friction")
    p.add_argument("--offset", action="store_true", help="identify constant joint torque offsets too "
                                                          "(with --stiffness: the springs' reference positions)")
    p.add_argument("--stiffness", action="store_true",
                   help="identify joint spring stiffness too (URDF has no springs: --out drops them, with a warning)")
    p.set_defaults(func=cmd_identify)
