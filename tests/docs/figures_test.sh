#!/usr/bin/env bash
# Published figures stay put: reduced runs of the scripts write their figures into out/, never
# into images/. The scripts run in a scratch directory holding a copy of images/; afterwards the
# copy (and the source tree's images/) must be byte for byte what they were, and the figures must
# be in out/. A script whose report checks fail at the reduced size still counts (the report
# was written); one that stops with an error does not.
#   figures_test.sh GRAINLAB SOURCE_DIR
set -euo pipefail
exe=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
sums() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 md5sum | md5sum | cut -d' ' -f1); }

cp -r "$src/images" "$tmp/images"
before=$(sums "$tmp/images")
before_src=$(sums "$src/images")
cd "$tmp"

k=0
run() {  # run SCRIPT [name=value…] -- FIGURE…
  local args=() figs=()
  while [ "$1" != "--" ]; do args+=("$1"); shift; done
  shift
  figs=("$@")
  k=$((k + 1))
  "$exe" --quiet --report "report_$k.json" "$src/scripts/${args[@]}" >"log_$k.txt" 2>&1 || true
  [ -s "report_$k.json" ] || { cat "log_$k.txt" >&2; fail "${args[*]}: no report (the script stopped)"; }
  for f in "${figs[@]}"; do
    [ -s "out/$f" ] || fail "${args[*]}: out/$f not written"
  done
  echo "ok    ${args[*]} -> out/: ${figs[*]}"
}
run mbc_shear_circle.lua n=60 gamma=0.01 -- mbc_shear_circle.png
run haff.lua n=500 -- haff_time.png haff_collisions.png haff_particles.png haff_density.png
run vibrated_bed.lua n=100 settle=0.1 avg=0.1 -- vibrated_bed_density.png vibrated_bed_temperature.png \
    vibrated_bed_density_field.png vibrated_bed_temperature_field.png vibrated_bed_particles.png
run incline.lua quick=true T=0.1 -- incline_cases.png incline_refinement.png
run column_two_scales.lua n=300 -- column_two_scales_profiles.png column_two_scales_front.png \
    column_two_scales_fields.png
run repose_cohesive.lua n=200 bos=0,1 seeds=2 -- repose_cohesive.png
run column_collapse.lua aspects=0.5 model=dp -- column_collapse_runout.png column_collapse_height.png \
    column_collapse_profiles.png column_collapse_front.png

[ "$(sums "$tmp/images")" = "$before" ] || fail "a reduced run changed images/ (in the scratch copy)"
[ "$(sums "$src/images")" = "$before_src" ] || fail "the source tree's images/ changed during the test"
echo "ok    images/ unchanged after $k reduced runs"
