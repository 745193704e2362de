#!/usr/bin/env bash
# Runs one Lua script at several rank counts and compares what rank 0 prints (and, on request,
# the files the script writes): the check that a distributed run gives the same answer for any
# number of ranks.
#
# usage: compare_np.sh [options] GRAINLAB SCRIPT.lua [name=value ...]
#   --np "0 1 2 3"   the rank counts (default "1 2 3"); 0 is a plain run without mpirun
#   --ignore REGEX   leave stdout lines matching REGEX (grep -E) out of the comparison, e.g.
#                    wall-clock times: --ignore 'wall|elapsed'
#   --file NAME      also compare the file NAME (relative to the run's directory) byte for byte;
#                    repeatable
#   --keep DIR       keep every run's directory under DIR (DIR/np1, DIR/np2, ...)
#   --mpirun PATH    the launcher (default: $GRAINLAB_MPIEXEC, else mpirun on PATH)
# Each run starts in an empty scratch directory of its own (the script's path is made absolute;
# the name=value pairs are passed on, so pass data paths as absolute paths), with --quiet.
# Exit status: 0 every output identical to the first count's, 1 a difference (a unified diff
# is printed) or a failed run (its stderr is printed), 77 no mpirun (ctest: skipped).
#
# From CMake (tests/CMakeLists.txt), a DSMC test for example:
#   add_test(NAME mpi_dsmc_same COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/mpi/compare_np.sh
#            --np "1 2 3 4" --ignore wall $<TARGET_FILE:grainlab> ${CMAKE_CURRENT_SOURCE_DIR}/mpi/dsmc_same.lua)
#   set_tests_properties(mpi_dsmc_same PROPERTIES ENVIRONMENT "${GRAINLAB_MPI_ENV}" SKIP_RETURN_CODE 77)
set -u
nps="1 2 3" ignore="" keep="" files=() launcher="${GRAINLAB_MPIEXEC:-}"
while [ $# -gt 0 ]; do
  case "$1" in
    --np) nps=$2; shift 2 ;;
    --ignore) ignore=$2; shift 2 ;;
    --file) files+=("$2"); shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    --mpirun) launcher=$2; shift 2 ;;
    --) shift; break ;;
    -*) echo "compare_np.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
[ $# -ge 2 ] || { sed -n '2,26p' "$0" >&2; exit 2; }
G=$(realpath "$1") script=$(realpath "$2"); shift 2
[ -n "$launcher" ] || launcher=$(command -v mpirun || true)
if [ -z "$launcher" ] || [ ! -x "$launcher" ]; then
  echo "compare_np.sh: skipped: no mpirun (apt-get install openmpi-bin)"; exit 77
fi
export OMPI_ALLOW_RUN_AS_ROOT=${OMPI_ALLOW_RUN_AS_ROOT:-1}
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}
export OMPI_MCA_btl=${OMPI_MCA_btl:-self,vader}

top=${keep:-$(mktemp -d)}
[ -n "$keep" ] || trap 'rm -rf "$top"' EXIT
mkdir -p "$top"
first="" status=0
for np in $nps; do
  d="$top/np$np"
  rm -rf "$d"; mkdir -p "$d"
  if [ "$np" = 0 ]; then
    (cd "$d" && "$G" --quiet "$script" "$@" >stdout 2>stderr)
  else
    (cd "$d" && "$launcher" -q --oversubscribe -np "$np" "$G" --quiet "$script" "$@" >stdout 2>stderr)
  fi
  rc=$?
  if [ $rc -ne 0 ]; then
    echo "FAIL np=$np: exit status $rc"; sed 's/^/  /' "$d/stderr"; status=1; continue
  fi
  if [ -n "$ignore" ]; then grep -Ev "$ignore" "$d/stdout" >"$d/compared"; else cp "$d/stdout" "$d/compared"; fi
  if [ -z "$first" ]; then first=$np; continue; fi
  if ! diff -u --label "np=$first" --label "np=$np" "$top/np$first/compared" "$d/compared"; then
    echo "FAIL np=$np: rank 0's output differs from np=$first"; status=1
  fi
  for f in ${files[@]+"${files[@]}"}; do
    if ! cmp -s "$top/np$first/$f" "$d/$f"; then
      echo "FAIL np=$np: file $f differs from np=$first's (or is missing)"; status=1
    fi
  done
done
[ $status -eq 0 ] && echo "compare_np.sh: $(basename "$script"): the same output for np = $nps"
exit $status
