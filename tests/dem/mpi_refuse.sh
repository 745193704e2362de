#!/bin/bash
# A scene with a boundary condition (springs) runs on one rank and stops with an error naming it
# on 2 ranks (tests/dem/mpi_refuse.lua checks the message on every rank).
#   mpi_refuse.sh GRAINLAB MPIEXEC
set -u
grainlab=$1 mpiexec=$2
here=$(cd "$(dirname "$0")" && pwd)
. "$here/mpi_lib.sh"
err=$(mktemp)
trap 'rm -f "$err"' EXIT
"$grainlab" --quiet "$here/mpi_refuse.lua" || { echo "FAIL: one rank"; exit 1; }
mpi_run "$err" "$mpiexec" 2 "$grainlab" --quiet "$here/mpi_refuse.lua" || { echo "FAIL: 2 ranks"; exit 1; }
echo "OK"
