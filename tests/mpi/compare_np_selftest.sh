#!/usr/bin/env bash
# compare_np.sh must pass a script whose output does not depend on the rank count, and fail
# (showing the difference) one whose output does, and one that fails on some count.
# usage: compare_np_selftest.sh GRAINLAB [MPIRUN]
set -u
here=$(dirname "$(realpath "$0")")
G=$1 M=${2:-}
[ -n "$M" ] && [ -x "$M" ] || { echo "skipped: no mpirun"; exit 77; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
cat >"$tmp/same.lua" <<'L'
local v = grainlab.mpi.bcast(grainlab.mpi.rank() == 0 and { 1, 2, 3 } or nil)
print("sum", v[1] + v[2] + v[3], "wall", grainlab.clock())
assert(io.open("f.txt", "w")):write("same\n")
L
cat >"$tmp/differs.lua" <<'L'
print("ranks", grainlab.mpi.size())
L
cat >"$tmp/fails.lua" <<'L'
if grainlab.mpi.size() == 2 then error("two is bad") end
L
bash "$here/compare_np.sh" --mpirun "$M" --np "0 2" --ignore '^never$' --file f.txt "$G" "$tmp/same.lua" >"$tmp/o" 2>&1
[ $? -eq 1 ] && grep -q 'wall' "$tmp/o" || { echo "FAIL: a clock in the output must differ"; cat "$tmp/o"; fail=1; }
bash "$here/compare_np.sh" --mpirun "$M" --np "0 1 2 3" --ignore wall --file f.txt "$G" "$tmp/same.lua" >"$tmp/o" 2>&1 \
  || { echo "FAIL: same.lua must compare equal"; cat "$tmp/o"; fail=1; }
bash "$here/compare_np.sh" --mpirun "$M" --np "1 3" "$G" "$tmp/differs.lua" >"$tmp/o" 2>&1
[ $? -eq 1 ] && grep -q '^+ranks	3' "$tmp/o" || { echo "FAIL: differs.lua must show the diff"; cat "$tmp/o"; fail=1; }
bash "$here/compare_np.sh" --mpirun "$M" --np "1 2" "$G" "$tmp/fails.lua" >"$tmp/o" 2>&1
[ $? -eq 1 ] && grep -q 'two is bad' "$tmp/o" || { echo "FAIL: fails.lua must fail, with its message"; cat "$tmp/o"; fail=1; }
[ $fail -eq 0 ] && echo "compare_np_selftest: 4 passed"
exit $fail
