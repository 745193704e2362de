#!/bin/bash
# scripts/bench/table.lua renders docs/performance.md's table and README.md's headline rows from
# the reports of one run, leaves the text around its markers alone, and refuses (writing nothing)
# a set that is incomplete, holds a report twice, mixes runs, or has a failed check.
# The set: tests/bench/reports/*.json (the reports of a quick run of run_all.sh), four of them
# replaced by real runs of their benchmarks at tiny size (so that what the benchmarks write is what
# table.lua reads), the others given this machine's facts; the coarse-graining rows are rendered
# from the stored report and once more from a real tiny run. Everything is written under WORK.
#   table_test.sh GRAINLAB SOURCE_DIR WORK_DIR
set -euo pipefail
GL=$1 SRC=$2 WORK=$3
rm -rf "$WORK"
mkdir -p "$WORK/set"
cd "$SRC"
fail() { echo "FAIL: $*" >&2; exit 1; }

# The run every report of the set belongs to.
export GRAINLAB_BENCH_RUN="table-test $$" GRAINLAB_BENCH_MODE=quick GRAINLAB_BENCH_COMMIT=test
unset GRAINLAB_BENCH_START GRAINLAB_BENCH_COMMAND
"$GL" --quiet --report "$WORK/set/dsmc_cooling.json" scripts/bench/dsmc_cooling.lua n=2000 steps=2 warm=1 >/dev/null
"$GL" --quiet --report "$WORK/set/render.json" scripts/bench/render.lua n=300 width=160 height=90 repeat=1 >/dev/null 2>&1
"$GL" --quiet --report "$WORK/set/largest_dsmc.json" scripts/bench/largest.lua engine=dsmc n=3000 steps=1 >/dev/null
"$GL" --quiet --report "$WORK/set/largest_dem.json" scripts/bench/largest.lua engine=dem n=400 steps=2 >/dev/null
machine=$(jq -c .metrics.machine "$WORK/set/dsmc_cooling.json")
[ "$(jq -r .run <<< "$machine")" = "table-test $$" ] || fail "the benchmark's report does not carry the run id"
[ "$(jq -r .cores <<< "$machine")" -ge 1 ] || fail "the benchmark's report does not carry the cores"
for f in tests/bench/reports/*.json; do
  b=$(basename "$f")
  [ -e "$WORK/set/$b" ] || jq --argjson m "$machine" '.metrics.machine = $m' "$f" > "$WORK/set/$b"
done

# Rendering into copies of the two pages.
cp docs/performance.md "$WORK/performance.md"
cp README.md "$WORK/README.md"
render() { "$GL" --quiet scripts/bench/table.lua dir="$1" page="$WORK/performance.md" readme="$WORK/README.md"; }
render "$WORK/set" > "$WORK/render.log" || fail "a complete set was refused: $(cat "$WORK/render.log")"
between() { awk -v k="$2" '$0 == "<!-- begin: bench " k " -->" { on = 1; next } $0 == "<!-- end: bench " k " -->" { on = 0 } on' "$1"; }
outside() { awk -v k="$2" '$0 == "<!-- begin: bench " k " -->" { on = 1; print; next } $0 == "<!-- end: bench " k " -->" { on = 0 } !on' "$1"; }
page=$(between "$WORK/performance.md" table)
head=$(between "$WORK/README.md" headline)
[ -n "$page" ] && [ -n "$head" ] || fail "nothing rendered between the markers"
cmp -s <(outside docs/performance.md table) <(outside "$WORK/performance.md" table) ||
  fail "the page's text outside the markers changed"
cmp -s <(outside README.md headline) <(outside "$WORK/README.md" headline) ||
  fail "README's text outside the markers changed"
# The tiny DSMC run's figures are on the page: its 2000 disks and its rate, as table.lua writes numbers.
grep -q '| DSMC cooling | 2000 disks, ' <<< "$page" || fail "the DSMC row does not show the tiny run's 2000 disks"
rate=$("$GL" -e "print(string.format('%.2e', $(jq .metrics.particle_steps_per_s_2_threads "$WORK/set/dsmc_cooling.json")))" |
       sed -E 's/e\+0?/·10^/')
mant=${rate%%·*}
grep -q "| particle-steps/s | 2 | ${mant}·10" <<< "$page" || fail "the DSMC rate $rate is not on the page"
# A fixture's figure: the LAMMPS ratio, to 3 digits.
ratio=$(jq .metrics.ratio_1_cores "$WORK/set/vs_lammps.json")
r3=$("$GL" -e "print(string.format('%.3g', $ratio))")
grep -q "| speed, grainlab / LAMMPS | 1 core | $r3 |" <<< "$page" || fail "the LAMMPS ratio $r3 is not on the page"
# The stored coarse-graining report: its scene and the time average's cost, to 3 digits.
grep -q '| Coarse-graining | 99,856 disks, 3.89 contacts per particle, 200 × 200 cells of 1.56 d, w = 2 d |' \
  <<< "$page" || fail "the coarse-graining scene is not on the page"
cost=$("$GL" -e "print(string.format('%.3g', $(jq .metrics.added_per_sample_over_sample "$WORK/set/cg.json")))")
grep -q "time added / the samples' own time | auto | $cost |" <<< "$page" ||
  fail "the time average's cost $cost is not on the page"
# The stored continuum reports: the column's points and the whole collapse's DEM / continuum ratio.
pts=$(jq .metrics.points tests/bench/reports/continuum_large.json)
grep -q "| MPM continuum column, large | $("$GL" -e "print((string.format('%d', $pts):reverse():gsub('(%d%d%d)', '%1,'):reverse():gsub('^,', '')))") points, " \
  <<< "$page" || fail "the large continuum column's $pts points are not on the page"
ratio=$("$GL" -e "print(string.format('%.3g', $(jq .metrics.whole_dem_over_mpm tests/bench/reports/continuum.json)))")
grep -q "| whole collapse, DEM time / continuum time | 1 | $ratio |" <<< "$page" ||
  fail "the whole collapse's DEM / continuum ratio $ratio is not on the page"
# Every headline row of the README is a row of the page (the same figure, threads and value).
while IFS= read -r row; do
  tail=$(awk -F' [|] ' '{ print $3 " | " $4 " | " $5 }' <<< "$row")
  grep -qF "$tail" <<< "$page" || fail "README row not on the page: $row"
done < <(grep '^| ' <<< "$head" | tail -n +3)
[ "$(grep -c '^| ' <<< "$head")" -ge 10 ] || fail "README has fewer than 8 headline rows"
# Rendering again changes nothing.
cp "$WORK/performance.md" "$WORK/page.1"
render "$WORK/set" > /dev/null
cmp -s "$WORK/page.1" "$WORK/performance.md" || fail "a second rendering changed the page"

# Refusals: each must exit non-zero, name the problem, and leave both files as they were.
refused() { # refused NAME MESSAGE: the set in $WORK/$NAME must be refused with MESSAGE
  cp "$WORK/performance.md" "$WORK/page.before"
  cp "$WORK/README.md" "$WORK/readme.before"
  if render "$WORK/$1" > "$WORK/$1.log" 2>&1; then fail "$1: the set was accepted"; fi
  grep -qF "$2" "$WORK/$1.log" || fail "$1: no '$2' in: $(cat "$WORK/$1.log")"
  cmp -s "$WORK/page.before" "$WORK/performance.md" || fail "$1: the page was written"
  cmp -s "$WORK/readme.before" "$WORK/README.md" || fail "$1: README was written"
}
variant() { rm -rf "${WORK:?}/$1"; cp -r "$WORK/set" "$WORK/$1"; }

# cg.lua at tiny size in place of the stored report: its rows from what it writes.
variant cgtiny
"$GL" --quiet --report "$WORK/cgtiny/cg.json" scripts/bench/cg.lua n=900 cells=30 reps=1 steps=10 every=5 >/dev/null
"$GL" --quiet scripts/bench/table.lua dir="$WORK/cgtiny" print=true > "$WORK/cgtiny.txt" ||
  fail "a set with a tiny coarse-graining run was refused: $(cat "$WORK/cgtiny.txt")"
grep -q '| Coarse-graining | 900 disks, [0-9.]* contacts per particle, 30 × 30 cells of ' "$WORK/cgtiny.txt" ||
  fail "the coarse-graining rows do not show the tiny run's 900 disks on 30 × 30 cells"
[ "$(grep -c 'seconds per call (per sample of an average), ' "$WORK/cgtiny.txt")" -eq 4 ] ||
  fail "the coarse-graining rows lack a kernel or a thread count"

variant missing
rm "$WORK/missing/render.json"
refused missing "incomplete: no report of 'bench_render'"
variant twice
cp "$WORK/twice/largest_dem.json" "$WORK/twice/largest_dem_again.json"
refused twice "two reports of 'largest_dem'"
variant mixed
jq '.metrics.machine.run = "another run"' "$WORK/set/mpm_shear.json" > "$WORK/mixed/mpm_shear.json"
refused mixed "the reports mix runs"
variant norun
jq '.metrics.machine.run = ""' "$WORK/set/biaxial.json" > "$WORK/norun/biaxial.json"
refused norun "biaxial.json: no run id"
variant failed
jq '.checks[0].pass = false' "$WORK/set/dem_dense.json" > "$WORK/failed/dem_dense.json"
refused failed "dem_dense.json: check 'pile_quiescent_contacts' failed"
variant stranger
jq '.scenario = "bench_other"' "$WORK/set/render.json" > "$WORK/stranger/other.json"
refused stranger "scenario 'bench_other' is not one of this set"
variant nometric
jq 'del(.metrics.ratio_2_cores)' "$WORK/set/vs_lammps.json" > "$WORK/nometric/vs_lammps.json"
refused nometric "vs_lammps.json has no metric 'ratio_2_cores'"
# A page without its markers: nothing written, README included.
grep -v 'bench table' "$WORK/performance.md" > "$WORK/page.nomarkers"
cp "$WORK/page.nomarkers" "$WORK/performance.md"
cp "$WORK/README.md" "$WORK/readme.before"
if render "$WORK/set" > "$WORK/nomarkers.log" 2>&1; then fail "a page without markers was accepted"; fi
cmp -s "$WORK/readme.before" "$WORK/README.md" || fail "README was written although the page had no markers"
echo "table.lua: rendered a complete set, refused 8 bad ones"
