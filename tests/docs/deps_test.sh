#!/usr/bin/env bash
# The dependency table of docs/development.md names exactly the Debian packages build.sh
# installs (its `packages` list), so the documentation cannot fall behind the build again.
#   deps_test.sh SOURCE_DIR
set -euo pipefail
src=$1
fail() { echo "FAIL: $*" >&2; exit 1; }
# build.sh: packages=(a b c\n d e) -> one name a line.
built=$(sed -n '/^packages=(/,/)/p' "$src/build.sh" | sed 's/^packages=(//; s/).*//' | tr -s ' \t' '\n\n' | grep -v '^$' | sort -u)
[ "$(wc -l <<<"$built")" -ge 5 ] || fail "could not read the packages list of build.sh"
# development.md: the backquoted names in the rows of the dependency table.
table=$(sed -n '/^| package | for |/,/^$/p' "$src/docs/development.md")
[ -n "$table" ] || fail "docs/development.md has no '| package | for |' table"
documented=$(cut -d'|' -f2 <<<"$table" | grep -o '`[^`]*`' | tr -d '`' | sort -u)
missing=$(comm -23 <(echo "$built") <(echo "$documented"))
extra=$(comm -13 <(echo "$built") <(echo "$documented"))
[ -z "$missing" ] || fail "build.sh installs packages docs/development.md does not list: $missing"
[ -z "$extra" ] || fail "docs/development.md lists packages build.sh does not install: $extra"
echo "ok    docs/development.md lists the $(wc -l <<<"$built") packages of build.sh"
