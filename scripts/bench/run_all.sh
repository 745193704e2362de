#!/bin/sh
# Runs every benchmark of scripts/bench/ once, each writing its report into one directory, then
# renders docs/performance.md's figures and README.md's headline rows from those reports
# (scripts/bench/table.lua). Run it from the checkout's top directory, on a machine left alone.
#   scripts/bench/run_all.sh [quick] [out=DIR] [grainlab=build/grainlab] [page=docs/performance.md]
#                            [readme=README.md] [table=false]
# full (the default): the benchmarks' own sizes (about 40 minutes on a busy 2-core machine; the
#   largest DSMC run needs 15 GiB of memory); writes the MPI scaling figure images/scaling.png.
# quick: the same scenes with fewer steps and repetitions, and the largest runs at a tenth of
#   their size (about 5 minutes); the page says it was a quick run.
# The DEM pile they share is prepared the first time (several minutes) and kept in out/bench/.
# table=false runs the benchmarks and leaves the docs alone (grainlab scripts/bench/table.lua
# dir=DIR renders them later). Reports go to DIR (default out/bench/<mode>), emptied first.
# Needs valgrind (instruction counts), mpirun (scaling) and LAMMPS's lmp (vs_lammps.sh).
set -eu
MODE=full GL=build/grainlab DIR= PAGE=docs/performance.md README=README.md TABLE=true
for a in "$@"; do
  case $a in
    quick) MODE=quick ;; full) MODE=full ;;
    out=*) DIR=${a#out=} ;; grainlab=*) GL=${a#grainlab=} ;;
    page=*) PAGE=${a#page=} ;; readme=*) README=${a#readme=} ;; table=*) TABLE=${a#table=} ;;
    *) echo "run_all.sh: unknown argument '$a' (quick, out=, grainlab=, page=, readme=, table=)" >&2; exit 2 ;;
  esac
done
[ -x "$GL" ] || { echo "run_all.sh: no grainlab at $GL (build first, or grainlab=PATH)" >&2; exit 1; }
for tool in valgrind callgrind_control mpirun lmp; do
  command -v $tool >/dev/null || { echo "run_all.sh: $tool not found (apt-get install valgrind openmpi-bin lammps)" >&2; exit 1; }
