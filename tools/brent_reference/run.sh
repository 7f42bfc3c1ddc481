#!/bin/sh
# Reference figures for runtime/tests/data/brent_zero.txt: builds Brent's procedure `zero`
# with the 410 test functions of problems.f90 and prints, per function and step (from 0
# and from 1), the number of evaluations after the two at the ends, their sum and the last
# point.
#
# Usage: tools/brent_reference/run.sh ZERO.f90 > runtime/tests/data/brent_zero.txt
#   ZERO.f90 holds `function zero(a, b, machep, t, f)`, Brent's ALGOL procedure `zero`
#   (R. P. Brent, Algorithms for Minimization without Derivatives, 1973, §4.6) as
#   J. Burkardt's brent.f90 transcribes it (version of 11 February 2013). Needs gfortran.
# Built without optimisation, so that every expression is evaluated as written.
set -eu
zero=${1:?usage: run.sh ZERO.f90}
zero=$(cd "$(dirname "$zero")" && pwd)/$(basename "$zero")
build=$(mktemp -d)
trap 'rm -rf "$build"' EXIT
here=$(cd "$(dirname "$0")" && pwd)
cd "$build"
gfortran -O0 -o problems "$here/problems.f90" "$zero"
./problems
