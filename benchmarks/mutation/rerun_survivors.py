"""Copy a cosmic-ray session with its surviving mutants made pending again, to run them (and
only them) against changed tests: ``cosmic-ray exec CONFIG NEW_SESSION`` runs the pending ones.

Usage: python benchmarks/mutation/rerun_survivors.py SESSION.sqlite NEW_SESSION.sqlite
"""

from __future__ import annotations

import shutil
import sqlite3
import sys


def main(session: str, new_session: str) -> int:
    shutil.copyfile(session, new_session)
    with sqlite3.connect(new_session) as db:
        n = db.execute("DELETE FROM work_results WHERE worker_outcome = 'NORMAL' AND test_outcome = 'SURVIVED'").rowcount
    print(f"{new_session}: {n} surviving mutants pending again")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
