#!/bin/sh
# Install volmorph's build and test dependencies from Debian 12's packages.
# Idempotent: installs only what is missing. As root it runs apt-get itself;
# otherwise it prints the exact command to run and exits non-zero.
set -eu

PACKAGES="build-essential cmake ninja-build pkg-config ccache
libopenvdb-dev libboost-iostreams-dev libembree-dev libopenimageio-dev openimageio-tools
libopenexr-dev libtbb-dev libassimp-dev libtomlplusplus-dev libcli11-dev libnifti2-dev
libeigen3-dev libgtest-dev libgmock-dev libbenchmark-dev libopenvdb-tools python3-openvdb
fonts-dejavu-core clang libclang-rt-14-dev clang-tidy clang-format"

missing=""
for p in $PACKAGES; do
    status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    case "$status" in
        "install ok installed") ;;
        *) missing="$missing $p" ;;
    esac
done

if [ -z "$missing" ]; then
    exit 0
fi

cmd="apt-get install -y --no-install-recommends$missing"
if [ "$(id -u)" -ne 0 ]; then
    echo "volmorph: missing Debian packages; run as root:" >&2
    echo "  apt-get update && $cmd" >&2
    exit 1
fi

echo "volmorph: installing:$missing" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
# shellcheck disable=SC2086
apt-get install -y -qq --no-install-recommends $missing >/dev/null
