#!/usr/bin/env bash
# scripts/dev/longest.sh can fail: on a scratch src/ it refuses a function of 151 lines and a file
# of 1,001 lines, accepts 150 and 1,000 and what the allow-list names, and refuses an allow-list
# entry that is no longer needed.
#   longest_selftest.sh CTAGS
set -u
ctags=${1:-ctags}
here=$(cd "$(dirname "$0")" && pwd)
longest=$here/../../scripts/dev/longest.sh
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/src/a"
fail=0
# a C function of n lines in all: signature, brace, n - 3 statements, brace
function_of() {
  echo "int $1(void)"
  echo "{"
  for ((k = 0; k < $2 - 3; k++)); do echo "    (void)$k;"; done
  echo "}"
}
expect() { # want_status what [longest.sh args]
  local want=$1 what=$2; shift 2
  out=$(bash "$longest" --ctags "$ctags" "$@" "$work/src" 2>&1)
  got=$?
  if [ "$got" -eq "$want" ]; then echo "ok    $what"; else
    echo "FAIL  $what: exit $got, expected $want"; echo "$out" | sed 's/^/      /'; fail=1; fi
}
: > "$work/allow.txt"
{ function_of at_limit 150; echo; function_of short 3; } > "$work/src/a/ok.c"
expect 0 "a function of 150 lines passes" --allow "$work/allow.txt"
function_of over 151 > "$work/src/a/over.c"
expect 1 "a function of 151 lines fails" --allow "$work/allow.txt"
echo "src/a/over.c over" > "$work/allow.txt"
expect 0 "an allowed function of 151 lines passes" --allow "$work/allow.txt"
rm "$work/src/a/over.c"
expect 1 "a stale allow-list entry fails" --allow "$work/allow.txt"
: > "$work/allow.txt"
for ((k = 0; k < 1000; k++)); do echo "/* $k */"; done > "$work/src/a/long.h"
expect 0 "a file of 1,000 lines passes" --allow "$work/allow.txt"
echo "/* one more */" >> "$work/src/a/long.h"
expect 1 "a file of 1,001 lines fails" --allow "$work/allow.txt"
echo "src/a/long.h -" > "$work/allow.txt"
expect 0 "an allowed file of 1,001 lines passes" --allow "$work/allow.txt"
exit $fail
