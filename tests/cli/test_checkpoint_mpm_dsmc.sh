#!/usr/bin/env bash
# Checkpoints across processes: run N + M steps in one grainlab, or run N and save in one, load
# and run M in another (on 2 threads instead of 1): the printed %a dump of every position and
# velocity must be identical. MPM with frictional contact and noslip, DSMC 2D and 3D with walls.
# usage: test_checkpoint_mpm_dsmc.sh path/to/grainlab   (run from tests/cli)
set -u
G=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0
for engine in mpm_friction mpm_noslip dsmc2 dsmc3; do
  f="$tmp/$engine.ckpt"
  "$G" --quiet --threads 1 ckpt_mpm_dsmc.lua engine=$engine mode=full >"$tmp/full" || failed=1
  "$G" --quiet --threads 1 ckpt_mpm_dsmc.lua engine=$engine mode=save path="$f" || failed=1
  "$G" --quiet --threads 2 ckpt_mpm_dsmc.lua engine=$engine mode=load path="$f" \
    >"$tmp/cont" || failed=1
  lines=$(wc -l <"$tmp/full")
  if [ "$lines" -lt 100 ] || ! cmp -s "$tmp/full" "$tmp/cont"; then
    echo "FAIL: $engine: N + M steps in one process differ from N, save, load in a new" \
      "process, M ($lines lines)"
    diff "$tmp/full" "$tmp/cont" | head -5
    failed=1
  else
    echo "ok: $engine ($lines lines the same)"
  fi
done
# A load that fails exits non-zero with the reason on stderr.
printf 'not a checkpoint' >"$tmp/bad.ckpt"
if "$G" --quiet -e "mpm.load('$tmp/bad.ckpt')" 2>"$tmp/err"; then
  echo "FAIL: loading a bad file succeeded"; failed=1
elif ! grep -q "not a grainlab checkpoint" "$tmp/err"; then
  echo "FAIL: loading a bad file: unexpected message: $(cat "$tmp/err")"; failed=1
else
  echo "ok: a bad file is refused"
fi
exit $failed
