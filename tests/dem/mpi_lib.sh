# Sourced by the DEM MPI test drivers: mpirun settings, and Open MPI's own exit leaks suppressed
# under the sanitizer build (tests/mpi/lsan_mpi.supp, as grainlab_mpi_test does; ours are still
# reported).
# As root on a small box without network: shared memory only, oversubscribed, no binding.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,vader
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_hwloc_base_binding_policy=none
export OMPI_MCA_btl_vader_single_copy_mechanism=none
mpi_lib_here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
mpi_lsan=""
[ -n "${LSAN_OPTIONS:-}" ] &&
  mpi_lsan="suppressions=$mpi_lib_here/../mpi/lsan_mpi.supp:print_suppressions=0"

# mpi_run ERRFILE MPIEXEC NP command...: 0 when the run passes (and, sanitized, leaks nothing of
# ours).
mpi_run() {
  local errf=$1 mpiexec=$2 np=$3
  shift 3
  if [ -n "$mpi_lsan" ]; then
    LSAN_OPTIONS=$mpi_lsan "$mpiexec" --oversubscribe -np "$np" "$@" 2> "$errf" ||
      { cat "$errf"; return 1; }
  else
    "$mpiexec" --oversubscribe -np "$np" "$@" 2> "$errf" || { cat "$errf"; return 1; }
  fi
  cat "$errf" >&2
  return 0
}
