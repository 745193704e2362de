#!/bin/bash
# Runs tests/dem/mpi_case.lua on 1, 2 and 3 ranks (oversubscribed) and requires what it wrote
# (positions, velocities, spins, forces as %a, energies, stress, wall forces; every rank checks
# that it sees what rank 0 sees) to be the bits of the one-rank run. An optional condition on what the decomposition did (the 3-rank
# run's s:info().distributed: ranks, rebuilds, rebalances, migrations, owned_min, owned_max) makes
# sure the case exercised what it is meant to.
#   mpi_compare.sh GRAINLAB MPIEXEC NAME CONDITION key=value...   (CONDITION "" for none)
set -u
grainlab=$1 mpiexec=$2 name=$3 cond=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
. "$here/mpi_lib.sh"
out=$(mktemp -d "${TMPDIR:-/tmp}/grainlab_mpi_$name.XXXXXX")
trap 'rm -rf "$out"' EXIT
"$grainlab" --quiet "$here/mpi_case.lua" out="$out/np1" "$@" || { echo "FAIL: one rank"; exit 1; }
for np in 2 3; do
  mpi_run "$out/err$np" "$mpiexec" $np "$grainlab" --quiet "$here/mpi_case.lua" out="$out/np$np" "$@" ||
    { echo "FAIL: $np ranks"; exit 1; }
  [ -f "$out/np$np.0" ] || { echo "FAIL: $np ranks wrote nothing"; exit 1; }
  if ! cmp -s "$out/np1.0" "$out/np$np.0"; then
    echo "FAIL: $np ranks differ from one rank:"
    diff "$out/np1.0" "$out/np$np.0" | head -8
    exit 1
  fi
done
lines=$(wc -l < "$out/np1.0")
[ "$lines" -gt 5 ] || { echo "FAIL: only $lines lines compared"; exit 1; }
if [ -n "$cond" ]; then
  cat "$out/np3.stats.0"
  awk -v c="$cond" '{ for (i = 1; i < NF; i += 2) v[$i] = $(i + 1) }
    END { split(c, t, " "); ok = 1
          for (k in t) { if (t[k] ~ /^[a-z_]+(>=|==|>)[0-9]+$/) {
              match(t[k], /(>=|==|>)/); key = substr(t[k], 1, RSTART - 1)
              op = substr(t[k], RSTART, RLENGTH); val = substr(t[k], RSTART + RLENGTH) + 0
              x = v[key] + 0
              if ((op == ">=" && !(x >= val)) || (op == "==" && !(x == val)) ||
                  (op == ">" && !(x > val))) { print "FAIL: " t[k] " (" key " = " x ")"; ok = 0 }
            } else { print "FAIL: bad condition " t[k]; ok = 0 } }
          exit !ok }' "$out/np3.stats.0" || exit 1
fi
echo "OK: $name, $lines lines the same on 1, 2 and 3 ranks"
