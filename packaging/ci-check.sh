#!/usr/bin/env bash
# The packaging part of CI (.ci/run calls it; runnable alone):
#
#   packaging/ci-check.sh PREFIX [--profile dev|release]      (default dev: the test build)
#
# installs jprom into PREFIX (outside the repository) with packaging/install.sh, checks the
# install tree's ABI (soname, links, exported symbols = the header's functions, nothing else
# exported), builds the consumer projects of packaging/consumers from a copy outside the
# repository against PREFIX only (CMake: find_package(jprom); Make: pkg-config, shared, static
# and Fortran; CMake Fortran), checks that no compile or link command names the repository and
# that the programs load libjprom from PREFIX, runs them and compares their tables.
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 PREFIX [--profile dev|release]" >&2; exit 2; }
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
mkdir -p "$1"
prefix="$(cd "$1" && pwd)"
shift
profile=dev
if [ $# -ge 2 ] && [ "$1" = --profile ]; then profile="$2"; fi
case "$prefix/" in "$root"/*) echo "PREFIX must be outside the repository ($root)" >&2; exit 2 ;; esac

packaging/install.sh --prefix "$prefix" --profile "$profile"
version="$(sed -n '/^\[workspace.package\]/,/^\[/ s/^version *= *"\([0-9.]*\)".*/\1/p' Cargo.toml)"
major="${version%%.*}"
lib="$prefix/lib"
so="$lib/libjprom.so.$version"

echo "== ABI of the installed library"
readelf -d "$so" | grep "(SONAME) *Library soname: \[libjprom.so.$major\]" >/dev/null ||
    { echo "soname of $so is not libjprom.so.$major:"; readelf -d "$so" | grep SONAME; exit 1; }
[ "$(readlink "$lib/libjprom.so.$major")" = "libjprom.so.$version" ] && [ "$(readlink "$lib/libjprom.so")" = "libjprom.so.$major" ] ||
    { echo "links: $(ls -l "$lib"/libjprom.so*)"; exit 1; }
# every defined dynamic symbol is a jprom_ function: rustc's version script hides the rest
# (Rust std, faer, ...); nothing else is needed on x86_64/aarch64 Linux
leaked="$(nm -D --defined-only "$so" | awk '$3 !~ /^jprom_/ { print $3 }')"
[ -z "$leaked" ] || { echo "symbols other than jprom_* exported:"; echo "$leaked" | head -20; exit 1; }
exported="$(nm -D --defined-only "$so" | awk '$2 == "T" { print $3 }' | sort)"
# the header's functions: names followed by "(" once the preprocessor removed the comments
# and the trailer's macros
declared="$(gcc -E -P -DJPROM_NO_DEPRECATION_WARNINGS "$prefix/include/jprom.h" | grep -oE '\bjprom_[a-z0-9_]+\(' | tr -d '(' | sort -u)"
diff <(echo "$declared") <(echo "$exported") >/dev/null ||
    { echo "header functions (<) vs exported (>):"; diff <(echo "$declared") <(echo "$exported") || true; exit 1; }
[ "$(pkg-config --modversion "$lib/pkgconfig/jprom.pc")" = "$version" ]
echo "soname libjprom.so.$major; $(echo "$exported" | wc -l) symbols exported, all jprom_*, exactly the functions of include/jprom.h"

echo "== consumer projects built against $prefix only"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# a copy of the consumer projects and the example programs they build: nothing below can
# reach into the repository by a relative path
mkdir -p "$work/examples-c" "$work/examples-fortran" "$work/packaging"
cp examples-c/sweep_example.c examples-c/cpp_raii.cpp "$work/examples-c/"
cp examples-fortran/sweep_example.f90 "$work/examples-fortran/"
cp -r packaging/consumers "$work/packaging/"
unset CPATH C_INCLUDE_PATH CPLUS_INCLUDE_PATH LIBRARY_PATH LD_LIBRARY_PATH PKG_CONFIG_LIBDIR
export PKG_CONFIG_PATH="$lib/pkgconfig"
make -C "$work/packaging/consumers/make" >"$work/make.log" 2>&1 || { cat "$work/make.log"; exit 1; }
build="$work/cmake-build"
# (run from $work: nothing of the repository, not even the working directory, reaches CMake)
(cd "$work" && cmake -S packaging/consumers/cmake -B "$build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_EXPORT_COMPILE_COMMANDS=ON && cmake --build "$build" -j 2) >"$work/cmake.log" 2>&1 || { cat "$work/cmake.log"; exit 1; }
if grep -rlF "$root" "$work/make.log" "$build/compile_commands.json" "$build/CMakeFiles" >/dev/null; then
    echo "a consumer's build names the repository $root:"; grep -rF "$root" "$work/make.log" "$build/compile_commands.json" "$build/CMakeFiles" | head; exit 1
fi
m="$work/packaging/consumers/make"
shared=("$m/sweep_example" "$m/sweep_example_f90" "$build/cpp_raii" "$build/sweep_example_f90")
for exe in "${shared[@]}"; do
    ldd "$exe" | grep "libjprom.so.$major => $lib/libjprom.so.$major " >/dev/null ||
        { echo "$exe does not load libjprom from $lib:"; ldd "$exe"; exit 1; }
done
for exe in "$m/sweep_example_static" "$build/sweep_example_static"; do
    if ldd "$exe" | grep libjprom >/dev/null; then echo "$exe is linked to the shared libjprom"; exit 1; fi
done
echo "built: C (pkg-config, shared and --static), Fortran (pkg-config jprom-fortran), C++ and static C and Fortran (CMake find_package); each loads libjprom.so.$major from $lib or has it linked in"

echo "== run the consumers"
out="$work/out"
mkdir -p "$out"
run() { "$1" >"$out/$2.txt" || { echo "$1 failed"; cat "$out/$2.txt"; exit 1; }; }
run "$m/sweep_example" c
run "$m/sweep_example_static" c_static
run "$m/sweep_example_f90" f90
run "$build/cpp_raii" cpp
run "$build/sweep_example_static" c_static_cmake
run "$build/sweep_example_f90" f90_cmake
rows() { grep -v '^#' "$out/$1.txt"; }
for t in c_static cpp c_static_cmake; do
    cmp <(rows c) <(rows $t) || { echo "$t prints another table than the C example"; exit 1; }
done
cmp <(rows f90) <(rows f90_cmake) || { echo "the Fortran example prints another table built by CMake than by Make"; exit 1; }
grep -q "^# jprom $version" "$out/c.txt" || { echo "the C example does not report jprom $version:"; head -1 "$out/c.txt"; exit 1; }
paste <(rows c) <(rows f90) | awk -F'\t' -v a="C (installed)" -v b="Fortran (installed module)" -f packaging/same-table.awk
echo "the C (shared, static), C++ and Fortran consumers print the same table"
"$prefix/bin/jprom" --help | grep demo >/dev/null || { echo "$prefix/bin/jprom --help does not list demo"; exit 1; }
echo "packaging checks passed"
