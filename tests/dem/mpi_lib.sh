# Sourced by the DEM MPI test drivers: mpirun settings and a run that keeps grainlab's own leaks
# visible under the sanitizer build.
# As root on a small box without network: shared memory only, oversubscribed, no binding (the
# spmd tests' settings: mpirun starts in ~0.3 s).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,vader
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_hwloc_base_binding_policy=none
export OMPI_MCA_btl_vader_single_copy_mechanism=none
mpi_lib_here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
mpi_lib_src=$(cd "$mpi_lib_here/../../src" && pwd)
# Sanitizer builds: Open MPI leaks at exit from components it has already unloaded, whose frames
# LSan cannot name (so no suppression matches them). Under mpirun the leak report is therefore
# read here instead: a leak with a frame in grainlab's own sources fails, the others (Open MPI's)
# are ignored. Plain (one-rank) runs keep LeakSanitizer's own verdict.
mpi_lib_sanitize=0
[ -n "${LSAN_OPTIONS:-}" ] && mpi_lib_sanitize=1

# mpi_run ERRFILE MPIEXEC NP command...: 0 when the run and its leak check pass.
mpi_run() {
  local errf=$1 mpiexec=$2 np=$3
  shift 3
  if [ $mpi_lib_sanitize = 0 ]; then
    "$mpiexec" --oversubscribe -np "$np" "$@" 2> "$errf" || { cat "$errf"; return 1; }
    cat "$errf" >&2
    return 0
  fi
  LSAN_OPTIONS="suppressions=$mpi_lib_here/lsan_mpi.supp:print_suppressions=0:exitcode=0" \
    "$mpiexec" --oversubscribe -np "$np" "$@" 2> "$errf" || { cat "$errf"; return 1; }
  # a leak block: from "Direct/Indirect leak" to the blank line; ours if a frame is in src/
  if awk -v src="$mpi_lib_src" '
       /^(Direct|Indirect) leak/ { blk = $0; inb = 1; next }
       inb && /^$/ { if (blk ~ src) { print blk; bad = 1 } inb = 0; next }
       inb { blk = blk "\n" $0 }
       END { exit !bad }' "$errf"; then
    echo "FAIL: $np ranks leak memory allocated by grainlab"
    return 1
  fi
  return 0
}
