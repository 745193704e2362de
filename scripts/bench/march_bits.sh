#!/bin/sh
# The instruction sets against each other: the same bits for the three engines, and the speed of
# each build. Three binaries of this checkout:
#   baseline  portable x86-64 (SSE2) only: -DGRAINLAB_CLONES=OFF, built under OUT
#   default   the given grainlab (the default build: its hot kernels also compiled for AVX2 and
#             picked at run time, src/core/clones.h)
#   march     the whole build for one instruction set: -DGRAINLAB_MARCH=MARCH, built under OUT
# Each runs, on 1 and 2 threads: `steps` steps of the DEM benchmark pile (dem_dense.lua's export,
# made once, or pile=), `cycles` cycles of the MPM shear benchmark from its prepared scene
# (mpm_shear.lua save=, made once), 10 steps of a 10^5-disk DSMC gas. The final states must be
# identical: DEM and DSMC are compared by their particle states written as hex floats (their
# checkpoints carry the runs' wall-clock statistics), MPM by its checkpoint, byte for byte. The
# runs alternate between the builds, `reps` times; the rates are medians.
#   scripts/bench/march_bits.sh [march=x86-64-v3] [grainlab=build/grainlab] [reps=3] [steps=3000]
#                               [cycles=100] [pile=PATH.data] [out=out/march_bits] [report=FILE.json]
# Prints SAME or DIFFERENT per engine, thread count and build, and a Markdown table of the rates;
# report= writes them as the report bench_march_bits (scripts/bench/shell_report.lua). Exits 1 on
# any difference.
set -eu
GRAINLAB_BENCH_START="$(cut -d' ' -f1 /proc/loadavg) $(awk '/^cpu / { print $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9, $9 }' /proc/stat)"
GRAINLAB_BENCH_COMMAND="scripts/bench/march_bits.sh $*"
export GRAINLAB_BENCH_START GRAINLAB_BENCH_COMMAND
MARCH=x86-64-v3 OUT=out/march_bits GL=build/grainlab REPS=3 STEPS=3000 CYCLES=100 PILE= REPORT=
for a in "$@"; do
  case $a in
    march=*) MARCH=${a#march=} ;; out=*) OUT=${a#out=} ;; grainlab=*) GL=${a#grainlab=} ;;
    reps=*) REPS=${a#reps=} ;; steps=*) STEPS=${a#steps=} ;; cycles=*) CYCLES=${a#cycles=} ;;
    pile=*) PILE=${a#pile=} ;; report=*) REPORT=${a#report=} ;;
    *) echo "march_bits.sh: unknown argument '$a' (march=, grainlab=, reps=, steps=, cycles=, pile=, out=, report=)" >&2
       exit 2 ;;
  esac
done
[ -x "$GL" ] || { echo "march_bits.sh: no grainlab at $GL (build first, or grainlab=PATH)" >&2; exit 1; }
SRC=$(pwd)
mkdir -p "$OUT"
for b in baseline march; do
  flag="-DGRAINLAB_CLONES=OFF"
  [ "$b" = baseline ] || flag="-DGRAINLAB_MARCH=$MARCH"
  cmake -S "$SRC" -B "$OUT/build-$b" -DCMAKE_BUILD_TYPE=Release -DGRAINLAB_TESTS=OFF $flag >/dev/null
  cmake --build "$OUT/build-$b" -j2 --target grainlab >/dev/null
done
exe() { case $1 in default) echo "$GL" ;; *) echo "$OUT/build-$1/grainlab" ;; esac; }
if [ -n "$PILE" ]; then
  DATA=$PILE
else
  DATA=$OUT/pile20000.data
  [ -s "$DATA.ckpt" ] || "$OUT/build-baseline/grainlab" scripts/bench/dem_dense.lua n=20000 export="$DATA" >/dev/null
fi
MPMP=$OUT/mpm_prep.ckpt
[ -s "$MPMP" ] || "$OUT/build-baseline/grainlab" scripts/bench/mpm_shear.lua cycles=1 warm=200 threads=1 save="$MPMP" >/dev/null
cat > "$OUT/run.lua" <<'LUA'
-- one build, one thread count: each engine's run, its state written as text (hex floats)
grainlab.threads(tonumber(params.threads))
local function dump(path, cols)
  local f = assert(io.open(path, "w"))
  for i = 1, #cols[1] do
    local row = {}
    for k = 1, #cols do row[k] = string.format("%a", cols[k][i]) end
    f:write(table.concat(row, " "), "\n")
  end
  f:close()
