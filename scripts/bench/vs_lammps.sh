#!/bin/sh
# grainlab against LAMMPS on the same DEM pile with the same laws: forces compared, then timed.
#
# 1. scripts/bench/dem_dense.lua n=N export=... prepares the benchmark pile (deposition + settle,
#    the same as the benchmark's) and writes it as a LAMMPS data file (atom_style sphere, 2D);
#    pile=PATH.data uses a pile exported before (PATH.data and PATH.data.ckpt).
# 2. Both codes start from that state (grainlab from the checkpoint written with the data file,
#    bit for bit the same; LAMMPS from read_data) with every tangential spring at zero, and the
#    per-particle forces are compared (grainlab: s:particles().fx/fy; LAMMPS: dump fx fy):
#      elastic : one evaluation (LAMMPS run 0; grainlab one step of 1e-20 s). Hertz
#                (hertz/material, E* = E / (2 (1 - nu^2)) in both), the four walls (fix wall/gran,
#                given E / (1 + nu) to undo its E / (2 (1 - nu))), gravity; no damping.
#      damped  : one evaluation, grainlab with one damping time T (the mean pair's) for every pair,
#                LAMMPS damping viscoelastic with eta_n0 = 4/3 E* T / m_ref (m_ref: the mean pair's
#                effective mass). LAMMPS's damping is eta_n0 m* a, grainlab's T 4/3 E* a: they agree
#                only for pairs of effective mass m_ref (no constant eta_n0 matches the per-pair T
#                of Brilliantov-from-restitution either: that T goes as m*^(2/5) R*^(-1/5)).
#      springs : after 100 steps of dt = 1e-7 s, no damping: grainlab's Cundall-Strack spring
#                (kt = 2/7 of the Hertz tangent stiffness = 4/7 E* a) against LAMMPS's
#                `tangential mindlin 4/7 E*` (k_t a, the same stiffness for every contact).
# 3. Timing: the same pile and laws (grainlab: the benchmark's per-pair Brilliantov damping;
#    LAMMPS: viscoelastic at the mean pair; mindlin tangential in both), `steps` steps at
#    dt = 1e-7 s; grainlab on 1 and 2 threads, LAMMPS on 1 and `mpirun -np 2` (its two ranks
#    balanced), the two codes' runs alternated (grainlab, LAMMPS, grainlab, ..., `reps` each), the
#    1-minute load average and the hypervisor's steal time recorded with every run. Contacts per
#    particle count particle-particle contacts only (compute contact/atom ignores wall/gran).
#
#   scripts/bench/vs_lammps.sh [n=20000] [steps=2000] [reps=3] [pile=PATH.data]
#                              [grainlab=build/grainlab] [out=out/vs_lammps] [report=FILE.json]
#
# Needs Debian's LAMMPS (`apt-get install lammps openmpi-bin`). Prints the force comparison and a
# Markdown table of the medians (particle-steps/s, contacts per particle, load, steal); report=
# writes them as the report bench_vs_lammps (scripts/bench/shell_report.lua).
set -eu
GRAINLAB_BENCH_START="$(cut -d' ' -f1 /proc/loadavg) $(awk '/^cpu / { print $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9, $9 }' /proc/stat)"
GRAINLAB_BENCH_COMMAND="scripts/bench/vs_lammps.sh $*"
export GRAINLAB_BENCH_START GRAINLAB_BENCH_COMMAND
N=20000 STEPS=2000 REPS=3 GL=build/grainlab OUT=out/vs_lammps PILE= REPORT=
for a in "$@"; do
  case $a in
    n=*) N=${a#n=} ;; steps=*) STEPS=${a#steps=} ;; reps=*) REPS=${a#reps=} ;;
    grainlab=*) GL=${a#grainlab=} ;; out=*) OUT=${a#out=} ;; pile=*) PILE=${a#pile=} ;;
    report=*) REPORT=${a#report=} ;;
    *) echo "vs_lammps.sh: unknown argument '$a' (n=, steps=, reps=, pile=, grainlab=, out=, report=)" >&2; exit 2 ;;
  esac
done
LMP=$(command -v lmp || command -v lmp_serial || command -v lmp_mpi || true)
if [ -z "$LMP" ]; then
  echo "vs_lammps.sh: LAMMPS not found: apt-get install lammps openmpi-bin" >&2; exit 1
