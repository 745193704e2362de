#!/usr/bin/env bash
# The command line as scripts and CI use it: exit codes, messages on stderr, params, standard
# input, -e, -i without a terminal, report JSON (read with jq), progress lines, Ctrl-C.
# usage: test_cli.sh path/to/grainlab   (run from tests/cli, where the fixture scripts are)
set -u
G=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0

# run CMD... : runs with stdin from /dev/null unless redirected; sets $out, $err, $rc
run() { "$@" >"$tmp/out" 2>"$tmp/err"; rc=$?; out=$(cat "$tmp/out"); err=$(cat "$tmp/err"); }
ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*"; echo "  rc=$rc"; echo "  stdout: $out"; echo "  stderr: $err"; }
expect_rc() { [ "$rc" -eq "$1" ] && ok || bad "$2: exit status $rc, expected $1"; }
has() { case "$1" in *"$2"*) ok ;; *) bad "$3: missing '$2'" ;; esac; }
lines() { [ "$(printf '%s\n' "$1" | grep -c .)" -eq "$2" ] && ok || bad "$3: expected $2 line(s)"; }

# --- flags ---
run "$G" --version </dev/null;  expect_rc 0 version; has "$out" "grainlab 0.1.0 (Lua 5.4" version
has "$out" "; kernels: " version
run "$G" --help </dev/null;     expect_rc 0 help; has "$out" "usage: grainlab" help
run "$G" --bogus </dev/null;    expect_rc 2 unknown-flag; has "$err" "unknown option '--bogus'" unknown-flag
lines "$err" 1 unknown-flag
run "$G" -e </dev/null;         expect_rc 2 e-without-code; has "$err" "-e needs a Lua chunk" e-without-code
run "$G" --threads 0 -e 'print(1)' </dev/null; expect_rc 2 threads-0; has "$err" "--threads needs an integer" threads-0
run "$G" --threads=1 -e 'print("threads", grainlab.threads())' </dev/null
expect_rc 0 threads-1; has "$out" "threads	1" threads-1
run "$G" --report </dev/null;   expect_rc 2 report-no-file; has "$err" "--report needs a file name" report-no-file

