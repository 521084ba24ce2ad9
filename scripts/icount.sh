#!/usr/bin/env bash
# Instruction counts of the core's hot operations (src/bin/icount.rs) and of the rapier3d world
# step (examples/icount_world.rs) under valgrind's callgrind, compared with the budgets in
# benches/icount-budget.txt (fails when an operation exceeds its budget).
# Usage: bash scripts/icount.sh            check against the budgets
#        bash scripts/icount.sh --print    only print the counts
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || { echo "valgrind is not installed (apt-get install valgrind)" >&2; exit 1; }
# Two builds: the example needs the simulator (a dev-dependency), whose features on the core and
# nalgebra would otherwise be unified into the core harness and change its counts.
cargo build -q --profile icount -p ballbot-benches --bin icount
cargo build -q --profile icount -p ballbot-benches --example icount_world
target=${CARGO_TARGET_DIR:-$PWD/target}
n=2000
count() { # binary operation iterations -> total instructions
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$1" "$2" "$3" 2>&1 \
        | sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
status=0
printf '%-36s %12s %12s\n' operation instructions budget
for bin in "$target/icount/icount" "$target/icount/examples/icount_world"; do
    for op in $("$bin" list); do
        one=$(count "$bin" "$op" "$n"); two=$(count "$bin" "$op" "$((2 * n))")
        per=$(( (two - one) / n ))
        budget=$(awk -v op="$op" '$1 == op { print $2 }' benches/icount-budget.txt)
        printf '%-36s %12s %12s\n' "$op" "$per" "${budget:--}"
        if [ "${1:-}" != "--print" ] && [ -n "$budget" ] && [ "$per" -gt "$budget" ]; then
            echo "  $op: $per instructions per call exceeds its budget $budget" >&2
            status=1
        fi
    done
done
exit $status
