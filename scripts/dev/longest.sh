#!/usr/bin/env bash
# The longest code in src/: functions over 150 lines and files over 1,000 lines, longest first,
# each marked "allowed" when the allow-list names it. Exits 1 when one is not allowed, or when
# the allow-list names one that is no longer too long (then remove it from the list); 0 when
# neither. A function counts from the first line of its definition to its closing brace
# (universal-ctags' line and end fields; the Debian package universal-ctags), a file by its
# lines. The test src_lengths runs it.
#   scripts/dev/longest.sh [--top N] [--allow FILE] [--ctags PROGRAM] [SRC]
# SRC: default src/ of this checkout; FILE: default scripts/dev/longest_allow.txt, one entry a
# line, "PATH FUNCTION" or "PATH -" for a whole file, PATH relative to SRC's parent (# comments).
# --top N: also print the N longest functions whatever their length.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
src=$root/src allow=$here/longest_allow.txt ctags=ctags top=0
max_fn=150 max_file=1000
while [ $# -gt 0 ]; do
  case $1 in
    --top) top=$2; shift 2 ;;
    --allow) allow=$2; shift 2 ;;
    --ctags) ctags=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) echo "longest.sh: unknown option $1" >&2; exit 2 ;;
    *) src=$1; shift ;;
  esac
done
[ -d "$src" ] || { echo "longest.sh: no directory $src" >&2; exit 2; }
"$ctags" --version 2>/dev/null | grep -q "Universal Ctags" ||
  { echo "longest.sh: '$ctags' is not universal-ctags (apt-get install universal-ctags)" >&2; exit 2; }
[ -f "$allow" ] || { echo "longest.sh: no allow-list $allow" >&2; exit 2; }
base=$(cd "$src/.." && pwd)
src=$(cd "$src" && pwd)
rel=${src#"$base"/}
mapfile -t files < <(cd "$base" && find "$rel" -type f \( -name '*.c' -o -name '*.h' -o -name '*.inc' \) | sort)
[ ${#files[@]} -gt 0 ] || { echo "longest.sh: no C sources in $src" >&2; exit 2; }
# "length path name" for every function, then for every file ("length path -")
fns=$(cd "$base" && "$ctags" -x --c-kinds=f --language-force=C --_xformat='%n %e %F %N' "${files[@]}" |
  awk '$2 == "" || $2 !~ /^[0-9]+$/ { print "longest.sh: no end line for " $4 " in " $3 > "/dev/stderr"; next }
       { print $2 - $1 + 1, $3, $4 }' | sort -k1,1nr -k2,2 -k3,3)
lens=$(cd "$base" && wc -l "${files[@]}" | awk '$2 != "total" { print $1, $2, "-" }' | sort -k1,1nr -k2,2)
entries=$(sed 's/#.*//' "$allow" | awk 'NF { if (NF != 2) { print "bad line: " $0 > "/dev/stderr"; exit 1 } print $1, $2 }')
status=0
report() { # kind limit lines
  local kind=$1 limit=$2 lines=$3 n p name mark
  while read -r n p name; do
    [ -n "$n" ] || continue
    [ "$n" -gt "$limit" ] || continue
    if grep -qxF "$p $name" <<<"$entries"; then mark=allowed; else mark=TOO-LONG; status=1; fi
    if [ "$kind" = file ]; then printf '%-9s %6d lines  %s\n' "$mark" "$n" "$p"
    else printf '%-9s %6d lines  %s  %s\n' "$mark" "$n" "$p" "$name"; fi
  done <<<"$lines"
}
echo "functions over $max_fn lines:"
report function "$max_fn" "$fns"
echo "files over $max_file lines:"
report file "$max_file" "$lens"
# allow-list entries that are no longer needed
while read -r p name; do
  [ -n "$p" ] || continue
  if [ "$name" = - ]; then n=$(awk -v p="$p" '$2 == p { print $1 }' <<<"$lens"); limit=$max_file
  else n=$(awk -v p="$p" -v f="$name" '$2 == p && $3 == f { print $1; exit }' <<<"$fns"); limit=$max_fn; fi
  if [ -z "$n" ] || [ "$n" -le "$limit" ]; then
    echo "stale     allow-list entry '$p $name': ${n:-no such function or file}${n:+ lines}, within the limit; remove it from $allow"
    status=1
  fi
done <<<"$entries"
if [ "$top" -gt 0 ]; then
  echo "the $top longest functions:"
  head -n "$top" <<<"$fns" | awk '{ printf "          %6d lines  %s  %s\n", $1, $2, $3 }'
fi
[ $status -eq 0 ] && echo "ok: no function over $max_fn lines and no file over $max_file lines beyond the allow-list"
exit $status
