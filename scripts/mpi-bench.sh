#!/usr/bin/env bash
# Wall time of a 12-unit study (crates/jprom-cli/tests/studies/four_levels.toml: 4 levels x FO,
# FR, NLR) with 1 and 2 threads (`jprom run --jobs N`) and 1 and 2 MPI ranks (`mpirun -np N`),
# and its serial part (model, Craig-Bampton, level reference: summary.json's build_seconds).
#   scripts/mpi-bench.sh SERIAL_JPROM MPI_JPROM
# SERIAL_JPROM: jprom built without the `mpi` feature; MPI_JPROM: with it
# (`cargo build -p jprom-cli --features mpi --bin jprom`). Every run's CSVs are checked equal
# to the first's.
set -euo pipefail
cd "$(dirname "$0")/.."
serial="$1"
mpi="$2"
study=crates/jprom-cli/tests/studies/four_levels.toml
work="$(mktemp -d)"
mpirun=(mpirun --oversubscribe --bind-to none)
if [ "$(id -u)" = 0 ]; then mpirun+=(--allow-run-as-root); fi

run() { # name, command...
    local name="$1"; shift
    local t0 t1
    t0=$(date +%s.%N)
    "$@" --out "$work/$name" --quiet > "$work/$name.txt"
    t1=$(date +%s.%N)
    local build units
    build=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['build_seconds'])" "$work/$name/summary.json")
    units=$(python3 -c "import json,sys; print(sum(r['sweep_seconds'] for r in json.load(open(sys.argv[1]))['rows']))" "$work/$name/summary.json")
    printf "%-12s wall %7.1f s   serial part (model + CB + level reference) %5.1f s   sum of unit sweep times %6.1f s\n" \
        "$name" "$(echo "$t1 - $t0" | bc)" "$build" "$units"
    if [ "$name" != threads-1 ]; then
        for f in "$work/threads-1"/*.csv; do cmp "$f" "$work/$name/$(basename "$f")"; done
    fi
}

echo "12-unit study ($study), $(nproc) cores"
run threads-1 "$serial" run "$study" --jobs 1
run threads-2 "$serial" run "$study" --jobs 2
run mpi-1 "${mpirun[@]}" -np 1 "$mpi" run "$study"
run mpi-2 "${mpirun[@]}" -np 2 "$mpi" run "$study"
echo "every run's CSVs identical to threads-1's"
rm -rf "$work"
