#!/bin/bash
# A scene with a boundary condition (springs), a wall beyond planes (a circle) or clumps runs on one
# rank and stops with an error naming it on 2 ranks (tests/dem/mpi_refuse.lua checks the message
# on every rank); an instability one rank finds stops every rank with the one-rank message at the
# same step.
#   mpi_refuse.sh GRAINLAB MPIEXEC
set -u
grainlab=$1 mpiexec=$2
here=$(cd "$(dirname "$0")" && pwd)
. "$here/mpi_lib.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$grainlab" --quiet "$here/mpi_refuse.lua" out="$out/np1" || { echo "FAIL: one rank"; exit 1; }
for np in 2 3; do
  mpi_run "$out/err$np" "$mpiexec" $np "$grainlab" --quiet "$here/mpi_refuse.lua" out="$out/np$np" ||
    { echo "FAIL: $np ranks"; exit 1; }
  cmp -s "$out/np1.0" "$out/np$np.0" ||
    { echo "FAIL: $np ranks stopped otherwise:"; diff "$out/np1.0" "$out/np$np.0"; exit 1; }
done
cat "$out/np1.0"
echo "OK"
