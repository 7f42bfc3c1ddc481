#!/bin/sh
# Reference figures for runtime/tests/radau5_reference.rs: builds Hairer and Wanner's
# radau5.f with the four cases of problems.f and prints radau5.f's statistics and final
# states.
#
# Usage: tools/radau5_reference/run.sh DIR
#   DIR holds radau5.f, decsol.f and dc_decsol.f as distributed with the book (Hairer's
#   software page, http://www.unige.ch/~hairer/software.html: radau5.f version of July 9,
#   1996, latest small correction January 18, 2002). Needs gfortran.
#
# The figures are the same at -O0, -O2 and -O3 -march=native (gfortran 12).
set -eu
src=${1:?usage: run.sh DIR-with-radau5.f-decsol.f-dc_decsol.f}
here=$(cd "$(dirname "$0")" && pwd)
build=$(mktemp -d)
trap 'rm -rf "$build"' EXIT
gfortran -O2 -std=legacy -o "$build/problems" "$here/problems.f" \
    "$src/radau5.f" "$src/decsol.f" "$src/dc_decsol.f"
"$build/problems"
