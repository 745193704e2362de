#!/usr/bin/env bash
# The layout list of docs/development.md names every file under src/, lua/grainlab/ and tests/,
# once, sorted within its folder, and nothing that does not exist: a file added, moved or removed
# without its line fails here.
#   layout_test.sh SOURCE_DIR
set -euo pipefail
export LC_ALL=C
src=$1
cd "$src"
fail() { echo "FAIL: $*" >&2; exit 1; }
# The list: lines "- `PATH`: what it holds" whose PATH lies in one of the three trees.
listed=$(sed -n 's/^- `\(\(src\|lua\|tests\)\/[^`]*\)`: .*/\1/p' docs/development.md)
[ "$(wc -l <<<"$listed")" -ge 100 ] || fail "docs/development.md lists fewer than 100 files (its layout list: lines '- \`src/…\`: …')"
# The files: git's view when this is a checkout (tracked and untracked, not ignored), else find.
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    present=$(git ls-files --cached --others --exclude-standard -- src lua tests | sort -u |
              while read -r f; do [ -f "$f" ] && echo "$f"; done)
else
    present=$(find src lua tests -type f | sort)
fi
dups=$(sort <<<"$listed" | uniq -d)
[ -z "$dups" ] || fail "docs/development.md lists these files twice: $dups"
missing=$(comm -23 <(echo "$present") <(sort <<<"$listed"))
extra=$(comm -13 <(echo "$present") <(sort <<<"$listed"))
[ -z "$missing" ] || fail "files docs/development.md does not list (add one line each to its layout list): $missing"
[ -z "$extra" ] || fail "docs/development.md lists files that do not exist: $extra"
# Sorted within each folder (byte order), so that lines added by separate changes merge.
prev_dir="" prev=""
while read -r f; do
    d=${f%/*}
    if [ "$d" = "$prev_dir" ] && [[ ! "$prev" < "$f" ]]; then
        fail "docs/development.md: '$f' is listed after '$prev' (keep each folder's files sorted)"
    fi
    prev_dir=$d prev=$f
done <<<"$listed"
echo "ok    docs/development.md lists the $(wc -l <<<"$listed") files under src/, lua/grainlab/ and tests/"
