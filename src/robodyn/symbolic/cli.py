"""``robodyn derive MODEL [--method lagrange|newton_euler] [--latex FILE] [--c DIR] [--form auto|expanded]``."""

from __future__ import annotations

import sys
import time

from .equations import equations_of_motion


def run_derive(model, args) -> int:
    """Derive the closed-form terms of ``model``, print a summary (the terms themselves for
    up to 3 joints), and write the LaTeX document and the C code when asked (``--form
    auto``: ``M``, ``g``, ``tau`` as the straight-line code of the recursions, ``C``
    expanded; ``--form expanded``: every term expanded; see
    :meth:`.EquationsOfMotion.program`)."""
    t0 = time.perf_counter()
    eom = equations_of_motion(model, method=args.method)
    t1 = time.perf_counter()
    print(f"robodyn derive {model.name!r}: {eom.n} joints, {args.method.replace('_', '-')} method, "
          f"derived in {t1 - t0:.2f} s")
    sizes = {name: sum(len(x) for row in p for x in (row if isinstance(row, list) else [row]))
             if isinstance(p, list) else len(p) for name, p in eom._poly.items()}
    print("  terms (monomials): " + ", ".join(f"{k} {sizes[k]}" for k in ("M", "C", "g", "T", "U", "tau")))
    if eom.n <= 3:
        for name in ("M", "C", "g"):
            print(f"  {name} = {eom.term(name).tolist()}")
    if args.latex:
        with open(args.latex, "w") as f:
            f.write(eom.latex())
        print(f"  LaTeX: {args.latex}")
    if args.c_dir:
        files = eom.to_c(args.c_dir, form=args.form)
        how = "M, g, tau by the recursions, C expanded" if args.form == "auto" else "every term expanded"
        print(f"  C: {', '.join(f'{args.c_dir}/{k}' for k in files)} ({how})")
    sys.stdout.flush()
    return 0
