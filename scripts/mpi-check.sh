#!/usr/bin/env bash
# MPI checks (issue 16), run by .ci/run after the rest; needs OpenMPI (mpirun, mpicc) and libclang.
#   scripts/mpi-check.sh [SERIAL_JPROM]
# SERIAL_JPROM: a jprom built without the `mpi` feature (default: target/debug/jprom as
# `cargo build` left it, copied before the MPI build replaces it); MPI_JPROM (environment): an
# MPI build to use instead of building one.
#  1. `mpirun -np 2` and `-np 3` of `jprom run` (built with --features mpi) on a two-level
#     study (6 units), on a two-case two-level study (12 units, files prefixed with the case)
#     and on the demo study (`jprom demo`'s, 9 units: 3 levels x FO, FR, NLR), and `-np 1` on the
#     first: the same CSV and SVG files as the serial run, byte for byte.
#  2. A unit forced to fail (JPROM_FAIL_UNIT=1:panic, FR at the first level) under -np 3: rank 0
#     reports it in the summary, the job exits non-zero, the other units' CSVs are the serial ones.
#  3. examples-c/mpi_levels.c (the C API from an MPI program) prints the same table with 2
#     ranks as with 1.
set -euo pipefail
cd "$(dirname "$0")/.."
target="${CARGO_TARGET_DIR:-$PWD/target}"
work="$target/mpi-check"
rm -rf "$work" && mkdir -p "$work"
serial="$work/jprom-serial"
cp "${1:-$target/debug/jprom}" "$serial"

# MPI_JPROM: an MPI build of jprom to use instead of building one
if [ -n "${MPI_JPROM:-}" ]; then
    jprom="$MPI_JPROM"
else
    # with the test build's dependency features (dev-dependencies included, which --examples
    # turns on), so that only the crates MPI adds and jprom-cli compile again
    cargo build --workspace --bins --examples --features jprom-cli/mpi
    jprom="$target/debug/jprom"
fi
# --bind-to none: each rank's solvers keep every core's thread, as the serial run's do (with
# mpirun's default binding a rank sees one core, and the solvers' sums, split over one thread
# instead of two, differ in the last bits)
mpirun=(mpirun --oversubscribe --bind-to none)
if [ "$(id -u)" = 0 ]; then mpirun+=(--allow-run-as-root); fi

studies=crates/jprom-cli/tests/studies

# the same files, byte for byte, in two output folders
same_files() {
    local a="$1" b="$2" n=0
    diff <(cd "$a" && ls *.csv *.svg) <(cd "$b" && ls *.csv *.svg)
    for f in "$a"/*.csv "$a"/*.svg; do
        cmp "$f" "$b/$(basename "$f")"
        n=$((n + 1))
    done
    echo "$b: $n CSV and SVG files identical to $a"
}

echo "== serial runs (jprom without MPI)"
"$serial" run "$studies/two_levels.toml" --out "$work/two-serial" --quiet > "$work/two-serial.txt"
"$serial" run "$studies/two_cases.toml" --out "$work/cases-serial" --quiet > "$work/cases-serial.txt"
"$serial" run crates/jprom-cli/demo_study.toml --out "$work/demo-serial" --quiet > "$work/demo-serial.txt"

echo "== mpirun -np 2 and -np 3 (serial runs done at ${SECONDS} s)"
for np in 2 3; do
    timeout 600 "${mpirun[@]}" -np "$np" "$jprom" run "$studies/two_levels.toml" --out "$work/two-np$np" --quiet > "$work/two-np$np.txt"
    same_files "$work/two-serial" "$work/two-np$np"
    # parameter cases: 2 cases x 2 levels x FO, FR, NLR
    timeout 600 "${mpirun[@]}" -np "$np" "$jprom" run "$studies/two_cases.toml" --out "$work/cases-np$np" --quiet > "$work/cases-np$np.txt"
    same_files "$work/cases-serial" "$work/cases-np$np"
    # the demo study (jprom demo): 3 levels x FO, FR, NLR
    timeout 900 "${mpirun[@]}" -np "$np" "$jprom" run crates/jprom-cli/demo_study.toml --out "$work/demo-np$np" --quiet > "$work/demo-np$np.txt"
    same_files "$work/demo-serial" "$work/demo-np$np"
done
# the files of each case are there, prefixed with its name
ls "$work/cases-np3"/base_alpha_ST_x1e-1_fo.csv "$work/cases-np3"/mu0.2_frf_alpha_ST_x1e-1.svg > /dev/null
[ "$(cd "$work/demo-serial" && ls *.csv | wc -l)" -ge 9 ] # 9 sweeps
# a one-rank job is the serial run
timeout 600 "${mpirun[@]}" -np 1 "$jprom" run "$studies/two_levels.toml" --out "$work/two-np1" --quiet > "$work/two-np1.txt"
same_files "$work/two-serial" "$work/two-np1"

echo "== a unit that fails on some rank is reported by rank 0 (at ${SECONDS} s)"
set +e
JPROM_FAIL_UNIT=1:panic timeout 600 "${mpirun[@]}" -x JPROM_FAIL_UNIT -np 3 "$jprom" run "$studies/two_levels.toml" \
    --out "$work/two-fail" > "$work/two-fail.txt" 2> "$work/two-fail.err"
status=$?
set -e
if [ "$status" = 0 ] || [ "$status" = 124 ]; then
    echo "the job with a failing unit exited with $status (expected non-zero, no timeout)"; exit 1
fi
grep "unit 1 (FR at level 3e-1): on rank" "$work/two-fail.txt"
grep -q "forced panic of unit 1" "$work/two-fail.txt"
[ ! -e "$work/two-fail/alpha_ST_x3e-1_fr.csv" ]
for f in "$work/two-serial"/*.csv; do
    name="$(basename "$f")"
    [ "$name" = alpha_ST_x3e-1_fr.csv ] && continue
    cmp "$f" "$work/two-fail/$name"
done
echo "exit status $status, the failing unit reported, the other 5 CSVs identical to the serial run"

echo "== examples-c/mpi_levels.c: the C API from MPI ranks"
lib="$target/debug"
mpicc -Wall -Werror -std=c11 -Iinclude examples-c/mpi_levels.c -L"$lib" -ljprom -Wl,-rpath,"$lib" -lm -o "$work/mpi_levels"
timeout 300 "${mpirun[@]}" -np 1 "$work/mpi_levels" "$work/mpi_levels_files" > "$work/mpi_levels_1.txt"
timeout 300 "${mpirun[@]}" -np 2 "$work/mpi_levels" "$work/mpi_levels_files" > "$work/mpi_levels_2.txt"
cat "$work/mpi_levels_2.txt"
cmp "$work/mpi_levels_1.txt" "$work/mpi_levels_2.txt"
[ "$(grep -vc '^#' "$work/mpi_levels_1.txt")" = 6 ]
echo "mpi_levels: 2 ranks print the same table as 1"
echo "MPI checks passed in ${SECONDS} s"
