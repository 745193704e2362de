#!/bin/sh
# Two builds side by side on the same machine: the three engines' benchmarks run by two grainlab
# checkouts, alternating in blocks of four runs (old, new, new, old), each checkout with its own
# bench scripts (the scenes are the same; a newer script may call what an older binary lacks).
# A machine whose speed drifts during a block weighs on both sides alike, so a block's ratio (the
# sum of its two new rates over its two old ones) is steadier than either side's rates.
#   scripts/bench/before_after.sh OLD_CHECKOUT NEW_CHECKOUT [reps=2] [engines=mpm,dem,dsmc]
#                                 [report=FILE.json]
# Each checkout must be built in its build/. Benches (their defaults but shorter runs), each on 1
# and then 2 threads in one process:
#   mpm  : bench/mpm_shear.lua cycles=200 warm=50 (74,047 points, 369 grains, friction)
#   dem  : bench/dem_dense.lua steps=2000 (20,000 disks; the new checkout starts from the pile it
#          exported once, pile=; the old one prepares the same state, bit for bit)
#   dsmc : bench/dsmc_cooling.lua steps=30 (10^6 disks)
# Prints one line per run (engine, threads, side, rate, load) and a Markdown table of medians
# (particle- or point-steps per second) and of the blocks' ratios; report= writes them as the
# report bench_before_after (scripts/bench/shell_report.lua, run by the new checkout).
set -eu
GRAINLAB_BENCH_START="$(cut -d' ' -f1 /proc/loadavg) $(awk '/^cpu / { print $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9, $9 }' /proc/stat)"
GRAINLAB_BENCH_COMMAND="scripts/bench/before_after.sh $*"
export GRAINLAB_BENCH_START GRAINLAB_BENCH_COMMAND
[ $# -ge 2 ] || { echo "usage: before_after.sh OLD_CHECKOUT NEW_CHECKOUT [reps=2] [engines=mpm,dem,dsmc] [report=FILE.json]" >&2; exit 2; }
OLD=$1 NEW=$2
shift 2
REPS=2 ENGINES="mpm dem dsmc" REPORT=
for a in "$@"; do
  case $a in
    reps=*) REPS=${a#reps=} ;;
    engines=*) ENGINES=$(echo "${a#engines=}" | tr ',' ' ') ;;
    report=*) REPORT=${a#report=} ;;
    *) echo "before_after.sh: unknown argument '$a' (reps=, engines=, report=)" >&2; exit 2 ;;
  esac
done
case $REPORT in /* | "") ;; *) REPORT=$(pwd)/$REPORT ;; esac
for d in "$OLD" "$NEW"; do
  [ -x "$d/build/grainlab" ] || { echo "before_after.sh: no $d/build/grainlab" >&2; exit 2; }
done
PILE=$NEW/out/before_after_pile
mkdir -p "$NEW/out"
if [ ! -f "$PILE.ckpt" ] && echo " $ENGINES " | grep -q ' dem '; then
  (cd "$NEW" && build/grainlab scripts/bench/dem_dense.lua n=20000 export="$PILE" >/dev/null 2>&1)
fi
LOG=$(mktemp) FIG=$(mktemp)
{ echo "param old $OLD"; echo "param new $NEW"; echo "param reps $REPS"; echo "param engines $ENGINES"; } > "$FIG"
# run <checkout> <side> <engine>: the bench on 1 and 2 threads in one process (one preparation);
# logs "engine threads side rate load"
run() {
  case $3 in
    mpm) args="scripts/bench/mpm_shear.lua cycles=200 warm=50" ;;
    dem) args="scripts/bench/dem_dense.lua steps=2000"
         # the new side starts from the pile it exported (the old one prepares the same state)
         [ "$2" = new ] && args="$args pile=$PILE.ckpt" ;;
    dsmc) args="scripts/bench/dsmc_cooling.lua steps=30" ;;
  esac
  load=$(cut -d' ' -f1 /proc/loadavg)
  (cd "$1" && build/grainlab $args 2>/dev/null) |
    awk -v e="$3" -v s="$2" -v l="$load" '$1 ~ /^particle_steps_per_s_[0-9]+_threads$/ {
      t = $1; sub(/^particle_steps_per_s_/, "", t); sub(/_threads$/, "", t); print e, t, s, $2, l }' |
    tee -a "$LOG"
}
# Each repetition is a block: old, new, new, old.
for e in $ENGINES; do
  r=1
  while [ "$r" -le "$REPS" ]; do
    run "$OLD" old $e
    run "$NEW" new $e
    run "$NEW" new $e
    run "$OLD" old $e
    r=$((r + 1))
  done
done
echo
echo "| engine | threads | before | after | after / before | blocks' ratios: median (range) |"
echo "|---|---:|---:|---:|---:|---:|"
med() { sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'; }
for e in $ENGINES; do
  for t in 1 2; do
    o=$(awk -v e=$e -v t=$t '$1 == e && $2 == t && $3 == "old" { print $4 }' "$LOG" | med)
    n=$(awk -v e=$e -v t=$t '$1 == e && $2 == t && $3 == "new" { print $4 }' "$LOG" | med)
    # the lines of (e, t) in log order: 4 per block, old new new old
    blocks=$(awk -v e=$e -v t=$t '$1 == e && $2 == t { v[k++] = $4 }
      END { for (b = 0; b + 3 < k; b += 4) printf "%.4f\n", (v[b + 1] + v[b + 2]) / (v[b] + v[b + 3]) }' "$LOG")
    bm=$(echo "$blocks" | med)
    lo=$(echo "$blocks" | sort -g | head -n 1)
    hi=$(echo "$blocks" | sort -g | tail -n 1)
    echo "| $e | $t | $o | $n | $(awk -v o="$o" -v n="$n" 'BEGIN { printf "%.2f", n / o }') | $(printf '%.2f (%.2f-%.2f)' "$bm" "$lo" "$hi") |"
    { echo "metric ${e}_old_${t}_threads $o"; echo "metric ${e}_new_${t}_threads $n"
      echo "metric ${e}_ratio_${t}_threads $bm"; echo "metric ${e}_ratio_min_${t}_threads $lo"
      echo "metric ${e}_ratio_max_${t}_threads $hi"; } >> "$FIG"
  done
done
if [ -n "$REPORT" ]; then
  (cd "$NEW" && build/grainlab --quiet --report "$REPORT" scripts/bench/shell_report.lua \
     scenario=bench_before_after figures="$FIG" >/dev/null)
fi
rm -f "$LOG" "$FIG"
