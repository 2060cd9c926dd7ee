#!/usr/bin/env bash
# Builds jprom with cargo and installs it as a C library into a prefix (Linux):
#
#   packaging/install.sh --prefix P [--profile release|dev]
#
#   P/lib/libjprom.so.MAJOR.MINOR.PATCH   the shared library, soname libjprom.so.MAJOR
#   P/lib/libjprom.so.MAJOR -> ...        the run-time link (what programs record)
#   P/lib/libjprom.so -> libjprom.so.MAJOR  the link-time (dev) link
#   P/lib/libjprom.a                      the static library
#   P/include/jprom.h                     the C header
#   P/lib/pkgconfig/jprom.pc              pkg-config (static link libraries in Libs.private)
#   P/lib/cmake/jprom/jpromConfig.cmake, jpromConfigVersion.cmake
#                                         find_package(jprom CONFIG): jprom::jprom (shared),
#                                         jprom::jprom_static, jprom::jprom_fortran
#   P/include/jprom/fortran/jprom.f90     the Fortran binding's source (modules jprom, jprom_c)
#   P/include/jprom/fortran/*.mod         ... compiled by the installing Fortran compiler ($FC,
#   P/lib/libjprom_fortran.a              default gfortran), with its object code
#   P/lib/pkgconfig/jprom-fortran.pc      pkg-config for the Fortran layer
#   P/bin/jprom                           the jprom program
#
# Why a script and not cargo-c (`cargo cinstall`), which does most of this: cargo-c is not a
# Cargo subcommand everyone has, compiling it takes longer than jprom itself, and it knows
# nothing of the Fortran module or of CMake packages. This script needs bash, cargo, a C
# toolchain's binutils and, for the Fortran layer, gfortran (or ifx/ifort as $FC).
#
# --profile release (default) builds `cargo build --release -p jprom-capi -p jprom-cli`.
# --profile dev installs the test build: `cargo build --workspace --lib --bins --tests` is the
# command the tests and .ci/run use (same dependency features, so nothing is compiled twice),
# and [profile.dev] is optimised in this workspace.
#
# The version comes from the workspace Cargo.toml. MAJOR is the C ABI's: it changes only when
# the ABI breaks (README, "Upgrading"); every 0.x library is libjprom.so.0.
set -euo pipefail

usage() { echo "usage: $0 --prefix DIR [--profile release|dev]" >&2; exit 2; }
prefix=""
profile="release"
while [ $# -gt 0 ]; do
    case "$1" in
        --prefix) [ $# -ge 2 ] || usage; prefix="$2"; shift 2 ;;
        --prefix=*) prefix="${1#--prefix=}"; shift ;;
        --profile) [ $# -ge 2 ] || usage; profile="$2"; shift 2 ;;
        --profile=*) profile="${1#--profile=}"; shift ;;
        -h|--help) usage ;;
        *) echo "unknown argument: $1" >&2; usage ;;
    esac
done
[ -n "$prefix" ] || usage
case "$profile" in release|dev) ;; *) echo "--profile must be release or dev, not $profile" >&2; exit 2 ;; esac
if [ "$(uname -s)" != Linux ]; then
    echo "install.sh installs the Linux layout (ELF soname, .so links); on $(uname -s) use target/*/ by hand" >&2
    exit 1
fi

root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
mkdir -p "$prefix"
prefix="$(cd "$prefix" && pwd)"   # absolute: it is written into jprom.pc

# the workspace version ([workspace.package] in Cargo.toml)
version="$(sed -n '/^\[workspace.package\]/,/^\[/ s/^version *= *"\([0-9.]*\)".*/\1/p' Cargo.toml)"
IFS=. read -r major minor patch <<<"$version"
[ -n "${major:-}" ] && [ -n "${minor:-}" ] && [ -n "${patch:-}" ] || { echo "no x.y.z version in Cargo.toml" >&2; exit 1; }

echo "== building jprom $version ($profile)"
if [ "$profile" = release ]; then
    cargo build --release -p jprom-capi -p jprom-cli
    dir=release
else
    cargo build --workspace --lib --bins --tests
    dir=debug