fi
[ -x "$GL" ] || { echo "vs_lammps.sh: no grainlab at $GL (build first, or grainlab=PATH)" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$OUT"
FIG=$OUT/figures.txt
: > "$FIG"
if [ -n "$PILE" ]; then
  DATA=$PILE
  [ -s "$DATA" ] && [ -s "$DATA.ckpt" ] || { echo "vs_lammps.sh: no pile $DATA (and $DATA.ckpt)" >&2; exit 1; }
  N=$(awk '$2 == "atoms" { print $1; exit }' "$DATA")
else
  DATA=$OUT/pile$N.data
  if [ ! -s "$DATA" ] || [ ! -s "$DATA.ckpt" ]; then
    "$GL" scripts/bench/dem_dense.lua n="$N" export="$DATA"
  fi
fi
echo "param n $N" >> "$FIG"; echo "param steps $STEPS" >> "$FIG"; echo "param reps $REPS" >> "$FIG"
echo "metric lammps_version $("$LMP" -h 2>/dev/null | awk -F' - ' '/^Large-scale Atomic/ { print $2 ($3 ? ", " $3 : ""); exit }')" >> "$FIG"

# ---- the grainlab side ------------------------------------------------------------------------
cat > "$OUT/grainlab_side.lua" <<'LUA'
-- mode=forces: one evaluation, forces to a file; mode=time: steps steps on threads threads.
-- The checkpoint holds the data file's state bit for bit, with the box's four walls (which touch
-- the settled pile, so add_wall would refuse them on a fresh read). Switching the tangential law
-- off and on clears the spring histories: LAMMPS starts from zero springs too.
local s = dem.load(params.data .. ".ckpt")
s:contact{ normal = "hertz" }
local dt = 1e-7
if params.mode == "forces" then
  if params.law ~= "damped" then
    s:contact{ normal = "hertz", tangential = "spring" }
  else
    s:contact{ normal = "hertz", damping = "brilliantov", damping_time = params.T, tangential = "spring" }
  end
  if (params.steps or 0) > 0 then -- the tangential springs at work: steps steps at dt
    s:run{ steps = params.steps, dt = dt, progress = false }
  else
    -- one step of 1e-20 s: forces at the file's positions and velocities to round-off (a run of
    -- 0 steps evaluates nothing; the drift and the spring increment are ~1e-20 of the forces)
    s:run{ steps = 1, dt = 1e-20, progress = false }
  end
  local p = s:particles()
  local f = assert(io.open(params.forces, "w"))
  for i = 1, p.count do f:write(string.format("%d %.17g %.17g %.17g\n", i, p.fx[i], p.fy[i], p.mass[i] * 9.81)) end
  f:close()
