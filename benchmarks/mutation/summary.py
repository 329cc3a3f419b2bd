"""Counts and surviving mutants of a cosmic-ray session.

Usage: python benchmarks/mutation/summary.py SESSION.sqlite [--diffs]

Prints one line of counts (mutants run, killed, timeouts, survived, incompetent, score =
(killed + timeouts) / run; filtered mutants are not counted), then one line per surviving
mutant: ``job_id line:column operator`` and the mutated source line (with ``--diffs``, the
whole diff).
"""

from __future__ import annotations

import signal
import sys

from cosmic_ray.work_db import WorkDB, use_db
from cosmic_ray.work_item import TestOutcome, WorkerOutcome


def main(session: str, *flags: str) -> int:
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # quietly, into head or less
    counts = dict(run=0, killed=0, timeout=0, survived=0, incompetent=0, skipped=0, pending=0)
    survivors = []
    with use_db(session, WorkDB.Mode.open) as db:
        results = dict(db.results)
        for item in db.work_items:
            r = results.get(item.job_id)
            if r is None:
                counts["pending"] += 1
                continue
            if r.worker_outcome == WorkerOutcome.SKIPPED:
                counts["skipped"] += 1
                continue
            counts["run"] += 1
            if r.worker_outcome != WorkerOutcome.NORMAL or r.test_outcome == TestOutcome.INCOMPETENT:
                counts["incompetent"] += 1
            elif r.test_outcome == TestOutcome.SURVIVED:
                counts["survived"] += 1
                survivors.append((item, r))
            elif r.output == "timeout":
                counts["timeout"] += 1
            else:
                counts["killed"] += 1
    run = counts["run"]
    score = (counts["killed"] + counts["timeout"]) / run if run else float("nan")
    print(" ".join(f"{k}={v}" for k, v in counts.items()) + f" score={score:.1%}")
    for item, r in sorted(survivors, key=lambda s: (str(s[0].mutations[0].module_path), s[0].mutations[0].start_pos)):
        m = item.mutations[0]
        added = [ln[1:].strip() for ln in (r.diff or "").splitlines() if ln.startswith("+") and not ln.startswith("+++")]
        print(f"{item.job_id} {m.module_path}:{m.start_pos[0]}:{m.start_pos[1]} {m.operator_name.removeprefix('core/')}"
              f" #{m.occurrence}: {added[0] if added else ''}")
        if "--diffs" in flags:
            print(r.diff)
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
