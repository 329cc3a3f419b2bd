"""``robodyn derive MODEL [--method lagrange|newton_euler] [--latex FILE] [--c DIR] [--form auto|expanded]
[--no-friction]``."""

from __future__ import annotations

import sys
import time

from .common import add_model_arguments, check_output_dir, check_output_file, loaded, save, written
from ..files import write_text


def run_derive(model, args) -> int:
    """Derive the closed-form terms of ``model``, print a summary (the terms themselves for
    up to 3 joints), and write the LaTeX document and the C code when asked (``--form
    auto``: ``M``, ``g``, ``tau`` as the straight-line code of the recursions, ``C``
    expanded; ``--form expanded``: every term expanded; see
    :meth:`.EquationsOfMotion.program`). A model with mimic joints (``--mimic couple``, the
    default) gives the equations of its independent joints (:mod:`robodyn.symbolic.mimic`)."""
    from ..symbolic.equations import equations_of_motion  # imports sympy
    from ..symbolic.mimic import rule_text

    t0 = time.perf_counter()
    eom = equations_of_motion(model, method=args.method, friction=not args.no_friction)
    t1 = time.perf_counter()
    passive = "without" if args.no_friction else "with"
    print(f"robodyn derive {model.name!r}: {eom.n} joints, {args.method.replace('_', '-')} method, "
          f"{passive} the joints' friction and springs (tau_p), derived in {t1 - t0:.2f} s")
    if eom.model.mimic:
        print(f"  mimic joints (not coordinates): {', '.join(rule_text(e) for e in eom.model.mimic)}")
    sizes = {name: sum(len(x) for row in p for x in (row if isinstance(row, list) else [row]))
             if isinstance(p, list) else len(p) for name, p in eom.polynomials.items()}
    print("  terms (monomials): " + ", ".join(f"{k} {sizes[k]}" for k in ("M", "C", "g", "T", "U", "tau")))
    if eom.n <= 3:
        for name in ("M", "C", "g"):
            print(f"  {name} = {eom.term(name).tolist()}")
    if args.latex:
        save(lambda path: write_text(path, eom.latex()), args.latex, "--latex")
        print(f"  LaTeX: {written(args.latex)}")
    if args.c_dir:
        files = save(lambda path: eom.to_c(path, form=args.form), args.c_dir, "--c")
        how = "M, g, tau by the recursions, C expanded" if args.form == "auto" else "every term expanded"
        print(f"  C: {', '.join(f'{written(args.c_dir)}/{k}' for k in files)} ({how})")
    sys.stdout.flush()
    return 0


def cmd_derive(args) -> int:
    check_output_file(args.latex, "--latex")
    check_output_dir(args.c_dir, "--c")
    return run_derive(loaded(args), args)


def add_commands(sub) -> None:
    """Register ``derive`` on the ``robodyn`` subcommand parser."""
    p = sub.add_parser("derive", help="closed-form equations of motion: LaTeX and C code")
    add_model_arguments(p)
    p.add_argument("--method", choices=("lagrange", "newton_euler"), default="lagrange")
    p.add_argument("--latex", metavar="FILE", help="write a LaTeX document of every term")
    p.add_argument("--c", metavar="DIR", dest="c_dir", help="write C source and header into DIR")
    p.add_argument("--form", choices=("auto", "expanded"), default="auto",
                   help="how the C code evaluates the terms: auto (M, g, tau by the recursions, C expanded) "
                        "or expanded (every term expanded)")
    p.add_argument("--no-friction", action="store_true",
                   help="leave the joints' friction and springs (tau_p) out of tau and U, as rnea(friction=False)")
    p.set_defaults(func=cmd_derive)