else
  s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
             tangential = "spring" }
  local function pair_z()
    local c, np = s:measure("contacts"), s:particles().count
    local pairs = 0
    for k = 1, #c.j do pairs = pairs + (c.j[k] > 0 and 1 or 0) end
    return 2 * pairs / np
  end
  local z0 = pair_z()
  grainlab.threads(params.threads)
  local w0 = grainlab.clock()
  s:run{ steps = params.steps, dt = dt, progress = false }
  local wall = grainlab.clock() - w0
  -- contacts per particle between particles only (LAMMPS's compute contact/atom does not count
  -- fix wall/gran's contacts; s:measure("coordination") does)
  print(string.format("RATE %.6g WALL %.4g Z %.4f Z0 %.4f", s:particles().count * params.steps / wall,
                      wall, pair_z(), z0))
end
LUA

# The damping constants: T of the benchmark's mean pair, its effective mass, E* (quartz with quartz).
cat > "$OUT/constants.lua" <<'LUA'
local quartz = grainlab.material{ name = "quartz", density = 2650, young = 30e9, poisson = 0.3,
                                  friction = 0.45, restitution = 0.5 }
local s = dem.load(params.data .. ".ckpt")
s:contact{ normal = "hertz", damping = "brilliantov", restitution = 0.5, impact_velocity = 1,
           tangential = "spring" }
local p = s:particles()
local m, r = 0, 0
for i = 1, p.count do m = m + p.mass[i]; r = r + p.radius[i] end
m, r = m / p.count, r / p.count
local meff = m / 2                                     -- two mean grains
local Estar = 30e9 / (2 * (1 - 0.3 ^ 2))
local K = 4 / 3 * Estar * math.sqrt(r / 2)
local T = 0.698 * (meff / K) ^ 0.4                      -- lambda(0.5) at v = 1 m/s (docs/dem.md)
-- grainlab's kt is 2/7 of the Hertz tangent stiffness, 2/7 * 3/2 * 4/3 E* sqrt(R delta) = 4/7 E* a:
-- LAMMPS's `tangential mindlin k_t` is k_t * a, so k_t = 4/7 E* gives every contact grainlab's kt.
print(string.format("%.17g %.17g %.17g %.17g", T, 4 / 3 * Estar * T / meff, 4 / 7 * Estar, meff))
LUA
set -- $("$GL" "$OUT/constants.lua" data="$DATA")
T=$1 ETA=$2 KT=$3 MEFF=$4
echo "mean pair: T = $T s, m_eff = $MEFF kg -> LAMMPS eta_n0 = $ETA; mindlin k_t = $KT Pa (k_t a = grainlab's kt = 2/7 of the Hertz tangent stiffness)"

# ---- the LAMMPS side -------------------------------------------------------------------------
# fix wall/gran's hertz/material (this LAMMPS, 2021/2022) sets E* = 4/3 E / (2 (1 - nu)), not
# E / (2 (1 - nu^2)) as pair granular does: the wall gets E (1 - nu) / (1 - nu^2) = E / (1 + nu)
# so that its contacts have grainlab's (and pair granular's) E* = E / (2 (1 - nu^2)).
EWALL=$(awk 'BEGIN { printf "%.17g", 30e9 / 1.3 }')
lammps_input() { # $1 = eta_n0, $2 = damping model, $3 = run line(s), $4 = a line after read_data
  cat <<LMPIN
units           si
atom_style      sphere
dimension       2
boundary        f f p
newton          off
comm_modify     vel yes
read_data       $DATA
${4:-}
neighbor        0.0001 bin
neigh_modify    delay 0 every 1 check yes
pair_style      granular
pair_coeff      * * hertz/material 30e9 $1 0.3 damping $2 tangential mindlin $KT 0 0.45
fix             integrate all nve/sphere
fix             gravity all gravity 9.81 vector 0 -1 0
fix             xwalls all wall/gran granular hertz/material $EWALL $1 0.3 damping $2 tangential mindlin $KT 0 0.45 xplane 0 0.25
fix             ywalls all wall/gran granular hertz/material $EWALL $1 0.3 damping $2 tangential mindlin $KT 0 0.45 yplane 0 0.3
fix             flat all enforce2d
compute         z all contact/atom
compute         zsum all reduce sum c_z
thermo_style    custom step atoms c_zsum
timestep        1e-7
$3
LMPIN
}

compare() { # $1 = law name, $2 = LAMMPS eta_n0, $3 = LAMMPS damping model, $4 = steps (0: one evaluation)
  lammps_input "$2" "$3" "dump f all custom ${4:-1} $OUT/lammps_$1.dump id fx fy
dump_modify f sort id format float %.17g
run ${4:-0}" > "$OUT/in.forces_$1"
  "$LMP" -in "$OUT/in.forces_$1" -log "$OUT/log.forces_$1" -screen none
  "$GL" "$OUT/grainlab_side.lua" mode=forces law="$1" T="$T" steps="${4:-0}" data="$DATA" forces="$OUT/grainlab_$1.txt"
  awk -v law="$1" -v fig="$FIG" 'NR == FNR { gx[$1] = $2; gy[$1] = $3; w[$1] = $4; next }
    /^ITEM: TIMESTEP/ { getline ts; on = 0 } /^ITEM: ATOMS/ { on = ts == '"${4:-0}"'; next } /^ITEM/ { on = 0 }
    on { dx = $2 - gx[$1]; dy = $3 - gy[$1]; d = sqrt(dx*dx + dy*dy); m = sqrt($2*$2 + $3*$3)
         if (d > dmax) dmax = d; if (m > fmax) fmax = m; if (d / w[$1] > rmax) { rmax = d / w[$1]; worst = $1 }
         s2 += d * d; f2 += m * m; n++ }
    END { printf "%-8s %d particles: max |f_lammps - f_grainlab| = %.3g N (largest net force %.3g N); rms |df| / rms |f| = %.3g; worst particle %d: |df| = %.3g of its weight\n",
          law, n, dmax, fmax, sqrt(s2 / f2), worst, rmax
          printf "metric forces_%s_rms_rel %.4g\nmetric forces_%s_worst_of_weight %.4g\n", law, sqrt(s2 / f2), law, rmax >> fig }' \
    "$OUT/grainlab_$1.txt" "$OUT/lammps_$1.dump"
}
compare elastic 0 velocity
compare damped "$ETA" viscoelastic
compare springs 0 velocity 100

# ---- timing: A B A B ... ----------------------------------------------------------------------
# LAMMPS: the "Loop time" of its log (the run's steps, no setup), contacts from compute
# contact/atom at the last step; grainlab: s:run's wall time, s:measure("coordination").
# On several ranks LAMMPS cuts the box into equal slabs by default; the pile fills the lower part
# of its box, so one rank would hold most of it. `balance` (shift) gives each rank an equal share
# of the particles, as a LAMMPS user would.
lammps_input "$ETA" viscoelastic "thermo $STEPS
run $STEPS" "balance         1.0 shift xy 10 1.05" > "$OUT/in.time"
load() { uptime | sed 's/.*load average: //; s/,.*//'; }
# CPU time the hypervisor gave to other guests ("steal", /proc/stat) during a run, as a percentage
# of the machine's CPU time: on a virtual machine a quiet load average can hide a host that runs
# this guest's cores at half speed.
cpustat() { awk '/^cpu / { print $2 + $3 + $4 + $5 + $6 + $7 + $8 + $9, $9 }' /proc/stat; }
steal() { echo "$1 $2" | awk '{ d = $3 - $1; printf "%.0f", (d > 0 ? 100 * ($4 - $2) / d : 0) }'; }
run_gl() { OMP_NUM_THREADS=$1 "$GL" "$OUT/grainlab_side.lua" mode=time threads="$1" steps="$STEPS" data="$DATA" | awk '/^RATE/'; }
run_lmp() {
  if [ "$1" = 1 ]; then "$LMP" -in "$OUT/in.time" -log "$OUT/log.time" -screen none
  else mpirun --oversubscribe -np "$1" "$LMP" -in "$OUT/in.time" -log "$OUT/log.time" -screen none; fi
  awk -v n="$N" -v s="$STEPS" '/^Loop time of/ { w = $4 } $1 == s && NF == 3 { z = $3 / n }
    $1 == 0 && NF == 3 { z0 = $3 / n }
    END { printf "RATE %.6g WALL %.4g Z %.4f Z0 %.4f", n * s / w, w, z, z0 }' "$OUT/log.time"
}
: > "$OUT/times.txt"
for cores in 1 2; do
  r=1
  while [ "$r" -le "$REPS" ]; do
    l=$(load); c0=$(cpustat); t=$(run_gl "$cores"); c1=$(cpustat)
    echo "grainlab $cores $t LOAD $l STEAL $(steal "$c0" "$c1")" | tee -a "$OUT/times.txt"
    l=$(load); c0=$(cpustat); t=$(run_lmp "$cores"); c1=$(cpustat)
    echo "lammps $cores $t LOAD $l STEAL $(steal "$c0" "$c1")" | tee -a "$OUT/times.txt"
    r=$((r + 1))
  done
done
# the medians, as a Markdown table
echo
echo "| cores | grainlab particle-steps/s | contacts/particle (start → end) | LAMMPS particle-steps/s | contacts/particle (start → end) | grainlab / LAMMPS | load (1 min) per run | steal % per run |"
echo "|---:|---:|---:|---:|---:|---:|---|---|"
for cores in 1 2; do
  g=$(awk -v c="$cores" '$1 == "grainlab" && $2 == c { print $4 }' "$OUT/times.txt" | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
  l=$(awk -v c="$cores" '$1 == "lammps" && $2 == c { print $4 }' "$OUT/times.txt" | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
  zg=$(awk -v c="$cores" '$1 == "grainlab" && $2 == c { z = $10 " → " $8 } END { print z }' "$OUT/times.txt")
  zl=$(awk -v c="$cores" '$1 == "lammps" && $2 == c { z = $10 " → " $8 } END { print z }' "$OUT/times.txt")
  ld=$(awk -v c="$cores" '$2 == c { printf "%s%s", s, $12; s = " " }' "$OUT/times.txt")
  st=$(awk -v c="$cores" '$2 == c { printf "%s%s", s, $14; s = " " }' "$OUT/times.txt")
  echo "| $cores | $g | $zg | $l | $zl | $(awk -v a="$g" -v b="$l" 'BEGIN { printf "%.2f", a / b }') | $ld | $st |"
  {
    echo "metric grainlab_rate_${cores}_cores $g"
    echo "metric lammps_rate_${cores}_cores $l"
    echo "metric ratio_${cores}_cores $(awk -v a="$g" -v b="$l" 'BEGIN { printf "%.6g", a / b }')"
    echo "metric loads_${cores}_cores $ld"
    echo "metric steal_percent_${cores}_cores $st"
  } >> "$FIG"
done
awk '$1 == "grainlab" { zs = $10; zg = $8 } $1 == "lammps" { zl = $8 }
  END { print "metric contacts_per_particle_start", zs; print "metric contacts_per_particle_end_grainlab", zg
        print "metric contacts_per_particle_end_lammps", zl }' "$OUT/times.txt" >> "$FIG"
if [ -n "$REPORT" ]; then
  "$GL" --quiet --report "$REPORT" scripts/bench/shell_report.lua scenario=bench_vs_lammps figures="$FIG" >/dev/null
fi
