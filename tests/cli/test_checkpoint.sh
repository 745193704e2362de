#!/usr/bin/env bash
# DEM checkpoints across processes: run N + M steps in one process, or N, save, and M in a new
# process that loads the file (with 2 threads where the first had 1; these scenes are below the
# 4096 particles at which threads start: test_checkpoint_dem.lua covers that): every position, velocity,
# angular velocity and angle printed with %a must agree, for 2D and 3D and each integrator; the
# same for a file saved from on_step and for Delaunay boundaries rebuilt during the run; a bad
# file stops the script with a clear message.
# usage: test_checkpoint.sh path/to/grainlab   (run from tests/cli)
set -u
G=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*"; }

for dim in 2 3; do
  for integ in velocity_verlet position_verlet gear two_timescales; do
    c="dim=$dim integ=$integ n=300 m=300"
    f="$tmp/$dim-$integ.ckpt"
    "$G" --quiet --threads 1 ckpt_dem.lua mode=full $c >"$tmp/full" || bad "$dim $integ full run"
    "$G" --quiet --threads 1 ckpt_dem.lua mode=save $c file="$f" || bad "$dim $integ save"
    "$G" --quiet --threads 2 ckpt_dem.lua mode=load $c file="$f" >"$tmp/load" || bad "$dim $integ load"
    [ "$(wc -l <"$tmp/full")" -gt 40 ] && ok || bad "$dim $integ: the dump is too short"
    if cmp -s "$tmp/full" "$tmp/load"; then ok; else
      bad "$dim $integ: N + M in one process differs from N, save, load in a new process, M"
      diff "$tmp/full" "$tmp/load" | head -4
    fi
  done
done

# boundary conditions (fixed edges, pressure, penalty with its integral, springs, tie, spin)
c="bnd=true integ=gear n=300 m=300"
f="$tmp/bnd.ckpt"
"$G" --quiet ckpt_dem.lua mode=full $c >"$tmp/full" || bad "boundary full run"
"$G" --quiet ckpt_dem.lua mode=save $c file="$f" || bad "boundary save"
"$G" --quiet ckpt_dem.lua mode=load $c file="$f" >"$tmp/load" || bad "boundary load"
cmp -s "$tmp/full" "$tmp/load" && ok || bad "boundary: N + M differs from N, save, load in a new process, M"

# a Delaunay boundary rebuilt every `every` steps (each variant of ckpt_dem_case.lua: pressure, MBC
# with its integral, lateral sides, ids): the rebuilds after the load, in the new process, give the
# same edges at the same steps (the dump ends with the edges and the count of rebuilds)
for k in 1 2 3 4; do
  f="$tmp/delaunay$k.ckpt"
  "$G" --quiet ckpt_dem.lua mode=full delaunay=$k >"$tmp/full" || bad "Delaunay $k full run"
  "$G" --quiet ckpt_dem.lua mode=save delaunay=$k file="$f" || bad "Delaunay $k save"
  "$G" --quiet --threads 2 ckpt_dem.lua mode=load delaunay=$k file="$f" >"$tmp/load" || bad "Delaunay $k load"
  grep -q "^boundary .* [1-9][0-9]* updates" "$tmp/load" && ok || bad "Delaunay $k: no edges in the dump"
  if cmp -s "$tmp/full" "$tmp/load"; then ok; else
    bad "Delaunay $k: N + M differs from N, save, load in a new process, M"
    diff "$tmp/full" "$tmp/load" | head -4
  fi
done

# saved from on_step, continued in a new process
f="$tmp/onstep.ckpt"
"$G" --quiet ckpt_dem.lua mode=onstep dim=2 integ=gear n=300 m=300 file="$f" >"$tmp/onstep" || bad "onstep run"
"$G" --quiet ckpt_dem.lua mode=full dim=2 integ=gear n=300 m=300 >"$tmp/full" || bad "full run"
"$G" --quiet ckpt_dem.lua mode=load dim=2 integ=gear n=300 m=300 file="$f" >"$tmp/load" || bad "load"
cmp -s "$tmp/full" "$tmp/onstep" && ok || bad "a run that saves from on_step differs from a plain run"
cmp -s "$tmp/full" "$tmp/load" && ok || bad "saved from on_step, continued in a new process: differs"

# a corrupt file: exit status 1, the path and the problem on stderr, nothing on stdout
head -c 1000 "$f" >"$tmp/trunc.ckpt"
"$G" --quiet ckpt_dem.lua mode=load file="$tmp/trunc.ckpt" >"$tmp/out" 2>"$tmp/err"
rc=$?
[ $rc -eq 1 ] && ok || bad "truncated file: exit status $rc, expected 1"
grep -q "load: '$tmp/trunc.ckpt' is truncated or corrupt" "$tmp/err" && ok || { bad "truncated file message"; cat "$tmp/err"; }
[ ! -s "$tmp/out" ] && ok || bad "truncated file: something was printed"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
