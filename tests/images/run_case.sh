#!/bin/sh
# Runs one image-diff case: tests/images/CASE/run.sh writes images into $OUT; each reference
# CASE/ref/NAME is compared with $OUT/NAME by `volmorph diff` with the flags in CASE/thresholds
# (idiff's: --fail, --failpercent, --hardfail, --warn, ...). A warning passes, with its report.
# usage: run_case.sh VOLMORPH SOURCE_DIR CASE_DIR [--update]
#   --update rewrites CASE/ref from this build: only with an independent justification in the
#   commit message (see README, "Image-diff tests").
set -eu
VOLMORPH=$1 SOURCE=$2 case=$3 mode=${4:-}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
export VOLMORPH SOURCE OUT VOLMORPH_CACHE="$OUT/cache"

sh "$case/run.sh"
if [ "$mode" = --update ]; then
    mkdir -p "$case/ref"
    for f in "$OUT"/*.exr; do cp "$f" "$case/ref/"; echo "updated $case/ref/$(basename "$f")"; done
    exit 0
fi
thresholds=$(grep -v '^#' "$case/thresholds" | tr '\n' ' ')
[ -n "$(ls "$case/ref")" ] || { echo "$case/ref holds no reference"; exit 1; }
status=0
for ref in "$case"/ref/*.exr; do
    name=$(basename "$ref")
    set +e
    # shellcheck disable=SC2086
    "$VOLMORPH" diff $thresholds "$ref" "$OUT/$name" >"$OUT/report" 2>&1
    code=$?
    set -e
    case $code in
        0) echo "$name: PASS" ;;
        1) echo "$name: WARNING"; cat "$OUT/report" ;;
        *) echo "$name: FAILURE (volmorph diff status $code)"; cat "$OUT/report"; status=1 ;;
    esac
done
exit $status
