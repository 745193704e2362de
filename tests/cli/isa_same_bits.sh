#!/usr/bin/env bash
# The AVX2 clones of the hot kernels (src/core/clones.h) give the baseline's bits: the scenes of
# tests/cli/isa_bits_scenes.lua (MPM with frictional and no-slip contact, DEM in 2D and 3D, DSMC)
# run by two grainlab binaries on 1 and 2 threads, their final states compared byte for byte,
# thread count by thread count (no-slip MPM's sums follow the fixed thread count: docs/mpm.md).
#   isa_same_bits.sh REFERENCE THIS
# The sanitizer build registers it (tests/CMakeLists.txt, GRAINLAB_BITS_REFERENCE) with THIS
# built without clones (the baseline code) and REFERENCE the plain Release build, whose clones
# run AVX2 on a machine that has it. Exit 0: the two binaries' runs identical; 1: a difference or a failed
# run.
set -u
[ $# -eq 2 ] || { sed -n '2,9p' "$0" >&2; exit 2; }
ref=$(realpath "$1") this=$(realpath "$2")
scenes=$(cd "$(dirname "$0")" && pwd)/isa_bits_scenes.lua
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for exe in "$ref" "$this"; do
  [ -x "$exe" ] || { echo "isa_same_bits.sh: no executable $exe" >&2; exit 1; }
done
# what each binary's kernels run (grainlab --version): the comparison means something only
# between a build with clones and one without
kref=$("$ref" --version | sed -n 's/.*kernels: \(.*\))$/\1/p')
kthis=$("$this" --version | sed -n 's/.*kernels: \(.*\))$/\1/p')
echo "reference: $kref; this build: $kthis"
case "$kref" in *"picked at run time"*) ;; *)
  echo "isa_same_bits.sh: the reference $ref has no clones (kernels: '$kref')" >&2; exit 1 ;; esac
case "$kthis" in *"no clones"*) ;; *)
  echo "isa_same_bits.sh: this build $this has clones (kernels: '$kthis'): configure it with -DGRAINLAB_CLONES=OFF" >&2; exit 1 ;; esac
status=0
for t in 1 2; do
  for side in ref this; do
    exe=$ref
    [ $side = this ] && exe=$this
    (cd "$(dirname "$scenes")" && "$exe" --quiet "$scenes" threads=$t out="$work/$side-$t.txt") ||
      { echo "isa_same_bits.sh: $exe failed on $t thread(s)" >&2; exit 1; }
  done
done
for t in 1 2; do
  if cmp -s "$work/ref-$t.txt" "$work/this-$t.txt"; then
    echo "$t thread(s): the same bits ($(grep -c '^#' "$work/this-$t.txt") scenes, $(wc -l < "$work/this-$t.txt") lines)"
  else
    echo "$t thread(s): DIFFERENT; first differing line and its scene:"
    diff "$work/ref-$t.txt" "$work/this-$t.txt" | head -3
    awk 'NR == FNR { a[FNR] = $0; next } /^#/ { s = $0 } a[FNR] != $0 { print "  " s; exit }' \
      "$work/ref-$t.txt" "$work/this-$t.txt"
    status=1
  fi
done
exit $status
