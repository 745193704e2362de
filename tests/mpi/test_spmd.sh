#!/usr/bin/env bash
# SPMD scripts under mpirun, as a user runs them: output and files once, errors once, a lone
# failing rank ending the run without a hang, SIGTERM stopping every rank at the same step,
# and the refusals (MPM, the REPL).
# usage: test_spmd.sh path/to/grainlab path/to/mpirun [SECTION]   (run from tests/mpi)
#   SECTION: output, errors, refusals or sigterm (default: all of them)
set -u
G=$(realpath "$1") M=${2:-} section=${3:-all}
want() { [ "$section" = all ] || [ "$section" = "$1" ]; }
if [ -z "$M" ] || [ ! -x "$M" ] || ! "$G" -e 'os.exit(grainlab.mpi.available and 0 or 1)'; then
  echo "skipped: grainlab was built without MPI, or mpirun is missing"; exit 77
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 GRAINLAB_PROGRESS_DELAY=0
here=$(pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0

# mpirun NP ARGS... in $tmp/run (emptied first): sets $out, $err, $rc; 60 s at most
run() {
  local np=$1; shift
  rm -rf "$tmp/run"; mkdir -p "$tmp/run"
  (cd "$tmp/run" && timeout 60 "$M" --oversubscribe -np "$np" "$G" "$@" >"$tmp/out" 2>"$tmp/err" </dev/null)
  rc=$?; out=$(cat "$tmp/out"); err=$(cat "$tmp/err")
}
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*"; echo "  rc=$rc"; echo "  stdout: $out"; echo "  stderr: $err"; }
expect_rc() { [ "$rc" -eq "$1" ] && ok || bad "$2: exit status $rc, expected $1"; }
# count TEXT N WHAT: TEXT appears on exactly N lines of stdout + stderr
count() {
  local n; n=$(printf '%s\n%s\n' "$out" "$err" | grep -cF -- "$1")
  [ "$n" -eq "$2" ] && ok || bad "$3: '$1' on $n lines, expected $2"
}
lacks() { case "$out$err" in *"$1"*) bad "$2: unexpected '$1'" ;; *) ok ;; esac; }

if want output; then
# --- output and files once (3 ranks) ---
run 3 --report r.json "$here/spmd_output.lua"
expect_rc 0 output
count "printed once	3" 1 print; count "io.write once" 1 io.write; count "stderr once" 1 io.stderr
count "spmd:  50% (5/10 steps)" 1 progress; count "spmd: done, 10 steps" 1 progress-end
count "== spmd_output ==" 1 report-table; count "1 passed, 0 failed" 1 report-checks
files=$(cd "$tmp/run" && ls | tr '\n' ' ')
[ "$files" = "io.txt r.json rec.csv scene.png whole.txt " ] && ok || bad "files: exactly the five outputs, no temporaries (got: $files)"
[ "$(wc -l <"$tmp/run/io.txt")" -eq 100 ] && [ "$(tail -n1 "$tmp/run/io.txt")" = "line 100" ] && ok || bad "io.txt whole"
[ "$(wc -l <"$tmp/run/rec.csv")" -eq 51 ] && [ "$(tail -n1 "$tmp/run/rec.csv")" = "50,2500" ] && ok || bad "rec.csv whole"
[ "$(wc -c <"$tmp/run/whole.txt")" -eq 1000 ] && ok || bad "whole.txt whole"
[ "$(head -c 8 "$tmp/run/scene.png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] && ok || bad "scene.png is a PNG"
if command -v jq >/dev/null; then
  [ "$(jq -r '.metrics.ranks' "$tmp/run/r.json")" = 3 ] && ok || bad "report JSON written once, whole"
fi

# the same script without mpirun gives the same stdout (the ranks line aside)
one=$(cd "$tmp" && mkdir -p plain && cd plain && "$G" --quiet "$here/spmd_output.lua" 2>/dev/null | grep -v -e '^printed once' -e wall -e '^  ranks ')
three=$(printf '%s\n' "$out" | grep -v -e '^printed once' -e wall -e '^  ranks ')
[ "$one" = "$three" ] && ok || bad "plain and 3-rank stdout differ: $one // $three"

# GRAINLAB_MPI_OUTPUT=all: every rank prints (debugging)
export GRAINLAB_MPI_OUTPUT=all
run 3 -e 'print("hello from", grainlab.mpi.rank())'
expect_rc 0 output-all; count "hello from" 3 output-all; count "hello from	2" 1 output-all
unset GRAINLAB_MPI_OUTPUT

fi

