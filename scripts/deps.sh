#!/bin/sh
# Installs the Debian packages cdem-c needs, only when some are missing.
# Idempotent and quiet when everything is present. Must run as root (or with sudo).
set -eu
# clang, libclang-rt-14-dev (libFuzzer + sanitizer runtimes) and libomp-14-dev (OpenMP for
# clang) are for `make fuzz` only (tests/fuzz/README.md).
PKGS="gcc make pkg-config libhdf5-dev zlib1g-dev hdf5-tools libgsl-dev libcairo2-dev libcmocka-dev \
libgif-dev libxml2-utils python3 python3-numpy python3-scipy python3-h5py \
clang libclang-rt-14-dev libomp-14-dev \
    python3-pil"  # python3-pil: examples/montage.py tiles the example figures
missing=""
for p in $PKGS; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
[ -z "$missing" ] && exit 0
echo "deps: installing:$missing"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
