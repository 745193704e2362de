#!/usr/bin/env bash
# cmake --install into a temporary prefix: bin/grainlab runs from anywhere (its Lua library is
# inside it), and share/man/man1/grainlab.1 exists, renders, and tells what --help tells.
#   install_test.sh BUILD_DIR
set -euo pipefail
build=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
exe=$tmp/prefix/bin/grainlab
page=$tmp/prefix/share/man/man1/grainlab.1
[ -x "$exe" ] || fail "no executable $exe"
[ -s "$page" ] || fail "no man page $page"

# The installed binary, run away from the source and build trees, loads its embedded library.
cd "$tmp"
out=$("$exe" -e 'print(grainlab.version, type(dem.scene), type(require("grainlab.figures").path))')
[ "$out" = "$("$exe" -e 'print(grainlab.version)')	function	function" ] || fail "installed binary: $out"
echo "ok    bin/grainlab runs: $out"

# The page is true to --help: every option and the exit-status line appear in it.
render() {
  if command -v man >/dev/null; then MANWIDTH=100 MANPAGER=cat PAGER=cat man -l "$1" 2>/dev/null
  elif command -v groff >/dev/null; then groff -man -Tutf8 "$1" 2>/dev/null
  elif command -v nroff >/dev/null; then nroff -man "$1" 2>/dev/null
  else cat "$1"; fi
}
text=$(render "$page" | sed 's/.\x08//g')   # no overstrike bold from nroff
[ -n "$text" ] || fail "the man page renders empty"
for want in NAME SYNOPSIS DESCRIPTION "grainlab [options] [FILE.lua] [name=value ...]"; do
  grep -qF -- "$want" <<<"$text" || fail "rendered man page lacks '$want'"
done
n=0
while IFS= read -r opt; do
  grep -qF -- "$opt" <<<"$text" || fail "man page lacks the option '$opt' of --help"
  n=$((n + 1))
done < <("$exe" --help | grep -oE '^  -[-a-z]+( [A-Z]+)?' | sed 's/^  //')
[ "$n" -ge 5 ] || fail "found only $n options in --help"
grep -qF "Exit status: 0 success" <<<"$text" || fail "man page lacks the exit status"
echo "ok    share/man/man1/grainlab.1 renders and names all $n options of --help"
