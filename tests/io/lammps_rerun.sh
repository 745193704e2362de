#!/usr/bin/env bash
# docs/io.md's dump example and its LAMMPS `rerun` input, as the page gives them: grainlab writes
# the 2D scene and its frames, LAMMPS reads them back, and its kinetic energy at the last frame is
# the one grainlab printed (LAMMPS prints 8 digits).
# usage: lammps_rerun.sh /abs/path/to/grainlab path/to/lmp path/to/docs/io.md
set -u
G=$1 LMP=$2 DOC=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/out"
# the ```lua block that writes out/fall.dump, and the ```text block that reruns it
awk '/^```lua$/ { b = ""; inb = 1; next } inb && /^```$/ { inb = 0; if (b ~ /out\/fall\.dump/) { printf "%s", b; exit } next }
     inb { b = b $0 "\n" }' "$DOC" >"$tmp/fall.lua"
awk '/^```text$/ { b = ""; inb = 1; next } inb && /^```$/ { inb = 0; if (b ~ /\nrerun /) { printf "%s", b; exit } next }
     inb { b = b $0 "\n" }' "$DOC" >"$tmp/out/rerun.in"
[ -s "$tmp/fall.lua" ] && [ -s "$tmp/out/rerun.in" ] || { echo "FAIL: the example or the input is missing from $DOC"; exit 1; }
(cd "$tmp" && "$G" --quiet fall.lua) >"$tmp/grainlab.txt" 2>&1 || { cat "$tmp/grainlab.txt"; echo "FAIL: the example"; exit 1; }
(cd "$tmp/out" && "$LMP" -in rerun.in -log none) >"$tmp/lammps.txt" 2>&1 || { cat "$tmp/lammps.txt"; echo "FAIL: LAMMPS refused the input"; exit 1; }
ours=$(awk -F'\t' 'NF == 2 { print $2 }' "$tmp/grainlab.txt" | tail -1)
theirs=$(awk '/^Step c_ke/ { on = 1; next } on && $1 == 400 { print $2; exit }' "$tmp/lammps.txt")
echo "grainlab: kinetic energy at step 400 $ours J; LAMMPS rerun: $theirs J"
if [ -n "$ours" ] && [ -n "$theirs" ] && awk -v a="$ours" -v b="$theirs" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a > 0 && d <= 1e-7 * a) }'
then echo "lammps_rerun: ok"; else cat "$tmp/lammps.txt"; echo "FAIL: the energies differ"; exit 1; fi