if want errors; then
# --- errors ---
# the same error on every rank: said once, status 1, no MPI_ABORT
run 3 -e 'local x = nil; x.field = 1'
expect_rc 1 same-error; count "attempt to index a nil value (local 'x')" 1 same-error; lacks MPI_ABORT same-error
lacks "rank 1" same-error
# bcast refused on the root: every rank raises the root's message (no rank waits for data)
run 3 -e 'grainlab.mpi.bcast(grainlab.mpi.rank() == 0 and print or 1)'
expect_rc 1 bcast-refused; count "bad argument #1 to 'bcast'" 1 bcast-refused; lacks "rank 1" bcast-refused
# different errors: each said once, by its rank
run 3 -e 'error("error of rank " .. grainlab.mpi.rank(), 0)'
expect_rc 1 rank-errors; count "grainlab: error of rank 0" 1 rank-errors
count "grainlab: rank 1: error of rank 1" 1 rank-errors; count "grainlab: rank 2: error of rank 2" 1 rank-errors
# an error on rank 1 only, the others waiting in a collective: no hang, the rank named
export GRAINLAB_MPI_ERROR_WAIT=1
run 3 -e 'if grainlab.mpi.rank() == 1 then error("only on rank one", 0) end grainlab.mpi.barrier()'
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] && ok || bad "lone error: nonzero status, no timeout"
count "grainlab: rank 1: only on rank one" 1 lone-error; count "rank 1 failed alone" 1 lone-error
# an error on rank 2 only, the others finishing normally: they wait for it, status 1, no abort
run 3 -e 'if grainlab.mpi.rank() == 2 then error("late on rank two", 0) end'
expect_rc 1 lone-error-at-end; count "grainlab: rank 2: late on rank two" 1 lone-error-at-end
lacks MPI_ABORT lone-error-at-end
# os.exit on every rank: MPI ended properly, the status kept; on one rank alone: no hang
run 2 -e 'print("bye") os.exit(true)'
expect_rc 0 os.exit-true; count bye 1 os.exit-true; lacks "exiting improperly" os.exit-true
run 3 -e 'os.exit(3, true)'
expect_rc 3 os.exit-3; lacks "exiting improperly" os.exit-3
run 3 -e 'if grainlab.mpi.rank() == 1 then os.exit(0) end grainlab.mpi.barrier()'
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] && ok || bad "lone os.exit: nonzero status, no timeout"
count "grainlab: rank 1 ended alone" 1 lone-os.exit
unset GRAINLAB_MPI_ERROR_WAIT
# the MPI module cannot be loaded: the rank says which and why, status 70, no hang
GRAINLAB_MPI_MODULE=/nonexistent/grainlab-mpi.so run 2 -e 'print("ran")'
expect_rc 70 no-module; lacks ran no-module
# (mpirun may end the second rank before it speaks: at least one says it)
case "$err" in *"could not be loaded"*"/nonexistent/grainlab-mpi.so: cannot open"*) ok ;;
  *) bad "no-module: the module and the reason named" ;; esac
# a plain run does not load MPI at all (the module and libmpi stay out of the process)
out=$("$G" -e 'local f = io.open("/proc/self/maps") local m = f:read("a") f:close()
  print(m:find("libmpi", 1, true) and "mpi loaded" or "no mpi")' 2>&1); rc=$?
case "$out" in "no mpi") ok ;; *) err=""; bad "plain run: $out" ;; esac
# a failed report check: once
run 2 -e 'grainlab.report{ scenario = "f", checks = { { name = "c", value = 2, limit = 1 } } }'
expect_rc 1 report-check; count "1 report check failed" 1 report-check

fi

if want refusals; then
# --- refusals ---
run 2 -e 'local m = mpm.scene{ cells = { 4, 4 }, size = { 1, 1 } }'
expect_rc 1 mpm; count "mpm.scene: MPM does not run distributed yet (this run has 2 ranks under mpirun); run MPM scripts without mpirun" 1 mpm
run 2
expect_rc 2 repl; count "under mpirun, give the script as a file" 1 repl
run 2 -
expect_rc 2 stdin-script; count "under mpirun, give the script as a file" 1 stdin-script

fi

if want sigterm; then
# --- SIGTERM to one rank only: every rank stops at the same step, said once, status 143 ---
rm -rf "$tmp/run"; mkdir -p "$tmp/run"
(cd "$tmp/run" && exec timeout 60 "$M" --oversubscribe -np 3 "$G" --quiet "$here/long_run.lua" >"$tmp/out" 2>"$tmp/err") &
launcher=$!
for _ in $(seq 300); do [ -e "$tmp/run/started" ] && break; sleep 0.1; done
sleep 0.5
mp=$(pgrep -P "$launcher" -x mpirun || pgrep -P "$launcher")
set -- $(pgrep -P "$mp")
if [ $# -eq 3 ]; then kill -TERM "$2"; else echo "no ranks found under mpirun $mp"; fi
wait "$launcher"; rc=$?; out=$(cat "$tmp/out"); err=$(cat "$tmp/err")
expect_rc 143 sigterm; count "grainlab: terminated (SIGTERM) at step" 1 sigterm
lacks MPI_ABORT sigterm
[ -z "$(ls "$tmp/run" | grep tmp)" ] && ok || bad "sigterm: temporaries left"

fi

echo "test_spmd: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
