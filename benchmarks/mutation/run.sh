#!/usr/bin/env bash
# Mutation testing of selected pure-Python modules with cosmic-ray; not part of CI.
#
#   pip install -e ".[test]" cosmic-ray      # once, in the virtualenv
#   benchmarks/mutation/run.sh [base log inputs estimation]   # from anywhere in the repo
#
# For each module NAME (default: base log inputs): the unmutated tests of NAME.toml must pass,
# then every mutant is applied to the source file in place, the tests run, and the file is
# restored. Sessions go to $MUTATION_SESSIONS (default /tmp/robodyn-mutation/); an existing
# session is resumed (delete it to start again). Prints the counts and the surviving mutants
# of each module (summary.py).
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
here=benchmarks/mutation
sessions=${MUTATION_SESSIONS:-/tmp/robodyn-mutation}
mkdir -p "$sessions"
if ! git diff --quiet -- src; then
    echo "src/ has uncommitted changes: commit or stash them first (mutants are written into src/)" >&2
    exit 1
fi
module=""
# An interrupted run leaves its mutant in place: put the module back (src/ was clean at the start).
trap '[ -z "$module" ] || git checkout -- "$module"' EXIT
[ $# -gt 0 ] || set -- base log inputs
for name in "$@"; do
    cfg=$here/$name.toml
    db=$sessions/$name.sqlite
    module=$(python -c "import sys, toml; print(toml.load(sys.argv[1])['cosmic-ray']['module-path'])" "$cfg")
    if [ ! -f "$db" ]; then
        cosmic-ray baseline "$cfg"
        cosmic-ray init "$cfg" "$db"
        cr-filter-operators "$db" "$cfg"
        python "$here/skip_compiled.py" "$db"
    fi
    start=$SECONDS
    cosmic-ray exec "$cfg" "$db"
    echo "== $name ($((SECONDS - start)) s)"
    python "$here/summary.py" "$db"
done
