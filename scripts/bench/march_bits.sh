#!/bin/sh
# The opt-in instruction set (CMake GRAINLAB_MARCH, issue 16) against the portable build: the same
# bits for the three engines, and the speed of each.
#   scripts/bench/march_bits.sh [march=x86-64-v3] [out=out/march_bits]
# Builds this checkout twice under OUT (portable without the AVX2 clones of src/core/clones.h, and
# -march=MARCH), then with each build and on 1 and 2 threads: 3000 steps of the DEM benchmark pile (scripts/bench/dem_dense.lua's export, made
# once), 20 cycles of the MPM shear benchmark from its prepared scene (mpm_shear.lua save=), 10
# steps of a 10^5-disk DSMC gas; each run ends in a checkpoint. The checkpoints' physics must be
# identical: DEM and DSMC are compared by their particle states written as hex floats (their
# checkpoints carry the runs' wall-clock statistics), MPM by its checkpoint, byte for byte.
# Prints SAME or DIFFERENT per engine and thread count, and the DEM and MPM rates of each build.
# Exits 1 on any difference. Not part of the test suite (it builds twice; ~3 min).
set -eu
MARCH=x86-64-v3 OUT=out/march_bits
for a in "$@"; do
  case $a in
    march=*) MARCH=${a#march=} ;; out=*) OUT=${a#out=} ;;
    *) echo "march_bits.sh: unknown argument '$a' (march=, out=)" >&2; exit 2 ;;
  esac
done
SRC=$(pwd)
mkdir -p "$OUT"
for b in portable "$MARCH"; do
  flag="-DGRAINLAB_CLONES=OFF" # the baseline code only (no AVX2 clones picked at run time)
  [ "$b" = portable ] || flag="-DGRAINLAB_MARCH=$b"
  cmake -S "$SRC" -B "$OUT/build-$b" -DCMAKE_BUILD_TYPE=Release -DGRAINLAB_TESTS=OFF $flag >/dev/null
  cmake --build "$OUT/build-$b" -j2 --target grainlab >/dev/null
done
PILE=$OUT/pile20000.data
[ -s "$PILE.ckpt" ] || "$OUT/build-portable/grainlab" scripts/bench/dem_dense.lua n=20000 export="$PILE" >/dev/null
MPMP=$OUT/mpm_prep.ckpt
[ -s "$MPMP" ] || "$OUT/build-portable/grainlab" scripts/bench/mpm_shear.lua cycles=1 warm=50 threads=1 save="$MPMP" >/dev/null
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
local s = dem.load(params.pile .. ".ckpt")
s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
           tangential = "spring" }
local w0 = grainlab.clock()
s:run{ steps = 3000, dt = 1e-7, progress = false }
local rate = s:particles().count * 3000 / (grainlab.clock() - w0)
local p = s:particles()
dump(params.out .. ".dem", { p.x, p.y, p.vx, p.vy, p.fx, p.fy })
local m = mpm.load(params.mpm)
w0 = grainlab.clock()
m:run{ steps = 20, dt = 9.6e-6 / 25124, progress = false }
local mrate = m:info().points * 20 / (grainlab.clock() - w0)
m:save(params.out .. ".mpm")
local n, R = 100000, 1e-3
local L = math.sqrt(n * math.pi * R * R / 0.003)
local g = dsmc.scene{ dim = 2, size = { L, L }, cells = { 70, 70 }, radius = R, restitution = 0.9, seed = 3 }
g:fill{ n = n, temperature = g:info().mass * 1.0, seed = 5 }
g:run{ steps = 10, dt = 0.1 / g:measure("temperature").collision_frequency, progress = false }
local q = g:particles()
dump(params.out .. ".dsmc", { q.x, q.y, q.vx, q.vy })
print(string.format("RATES dem %.4g mpm %.4g", rate, mrate))
LUA
status=0
for t in 1 2; do
  for b in portable "$MARCH"; do
    r=$("$OUT/build-$b/grainlab" "$OUT/run.lua" threads=$t pile="$PILE" mpm="$MPMP" out="$OUT/$b-$t" | awk '/^RATES/ { print "dem", $3, "mpm", $5 }')
    echo "$b, $t thread(s): particle- and point-steps/s $r"
  done
  for e in dem mpm dsmc; do
    if cmp -s "$OUT/portable-$t.$e" "$OUT/$MARCH-$t.$e"; then echo "$e, $t thread(s): SAME"
    else echo "$e, $t thread(s): DIFFERENT"; status=1; fi
  done
done
exit $status