fi
target="$(cargo metadata --no-deps --format-version 1 | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')"
built="$target/$dir"
for f in libjprom.so libjprom.a jprom; do
    [ -f "$built/$f" ] || { echo "cargo did not produce $built/$f" >&2; exit 1; }
done

# What a program linking libjprom.a statically needs besides it: the system libraries of
# Rust's std (jprom's dependencies link none of their own). rustc prints them for a staticlib.
probe="$(mktemp -d)"
trap 'rm -rf "$probe"' EXIT
: >"$probe/empty.rs"
static_libs="$(rustc --crate-type staticlib --print native-static-libs -o "$probe/empty.a" "$probe/empty.rs" 2>&1 |
    sed -n 's/.*native-static-libs: //p')"
[ -n "$static_libs" ] || { echo "rustc did not print the native static libraries" >&2; exit 1; }

echo "== installing into $prefix"
lib="$prefix/lib"
mkdir -p "$lib/pkgconfig" "$lib/cmake/jprom" "$prefix/include/jprom/fortran" "$prefix/bin"
real="libjprom.so.$major.$minor.$patch"
install -m 755 "$built/libjprom.so" "$lib/$real"
ln -sfn "$real" "$lib/libjprom.so.$major"
ln -sfn "libjprom.so.$major" "$lib/libjprom.so"
install -m 644 "$built/libjprom.a" "$lib/libjprom.a"
install -m 644 include/jprom.h "$prefix/include/jprom.h"
install -m 755 "$built/jprom" "$prefix/bin/jprom"

subst() {   # template -> file, @VAR@ replaced
    sed -e "s|@PREFIX@|$prefix|g" -e "s|@VERSION@|$version|g" -e "s|@MAJOR@|$major|g" \
        -e "s|@STATIC_LIBS@|$static_libs|g" -e "s|@STATIC_LIBS_CMAKE@|$(sed 's/-l//g; s/ /;/g' <<<"$static_libs")|g" \
        -e "s|@FC_ID@|${fc_id:-}|g" "$1" >"$2"
}

# The Fortran layer: source, modules and object code of the installing compiler ($FC).
fc="${FC:-gfortran}"
fmod="$prefix/include/jprom/fortran"
install -m 644 fortran/jprom.f90 "$fmod/jprom.f90"
rm -f "$fmod"/*.mod "$lib/libjprom_fortran.a" "$lib/pkgconfig/jprom-fortran.pc"
if command -v "$fc" >/dev/null 2>&1; then
    fc_id="$("$fc" --version 2>/dev/null | head -1 | tr -d '|&\\')"   # (written into files by sed below)
    case "$fc_id" in
        *"GNU Fortran"*) modflag=(-J "$fmod") ;;
        *ifort*|*ifx*|*Intel*) modflag=(-module "$fmod") ;;
        *) modflag=() ;;
    esac
    if [ ${#modflag[@]} -gt 0 ]; then
        "$fc" -O2 -fPIC "${modflag[@]}" -c fortran/jprom.f90 -o "$probe/jprom_fortran.o"
        ar rcs "$lib/libjprom_fortran.a" "$probe/jprom_fortran.o"
        chmod 644 "$lib/libjprom_fortran.a" "$fmod"/*.mod
        subst packaging/jprom-fortran.pc.in "$lib/pkgconfig/jprom-fortran.pc"
        echo "Fortran modules compiled by: $fc_id"
    else
        echo "NOTICE: $fc ($fc_id) is neither gfortran nor Intel Fortran; only the source $fmod/jprom.f90 is installed"
    fi
else
    echo "NOTICE: no Fortran compiler ($fc); only the source $fmod/jprom.f90 is installed"
fi

subst packaging/jprom.pc.in "$lib/pkgconfig/jprom.pc"
subst packaging/jpromConfig.cmake.in "$lib/cmake/jprom/jpromConfig.cmake"
subst packaging/jpromConfigVersion.cmake.in "$lib/cmake/jprom/jpromConfigVersion.cmake"
echo "installed jprom $version: $lib/$real (soname libjprom.so.$major), libjprom.a, include/jprom.h, bin/jprom, pkg-config and CMake files"