done
DIR=${DIR:-out/bench/$MODE}
mkdir -p "$DIR"
rm -f "$DIR"/*.json "$DIR"/callgrind.*
GRAINLAB_BENCH_MODE=$MODE
GRAINLAB_BENCH_COMMIT=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
git diff --quiet HEAD 2>/dev/null || GRAINLAB_BENCH_COMMIT="$GRAINLAB_BENCH_COMMIT (modified)"
GRAINLAB_BENCH_RUN="$GRAINLAB_BENCH_COMMIT $MODE $(date +%s)-$$"
export GRAINLAB_BENCH_MODE GRAINLAB_BENCH_COMMIT GRAINLAB_BENCH_RUN

if [ $MODE = full ]; then
  DEM_STEPS=20000 LMP_STEPS=2000 LMP_REPS=3 MPM_CYCLES=400 DSMC_STEPS=50
  SCALING="" LARGE_DSMC="n=2e8 steps=4" LARGE_DEM="n=5e6 steps=200" RENDER="repeat=5"
  BIAX="steps=5000" CONTENDED="seconds=5 rounds=2" MARCH="reps=3 steps=3000 cycles=100" CGRAIN=""
  CONT="cells=160" CONT_LARGE="cells=360"
else
  DEM_STEPS=2000 LMP_STEPS=500 LMP_REPS=1 MPM_CYCLES=100 DSMC_STEPS=20
  SCALING="reps=1 dem_steps=500 dsmc_steps=10" LARGE_DSMC="n=2e7 steps=4" LARGE_DEM="n=5e5 steps=50"
  RENDER="repeat=3" BIAX="steps=1000" CONTENDED="seconds=2 rounds=1" MARCH="reps=1 steps=1000 cycles=20"
  CGRAIN="reps=1 steps=100" CONT="cells=60 warm=50 steps=50" CONT_LARGE="cells=120 warm=20 steps=20"
fi
CG="valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file=$DIR/callgrind.%p"
# run NAME COMMAND...: the command's output into DIR/NAME.log, its report into DIR/NAME.json
# (@REPORT in COMMAND's words stands for the report's path); a failure ends the run with its log.
run() {
  name=$1
  shift
  echo "== $name (load $(cut -d' ' -f1 /proc/loadavg))" >&2
  n=$#
  while [ $n -gt 0 ]; do # rotate the words once, @REPORT replaced
    w=$1
    shift
    case $w in *@REPORT*) w="${w%%@REPORT*}$DIR/$name.json${w#*@REPORT}" ;; esac
    set -- "$@" "$w"
    n=$((n - 1))
  done
  if ! "$@" > "$DIR/$name.log" 2>&1; then
    tail -n 20 "$DIR/$name.log" >&2
    echo "run_all.sh: $name failed (log: $DIR/$name.log)" >&2
    exit 1
  fi
}
t0=$(date +%s)

# The DEM pile, prepared once (deposition and settling, several minutes): the DEM benchmarks,
# the LAMMPS comparison, the scaling runs and the instruction sets all start from it.
mkdir -p out/bench
PILE=out/bench/pile20000.data
[ -s "$PILE.ckpt" ] || run pile "$GL" --quiet scripts/bench/dem_dense.lua n=20000 export="$PILE"
MPMP=$DIR/mpm_prep.ckpt MPMN=$DIR/mpm_noslip_prep.ckpt
CGO="callgrind=$DIR/callgrind.%p"

# shellcheck disable=SC2086 # the mode's size arguments are words
{
run dem_dense "$GL" --quiet --report @REPORT scripts/bench/dem_dense.lua pile="$PILE.ckpt" steps=$DEM_STEPS
run dem_dense_callgrind $CG "$GL" --quiet --report @REPORT scripts/bench/dem_dense.lua pile="$PILE.ckpt" \
  steps=50 "$CGO"
run vs_lammps sh scripts/bench/vs_lammps.sh pile="$PILE" steps=$LMP_STEPS reps=$LMP_REPS grainlab="$GL" \
  out="$DIR/vs_lammps" report=@REPORT
run mpm_shear "$GL" --quiet --report @REPORT scripts/bench/mpm_shear.lua cycles=$MPM_CYCLES save="$MPMP"
run mpm_shear_callgrind $CG "$GL" --quiet --report @REPORT scripts/bench/mpm_shear.lua load="$MPMP" \
  cycles=10 "$CGO"
run mpm_shear_noslip "$GL" --quiet --report @REPORT scripts/bench/mpm_shear.lua model=noslip \
  cycles=$MPM_CYCLES save="$MPMN"
run mpm_shear_noslip_callgrind $CG "$GL" --quiet --report @REPORT scripts/bench/mpm_shear.lua load="$MPMN" \
  cycles=10 "$CGO"
run continuum "$GL" --quiet --report @REPORT scripts/bench/continuum.lua $CONT
run continuum_large "$GL" --quiet --report @REPORT scripts/bench/continuum.lua $CONT_LARGE whole=false \
  scenario=bench_mpm_continuum_large
run dsmc_cooling "$GL" --quiet --report @REPORT scripts/bench/dsmc_cooling.lua steps=$DSMC_STEPS
run dsmc_cooling_callgrind $CG "$GL" --quiet --report @REPORT scripts/bench/dsmc_cooling.lua n=100000 \
  steps=20 "$CGO"
run scaling "$GL" --quiet --report @REPORT scripts/bench/scaling.lua pile="$PILE.ckpt" $SCALING
run largest_dsmc "$GL" --quiet --report @REPORT scripts/bench/largest.lua engine=dsmc $LARGE_DSMC
run largest_dem "$GL" --quiet --report @REPORT scripts/bench/largest.lua engine=dem $LARGE_DEM
run render "$GL" --quiet --report @REPORT scripts/bench/render.lua $RENDER
run cg "$GL" --quiet --report @REPORT scripts/bench/cg.lua $CGRAIN
run biaxial "$GL" --quiet --report @REPORT scripts/bench/biaxial.lua $BIAX
run contended "$GL" --quiet --report @REPORT scripts/bench/contended.lua $CONTENDED
run march_bits sh scripts/bench/march_bits.sh pile="$PILE" grainlab="$GL" out=out/bench/march_bits \
  report=@REPORT $MARCH
}
rm -f "$DIR"/callgrind.*
echo "run_all.sh: $MODE run in $(( ($(date +%s) - t0) / 60 )) min, reports and logs in $DIR" >&2

if [ "$TABLE" != false ]; then
  "$GL" --quiet scripts/bench/table.lua dir="$DIR" page="$PAGE" readme="$README"
fi