end
local s = dem.load(params.pile)
s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
           tangential = "spring" }
local w0 = grainlab.clock()
s:run{ steps = params.steps, dt = 1e-7, progress = false }
local rate = s:particles().count * params.steps / (grainlab.clock() - w0)
local p = s:particles()
dump(params.out .. ".dem", { p.x, p.y, p.vx, p.vy, p.fx, p.fy })
local m = mpm.load(params.mpm)
w0 = grainlab.clock()
m:run{ steps = params.cycles, dt = 9.6e-6 / 25124, progress = false }
local mrate = m:info().points * params.cycles / (grainlab.clock() - w0)
m:save(params.out .. ".mpm")
local n, R = 100000, 1e-3
local L = math.sqrt(n * math.pi * R * R / 0.003)
local g = dsmc.scene{ dim = 2, size = { L, L }, cells = { 70, 70 }, radius = R, restitution = 0.9, seed = 3 }
g:fill{ n = n, temperature = g:info().mass * 1.0, seed = 5 }
w0 = grainlab.clock()
g:run{ steps = 10, dt = 0.1 / g:measure("temperature").collision_frequency, progress = false }
local drate = n * 10 / (grainlab.clock() - w0)
local q = g:particles()
dump(params.out .. ".dsmc", { q.x, q.y, q.vx, q.vy })
print(string.format("RATES %.6g %.6g %.6g", rate, mrate, drate))
LUA
FIG=$OUT/figures.txt LOG=$OUT/rates.txt
: > "$LOG"
{ echo "param march $MARCH"; echo "param reps $REPS"; echo "param dem_steps $STEPS"
  echo "param mpm_cycles $CYCLES"; echo "param dsmc_steps 10"; } > "$FIG"
echo "metric dem_particles $(awk '$2 == "atoms" { print $1; exit }' "$DATA")" >> "$FIG"
echo "metric dem_contacts_per_particle $("$GL" -e "print(dem.load('$DATA.ckpt'):measure('coordination').z)")" >> "$FIG"
echo "metric mpm_points $("$GL" -e "print(mpm.load('$MPMP'):info().points)")" >> "$FIG"
status=0
for t in 1 2; do
  r=1
  while [ "$r" -le "$REPS" ]; do
    for b in baseline default march; do
      "$(exe $b)" "$OUT/run.lua" threads=$t steps="$STEPS" cycles="$CYCLES" pile="$DATA.ckpt" mpm="$MPMP" \
        out="$OUT/$b-$t" | awk -v b=$b -v t=$t '/^RATES/ { print b, t, $2, $3, $4 }' | tee -a "$LOG"
    done
    r=$((r + 1))
  done
  for e in dem mpm dsmc; do
    for b in default march; do
      if cmp -s "$OUT/baseline-$t.$e" "$OUT/$b-$t.$e"; then same=true; else same=false; status=1; fi
      echo "$e, $t thread(s), $b against baseline: $([ $same = true ] && echo SAME || echo DIFFERENT)"
      echo "check same_bits_${e}_${b}_${t}_threads $same" >> "$FIG"
    done
  done
done
echo
echo "| threads | build | DEM particle-steps/s | MPM point-steps/s | DSMC particle-steps/s |"
echo "|---:|---|---:|---:|---:|"
med() { sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'; }
for t in 1 2; do
  for b in baseline default march; do
    line="| $t | $b"
    for k in 3 4 5; do
      v=$(awk -v b=$b -v t=$t -v k=$k '$1 == b && $2 == t { print $k }' "$LOG" | med)
      e=$(echo dem mpm dsmc | cut -d' ' -f$((k - 2)))
      echo "metric ${e}_rate_${b}_${t}_threads $v" >> "$FIG"
      line="$line | $v"
    done
    echo "$line |"
  done
done
if [ -n "$REPORT" ]; then
  "$GL" --quiet --report "$REPORT" scripts/bench/shell_report.lua scenario=bench_march_bits figures="$FIG" >/dev/null
fi
exit $status
