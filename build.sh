#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine: install what grainlab needs, build, then
#   ./build.sh demo       run the main job (scripts/demo.lua)
#   ./build.sh test       run the whole test suite (ctest)
#   ./build.sh sanitize   build with AddressSanitizer + UBSan into build-asan/ and run the suite;
#                         that build runs the hot kernels' baseline code only (GRAINLAB_CLONES=OFF)
#                         and checks its bits against build/'s AVX2 clones (isa_same_bits)
#   ./build.sh build      only install and build
set -euo pipefail
cd "$(dirname "$0")"

# Debian packages: compiler and build tools, the libraries grainlab links, jq (tests read
# report JSON with it), python3-vtk9 and python3-numpy (tests open the VTK files with VTK's
# readers, whose array access needs numpy, a package --no-install-recommends leaves out) and
# Open MPI (distributed runs: mpirun -np K grainlab script.lua), universal-ctags (the test
# src_lengths measures functions with it), libc6-dbg (glibc's symbols: the sanitizer build's
# leak reports name glibc's frames, and the MPI tests' suppressions of Open MPI's allocations
# made through asprintf match them). scripts/fresh_machine.sh checks this list on a clean
# Debian 12 root.
packages=(build-essential cmake pkg-config liblua5.4-dev libreadline-dev libosmesa6-dev
          libpng-dev libfreetype-dev fonts-dejavu-core libcmocka-dev jq libqhull-dev
          python3-vtk9 python3-numpy libopenmpi-dev openmpi-bin universal-ctags libc6-dbg)

install_packages() {
    local missing=()
    for p in "${packages[@]}"; do
        # ParaView's python3-paraview provides the same `vtk` module and conflicts with
        # python3-vtk9: installing the latter would remove ParaView.
        [ "$p" = python3-vtk9 ] && dpkg-query -W -f='${Status}' python3-paraview 2>/dev/null |
            grep -q 'install ok installed' && continue
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    echo "build.sh: installing Debian packages: ${missing[*]}"
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    local log
    log=$(mktemp)
    if ! { $sudo apt-get update -qq &&
           DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
               "${missing[@]}"; } >"$log" 2>&1; then
        cat "$log" >&2
        echo "build.sh: could not install ${missing[*]} (see the apt output above)" >&2
        rm -f "$log"
        exit 1
    fi
    rm -f "$log"
}

jobs=$(nproc 2>/dev/null || echo 2)

build() {  # build DIR [cmake options…]
    local dir=$1; shift
    cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DGRAINLAB_WERROR=ON "$@" >/dev/null
    cmake --build "$dir" -j "$jobs"
}

cmd=${1:-build}
[ $# -gt 0 ] && shift
install_packages
case "$cmd" in
    build)    build build ;;
    demo)     build build && ./build/grainlab scripts/demo.lua "$@" ;;
    test)     build build && ctest --test-dir build --output-on-failure -j "$jobs" "$@" ;;
    sanitize) build build &&
              build build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGRAINLAB_SANITIZE=ON \
                  -DGRAINLAB_CLONES=OFF -DGRAINLAB_BITS_REFERENCE="$PWD/build/grainlab" &&
              ctest --test-dir build-asan --output-on-failure -j "$jobs" "$@" ;;
    *) echo "usage: ./build.sh [build|demo|test|sanitize]" >&2; exit 2 ;;
esac
