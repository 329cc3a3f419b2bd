"""Mark as skipped the mutants inside compiled (Numba) functions of a cosmic-ray session.

A function decorated by one of ``robodyn._jit``'s decorators (``inline``, ``kernel``,
``core``, ...) or by ``numba.njit`` is compiled and cached on disk; its callers in other
modules keep their cached machine code when the function's source changes, so a mutant there
is not what the tests run (it would survive for that reason alone). The kernels are covered
by their own tests, not by this mutation run.

Usage: python benchmarks/mutation/skip_compiled.py SESSION.sqlite
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

from cosmic_ray.work_db import WorkDB, use_db
from cosmic_ray.work_item import WorkerOutcome, WorkResult

COMPILED = {"inline", "kernel", "core", "parallel", "splice", "exact", "fast", "njit", "jit"}


def _decorator_name(node: ast.expr) -> str:
    if isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else ""


def compiled_lines(path: Path) -> list[tuple[int, int]]:
    """Line ranges (decorators included) of the compiled functions defined in ``path``."""
    ranges = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and any(
                _decorator_name(d) in COMPILED for d in node.decorator_list):
            ranges.append((min(d.lineno for d in node.decorator_list), node.end_lineno))
    return ranges


def main(session: str) -> int:
    ranges: dict[Path, list[tuple[int, int]]] = {}
    skipped = []
    with use_db(session, WorkDB.Mode.open) as db:
        for item in db.pending_work_items:
            for m in item.mutations:
                path = Path(m.module_path)
                if path not in ranges:
                    ranges[path] = compiled_lines(path)
                if any(lo <= m.start_pos[0] <= hi for lo, hi in ranges[path]):
                    skipped.append(item.job_id)
                    break
        if skipped:
            db.set_multiple_results(skipped, WorkResult(output="Compiled function", worker_outcome=WorkerOutcome.SKIPPED))
    print(f"{session}: {len(skipped)} mutants inside compiled functions skipped")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
