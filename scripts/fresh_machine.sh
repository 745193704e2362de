#!/usr/bin/env bash
# The judge of build.sh's package list: builds a clean Debian 12 (bookworm, minbase) root from
# Debian's archive with mmdebstrap, clones this repository's HEAD into it, and runs the README's
# two commands inside it (chroot) as a new user would on a machine that never had grainlab:
#   ./build.sh demo    then    ./build.sh test      (with --ci: .ci/run, which adds the sanitizers)
# It prints each command's exit status and the test summary, and exits non-zero when either fails.
#
#   scripts/fresh_machine.sh [--ci] [--keep] [--dir DIR] [--mirror URL]
#     --ci      run .ci/run (test + sanitize) in place of `./build.sh test`
#     --keep    leave the root in place afterwards (it is removed by default)
#     --dir     where to build the root (default: a new directory under /var/tmp)
#     --mirror  Debian mirror (default http://deb.debian.org/debian)
#
# Needs root (mmdebstrap's root mode, chroot and bind mounts) and Debian's archive; installs
# mmdebstrap on this machine if it is missing. About 10 minutes on 2 cores (20 with --ci), most of
# it downloading and building. Only committed work is tested: commit before running it. Logs go
# to out/fresh_machine/.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD

ci=0 keep=0 dir="" mirror=http://deb.debian.org/debian
while [ $# -gt 0 ]; do
    case "$1" in
        --ci) ci=1 ;;
        --keep) keep=1 ;;
        --dir) dir=$2; shift ;;
        --mirror) mirror=$2; shift ;;
        -h|--help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "fresh_machine.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    esac
    shift
done

[ "$(id -u)" -eq 0 ] || { echo "fresh_machine.sh: needs root (chroot and mounts)" >&2; exit 2; }
if ! command -v mmdebstrap >/dev/null; then
    echo "fresh_machine.sh: installing mmdebstrap"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mmdebstrap >/dev/null
fi

logs=$repo/out/fresh_machine
mkdir -p "$logs"
[ -n "$dir" ] || dir=$(mktemp -d /var/tmp/grainlab-fresh.XXXXXX)
mkdir -p "$dir"
root=$dir/root
[ ! -e "$root" ] || { echo "fresh_machine.sh: $root exists; give another --dir" >&2; exit 2; }

mounted=()
cleanup() {
    local i
    for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
        umount -l "${mounted[i]}" 2>/dev/null || true
    done
    if [ "$keep" -eq 0 ]; then
        rm -rf --one-file-system "$dir"
    else
        echo "fresh_machine.sh: the root stays in $root"
    fi
}
trap cleanup EXIT

t0=$(date +%s)
echo "fresh_machine.sh: a Debian 12 root (minbase) in $root"
# The suites a Debian 12 machine has: the release, its updates and its security updates.
security=${mirror%/debian}/debian-security
[ "$security" != "$mirror" ] || security=http://deb.debian.org/debian-security
if ! mmdebstrap --mode=root --variant=minbase --include=ca-certificates bookworm "$root" \
        "deb $mirror bookworm main" "deb $mirror bookworm-updates main" \
        "deb $security bookworm-security main" >"$logs/mmdebstrap.log" 2>&1; then
    tail -20 "$logs/mmdebstrap.log" >&2
    echo "fresh_machine.sh: mmdebstrap failed (log: $logs/mmdebstrap.log)" >&2
    exit 1
fi

bind() {  # bind SOURCE TARGET-inside-root [type]
    mkdir -p "$root$2"
    if [ "${3:-}" = tmpfs ]; then
        mount -t tmpfs tmpfs "$root$2"
    else
        mount --bind "$1" "$root$2"
    fi
    mounted+=("$root$2")
}
mount -t proc proc "$root/proc" && mounted+=("$root/proc")
bind /sys /sys
bind /dev /dev
bind /dev/pts /dev/pts
bind tmpfs /dev/shm tmpfs   # Open MPI's shared-memory transport
cp /etc/resolv.conf "$root/etc/resolv.conf"

# A clean clone of HEAD, as a user gets it.
git clone -q "$repo" "$root/root/grainlab"
head=$(git -C "$repo" log -1 --format='%h %s')
echo "fresh_machine.sh: testing $head"

in_root() {  # in_root LOGNAME command... : run in the root's clone, log, return its status
    local name=$1; shift
    local st=0
    chroot "$root" /usr/bin/env -i HOME=/root TERM=dumb LANG=C.UTF-8 \
        PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
        bash -c 'cd /root/grainlab && "$@"' bash "$@" >"$logs/$name.log" 2>&1 || st=$?
    return $st
}

demo=0 tests=0
in_root demo ./build.sh demo || demo=$?
if [ "$ci" -eq 1 ]; then
    in_root test .ci/run || tests=$?
else
    in_root test ./build.sh test || tests=$?
fi

echo
echo "== fresh Debian 12 root, $head"
echo "./build.sh demo: exit $demo ($(grep -c . "$logs/demo.log") lines of output; log $logs/demo.log)"
[ "$demo" -eq 0 ] || tail -15 "$logs/demo.log"
label="./build.sh test"
[ "$ci" -eq 0 ] || label=".ci/run"
echo "$label: exit $tests (log $logs/test.log)"
grep -E 'tests passed|tests failed out of|Total Test time|^\s+[0-9]+ - ' "$logs/test.log" || true
[ "$tests" -eq 0 ] || tail -30 "$logs/test.log"
echo "wall time: $(( $(date +%s) - t0 )) s"
[ "$demo" -eq 0 ] && [ "$tests" -eq 0 ]
