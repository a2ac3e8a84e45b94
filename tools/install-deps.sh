#!/bin/sh
# Install volmorph's build and test dependencies from Debian 12's packages.
# Idempotent: installs only what is missing. As root it runs apt-get itself;
# otherwise it prints the exact command to run and exits non-zero.
set -eu

PACKAGES="build-essential cmake ninja-build pkg-config ccache
libopenvdb-dev libboost-iostreams-dev libembree-dev libopenimageio-dev openimageio-tools
libopenexr-dev libtbb-dev libassimp-dev libtomlplusplus-dev libcli11-dev libnifti2-dev
libeigen3-dev libopenmesh-dev python3-dev libboost-python-dev python3-numpy python3-openimageio libgtest-dev libgmock-dev libbenchmark-dev libopenvdb-tools python3-openvdb
nlohmann-json3-dev libcpp-httplib-dev chromium curl
fonts-dejavu-core clang libclang-rt-14-dev clang-tidy clang-format"

# The editor's page and its browser tests come from npm (tools/editor/web): Node.js and npm from
# Debian unless the machine has them already.
if ! command -v npm >/dev/null 2>&1; then PACKAGES="$PACKAGES nodejs npm"; fi

missing=""
for p in $PACKAGES; do
    status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    case "$status" in
        "install ok installed") ;;
        *) missing="$missing $p" ;;
    esac
done

# three.js (the page) and playwright-core (its tests, driving Debian's chromium) at the versions
# package-lock.json pins; again only when they are missing or the lock file changed.
npm_modules() {
    web=$(dirname "$0")/editor/web
    stamp=$web/node_modules/.package-lock.json
    if [ -f "$stamp" ] && [ ! "$web/package-lock.json" -nt "$stamp" ]; then return 0; fi
    echo "volmorph: installing the editor's npm packages (tools/editor/web)" >&2
    (cd "$web" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
}

if [ -z "$missing" ]; then
    npm_modules
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
npm_modules