# --- scripts and their errors ---
run "$G" no_such_script.lua </dev/null
expect_rc 1 missing-script; has "$err" "cannot open no_such_script.lua" missing-script; lines "$err" 1 missing-script
# docs/cli.md's exit status table says the same: the status of the row naming each case
doc_status() { grep -E "^ *\| [0-9]+ \|.*$1" ../../docs/cli.md | sed -E 's/^ *\| ([0-9]+) \|.*/\1/'; }
[ "$(doc_status 'script that cannot be read')" = 1 ] && ok || bad "docs/cli.md: a missing script's status"
[ "$(doc_status 'unknown option')" = 2 ] && ok || bad "docs/cli.md: an unknown option's status"
[ "$(doc_status 'argument without')" = 2 ] && ok || bad "docs/cli.md: an argument without = status"
[ "$(doc_status 'a Lua error')" = 1 ] && ok || bad "docs/cli.md: a Lua error's status"
run "$G" syntax_error.lua </dev/null
expect_rc 1 syntax; has "$err" "syntax_error.lua:4: ')' expected (to close '(' at line 3) near 'end'" syntax
lines "$err" 1 syntax
run "$G" runtime_error.lua </dev/null
expect_rc 1 runtime; has "$err" "runtime_error.lua:2: attempt to index a nil value (local 'v')" runtime
has "$err" "stack traceback:" runtime; has "$err" "runtime_error.lua:4: in main chunk" runtime
run "$G" library_error.lua </dev/null
expect_rc 1 library-error; has "$err" "grainlab: library_error.lua:6: run: particle " library-error
has "$err" "likely cause: no wall on the " library-error
has "$err" "stack traceback:" library-error; has "$err" "library_error.lua:6: in main chunk" library-error
case "$err" in *lua/grainlab/*) bad "library-error: library frames or positions shown" ;; *) ok ;; esac
lines "$err" 3 library-error
run "$G" -e 'error({})' </dev/null
expect_rc 1 error-object; has "$err" "(error object is a table value)" error-object

# --- params ---
run "$G" params.lua n=100 x=2.5 name=run1 flag=false on=true neg=-3 hex=0x10 empty= path=a=b </dev/null
expect_rc 0 params
for want in "n	integer	100" "x	float	2.5" "name	string	run1" "flag	boolean	false" \
            "on	boolean	true" "neg	integer	-3" "hex	integer	16" "empty	string	" \
            "path	string	a=b" "arg0	params.lua"; do
  has "$out" "$want" params
done
run "$G" params.lua n=1 oops </dev/null; expect_rc 2 param-without-eq; has "$err" "argument 'oops' is not name=value" param-without-eq
lines "$err" 1 param-without-eq
run "$G" params.lua 1x=2 </dev/null;    expect_rc 2 param-bad-name; has "$err" "bad parameter '1x=2'" param-bad-name
run "$G" -e 'print(params.k + 1)' k=41 </dev/null; expect_rc 0 params-with-e; has "$out" "42" params-with-e

# --- standard input, -e, -i ---
run "$G" <<<'print("from stdin", 6*7)'; expect_rc 0 stdin-chunk; has "$out" "from stdin	42" stdin-chunk
run "$G" <<<'error("stdin boom")'; expect_rc 1 stdin-error; has "$err" "stdin:1: stdin boom" stdin-error
run "$G" - who=pipe <<<'print("script from stdin", params.who)'
expect_rc 0 stdin-script; has "$out" "script from stdin	pipe" stdin-script
run "$G" -e 'x = 5' -e 'print(x * 2)' </dev/null; expect_rc 0 two-e; has "$out" "10" two-e
run "$G" -e 'nil_call()' </dev/null; expect_rc 1 e-error; has "$err" "(command line):1: attempt to call a nil value (global 'nil_call')" e-error
run "$G" -i -e 'y = 3' <<<$'y * 14\nfunction f()\nreturn "multi"\nend\nf()\nerror("in repl")\nprint("after error")'
expect_rc 0 interactive-pipe; has "$out" "42" interactive-pipe; has "$out" "multi" interactive-pipe
has "$err" "stdin:1: in repl" interactive-pipe; has "$out" "after error" interactive-pipe

# --- reports ---
run "$G" report_ok.lua n=7 --report "$tmp/ok.json" </dev/null
expect_rc 0 report-ok; has "$out" "== cli_ok ==" report-ok; has "$out" "3 passed, 0 failed" report-ok
if jq -e '.scenario == "cli_ok" and .params.n == 7 and .params.label == "x"
          and .metrics.particle_steps_per_s == 1500000 and .metrics.steps == 1000
          and (.checks | length) == 3 and all(.checks[]; .pass == true)
          and .checks[0].name == "restitution_rel_err" and .checks[0].limit == 0.001
          and .checks[1].op == ">=" and (.wall_s | type) == "number" and .wall_s >= 0' \
     "$tmp/ok.json" >/dev/null; then ok; else bad "report-ok: JSON content: $(cat "$tmp/ok.json")"; fi
[ -z "$(ls "$tmp" | grep '\.tmp\.')" ] && ok || bad "report-ok: temporary file left behind"

run env GRAINLAB_REPORT="$tmp/fail.json" "$G" report_fail.lua </dev/null
expect_rc 1 report-fail; has "$out" "FAIL  small_error" report-fail; has "$out" "1 passed, 2 failed" report-fail
has "$out" "report returned	false" report-fail; has "$err" "2 report checks failed" report-fail
if jq -e '.scenario == "cli_fail" and .checks[0].pass == false and .checks[1].value == null
          and .checks[1].pass == false and .checks[2].pass == true' "$tmp/fail.json" >/dev/null
then ok; else bad "report-fail: JSON content: $(cat "$tmp/fail.json")"; fi

run "$G" report_ok.lua --report "$tmp/no/such/dir/r.json" </dev/null
expect_rc 1 report-unwritable; has "$err" "report: cannot write '$tmp/no/such/dir/r.json'" report-unwritable
[ ! -e "$tmp/no/such/dir/r.json" ] && ok || bad "report-unwritable: file exists"

run "$G" -e 'grainlab.report{ scenario = "x", metrics = { ["Bad-Name"] = 1 } }' </dev/null
expect_rc 1 report-bad-metric; has "$err" "bad field 'metrics' in argument #1 to 'report' (snake_case metric names" report-bad-metric
has "$err" "(command line):1:" report-bad-metric

# --- progress when not a terminal; --quiet ---
run "$G" progress.lua </dev/null
expect_rc 0 progress-lines
for pct in " 10%" " 50%" " 90%"; do has "$err" "sweep: $pct" progress-lines; done
has "$err" "sweep: done, 50 cases in" progress-lines; lines "$err" 10 progress-lines
run "$G" --quiet progress.lua </dev/null; expect_rc 0 progress-quiet; [ -z "$err" ] && ok || bad "progress-quiet: stderr not empty"

# --- warnings go to stderr and do not stop the script ---
run "$G" -e 'local m = mpm.scene{ cells = { 10, 10 }, size = { 1, 1 } }
local mt = mpm.material{ density = 1, shear = 1, bulk = 1 }
m:add_disk{ center = { 0.4, 0.5 }, radius = 0.2, material = mt }
m:add_disk{ center = { 0.7, 0.5 }, radius = 0.2, material = mt }
print("added", m:info().grains)' </dev/null
expect_rc 0 mpm-overlap; has "$out" "added	2" mpm-overlap
has "$err" "grainlab: warning: add_disk: grain 2 overlaps grain 1 by 0.1 m" mpm-overlap

# --- the default material is named once per scene, with what it costs; --quiet silences it ---
run "$G" default_material.lua </dev/null
expect_rc 0 default-material; has "$out" "dt	" default-material
dt=$(sed -n 's/^dt\t//p' <<<"$out" | head -1)
has "$err" "grainlab: note: add_disk: no material given, using the default quartz (E = 30 GPa, rho = 2650 kg/m^3): its contact time sets dt = \"auto\" to $dt s here" default-material
has "$err" "; pass material = grainlab.material{...}" default-material
has "$err" "grainlab: note: grainlab.pack.random: no material given, using the default quartz" default-material
lines "$err" 2 default-material
run "$G" --quiet default_material.lua </dev/null
expect_rc 0 default-material-quiet; [ -z "$err" ] && ok || bad "default-material-quiet: printed"

# --- a material's restitution under contacts without damping is named once, as elastic ---
run "$G" undamped.lua </dev/null
expect_rc 0 undamped; has "$out" "e	1.0000" undamped
has "$err" "grainlab: warning: run: the contacts have no damping (damping = \"none\"), so every collision is elastic (e = 1), but material 1 asks restitution 0.5" undamped
lines "$err" 1 undamped
run "$G" --quiet undamped.lua </dev/null
expect_rc 0 undamped-quiet; [ -z "$err" ] && ok || bad "undamped-quiet: printed"

# --- Ctrl-C (SIGINT) stops a running script with an error naming it ---
# The signals are sent once the script says it runs: a background job of this non-interactive
# shell starts with SIGINT ignored until grainlab's handler is in place, so a signal sent at a
# fixed delay was lost whenever a loaded machine made the start-up slower than the delay.
start_long() {
  rm -f "$tmp/out" "$tmp/err" # else the wait below can find the last run's "running"
  "$@" >"$tmp/out" 2>"$tmp/err" &
  pid=$!
  for _ in $(seq 200); do grep -q running "$tmp/err" 2>/dev/null && break; sleep 0.05; done
}
finish_long() { wait "$pid"; rc=$?; out=$(cat "$tmp/out"); err=$(cat "$tmp/err"); }
start_long "$G" -e 'io.stderr:write("running\n") while true do end' </dev/null
kill -INT "$pid"; finish_long
expect_rc 1 sigint; has "$err" "interrupted by Ctrl-C" sigint

# --- progress of every engine's run, standard error redirected to a file ---
# GRAINLAB_PROGRESS_DELAY=0 shows unasked progress from the start (by default after 2 s), so the
# lines below depend only on the run's length, never on timing.
for e in dem mpm dsmc; do
  run env GRAINLAB_PROGRESS_DELAY=0 "$G" run_progress.lua engine=$e steps=2000 </dev/null
  expect_rc 0 "progress-$e"; has "$out" "ran" "progress-$e"
  for pct in 10 50 90; do has "$err" "$e run:  $pct% ($((pct * 20))/2000 steps)" "progress-$e"; done
  has "$err" "ETA" "progress-$e"; has "$err" "$e run: done, 2000 steps in" "progress-$e"
  lines "$err" 10 "progress-$e"
done
run env GRAINLAB_PROGRESS_DELAY=1000 "$G" run_progress.lua </dev/null
expect_rc 0 progress-unasked-short; [ -z "$err" ] && ok || bad "progress-unasked-short: a run shorter than the delay printed"
run env GRAINLAB_PROGRESS_DELAY=1000 "$G" run_progress.lua engine=mpm progress=true </dev/null
has "$err" "mpm run:  50% (1000/2000 steps)" progress-asked; lines "$err" 10 progress-asked
run env GRAINLAB_PROGRESS_DELAY=0 "$G" run_progress.lua progress=false </dev/null
[ -z "$err" ] && ok || bad "progress-false: printed"
run env GRAINLAB_PROGRESS_DELAY=0 "$G" --quiet run_progress.lua engine=dsmc progress=true </dev/null
[ -z "$err" ] && ok || bad "progress-quiet-run: printed"
run env GRAINLAB_PROGRESS_DELAY=0 "$G" run_progress.lua engine=dem stop_at=500 </dev/null
has "$err" "dem run: stopped (on_step returned false) at step 500 of 2000 after" progress-stopped
lines "$err" 3 progress-stopped

# --- Ctrl-C during a run: the last progress line and the error say where it stopped ---
# start_long ARGS...: runs long_run.lua in the background until it says "running"
start_long env GRAINLAB_PROGRESS_DELAY=0 "$G" long_run.lua </dev/null
kill -INT "$pid"; finish_long
expect_rc 1 run-sigint
if grep -Eq '^dem run: interrupted at step [0-9]+ of 1000000000 after' <<<"$err"; then ok; else bad "run-sigint: progress line"; fi
# the kernel stops between steps, or on_step's Lua code is interrupted: both say where
if grep -Eq 'run: interrupted at step [0-9]+ of 1000000000 of this run \(t = [0-9.e-]+ s\); the scene is intact|interrupted by Ctrl-C \(in on_step: the run stopped at step [0-9]+ of 1000000000 of this run; the scene is intact\)' <<<"$err"
then ok; else bad "run-sigint: error message"; fi
[ "$(grep -c 'done,' <<<"$err")" -eq 0 ] && ok || bad "run-sigint: says done"

# --- a caught Ctrl-C is handled: later runs go to their end, a later Ctrl-C interrupts again ---
"$G" interrupt_resume.lua </dev/null >"$tmp/out" 2>"$tmp/err" &
pid=$!
for phase in 1 2; do
  for _ in $(seq 200); do grep -q "running$phase" "$tmp/err" 2>/dev/null && break; sleep 0.05; done
  kill -INT "$pid"
done
finish_long
expect_rc 0 interrupt-resume
if grep -Eq '^caught1	false	run: interrupted at step [0-9]+ of 1000000000 of this run' <<<"$out" \
   || grep -Eq '^caught1	false	.*interrupted by Ctrl-C \(in on_step' <<<"$out"
then ok; else bad "interrupt-resume: the first Ctrl-C stops the run"; fi
if grep -Eq '^caught2	false	.*interrupted by Ctrl-C$' <<<"$out"; then ok; else bad "interrupt-resume: the hook's error"; fi
for phase in after1 after2; do
  for e in dem mpm dsmc; do has "$out" "$phase	$e	10" "interrupt-resume ($phase, $e)"; done
done

# --- SIGTERM: stops between steps, removes temporaries, says where, exits 128 + 15 ---
mkdir -p "$tmp/w"
start_long "$G" long_run.lua write=true out="$tmp/w/big.dat" </dev/null
kill -TERM "$pid"; finish_long
expect_rc 143 sigterm-run
if grep -Eq "^grainlab: terminated \(SIGTERM\) at step [0-9]+ of 1000000000 of 'dem run'; partial outputs removed \((none was open|1 file)\)$" <<<"$err"
then ok; else bad "sigterm-run: message"; fi
[ "$(grep -c traceback <<<"$err")" -eq 0 ] && ok || bad "sigterm-run: a traceback instead of one message"
[ -z "$(ls "$tmp/w" | grep '\.tmp\.')" ] && ok || bad "sigterm-run: temporary file left: $(ls "$tmp/w")"
[ ! -e "$tmp/w/big.dat" ] || [ "$(stat -c %s "$tmp/w/big.dat")" -eq 4000000 ] && ok || bad "sigterm-run: partial file"
# in plain Lua, and where the script swallows errors with pcall
"$G" -e 'io.stderr:write("running\n") io.stderr:flush() while true do pcall(function() while true do end end) end' \
  </dev/null >"$tmp/out" 2>"$tmp/err" &
pid=$!
for _ in $(seq 200); do grep -q running "$tmp/err" 2>/dev/null && break; sleep 0.05; done
kill -TERM "$pid"; finish_long
expect_rc 143 sigterm-lua; has "$err" "grainlab: terminated (SIGTERM); partial outputs removed (none was open)" sigterm-lua

echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
