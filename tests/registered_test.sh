#!/usr/bin/env bash
# Every test file is run: each tests/**/test_*.lua and test_*.sh is named in the command of a
# ctest of this build (`ctest --show-only=json-v1`), and each tests/**/test_*.c is compiled into
# one (tests/CMakeLists.txt names it). A test file that no ctest runs would pass by never running.
# The check is first shown to catch a file it is given that no command names.
#   registered_test.sh CTEST BUILD_DIR SOURCE_DIR
set -euo pipefail
ctest=$1 build=$2 src=$3
tests=$src/tests
fail() { echo "FAIL: $*" >&2; exit 1; }

# The arguments of every registered test's command, one a line.
words=$(cd "$build" && "$ctest" --show-only=json-v1 | jq -r '.tests[].command[]?')
[ "$(printf '%s\n' "$words" | grep -c .)" -gt 100 ] || fail "ctest lists too few command words"

# unregistered FILE...: the files (relative to tests/) that no command names.
# The words go to grep as a here-string, not through a pipe: grep -q exits at its first match, and
# under pipefail the writer's SIGPIPE would fail the lookup now and then.
unregistered() {
  local f
  for f in "$@"; do
    case $f in
      *.c) grep -qE "^[^#]* ${f//./\\.}( |\)|$)" "$tests/CMakeLists.txt" || echo "$f" ;;
      *) grep -qxF "$tests/$f" <<<"$words" || echo "$f" ;;
    esac
  done
}

files=()
while IFS= read -r f; do files+=("$f"); done < <(cd "$tests" &&
  find . -type f \( -name 'test_*.lua' -o -name 'test_*.sh' -o -name 'test_*.c' \) | sed 's|^\./||' | sort)
[ ${#files[@]} -gt 80 ] || fail "found only ${#files[@]} test files under $tests"

# The check catches what it must: a file no command names, in each kind.
planted=$(unregistered dem/test_never_registered.lua cli/test_never_registered.sh \
  core/test_never_registered.c | tr '\n' ' ')
[ "$planted" = "dem/test_never_registered.lua cli/test_never_registered.sh core/test_never_registered.c " ] ||
  fail "the check misses files no test runs (it reported '$planted')"

missing=$(unregistered "${files[@]}")
[ -z "$missing" ] || fail "test files no ctest runs (register them in tests/CMakeLists.txt):
$missing"
echo "ok    ${#files[@]} test files, each run by a registered ctest"
