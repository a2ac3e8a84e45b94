#!/bin/sh
# volmorph diff agrees with OpenImageIO's idiff, verdict and exit code, on pairs that pass, warn,
# fail (by count, by percentage, by one hard outlier), differ in size or channels, are missing or
# are not images, with the same thresholds given to both.
# usage: diff_vs_idiff.sh VOLMORPH
set -eu
volmorph=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"

# ref: a gradient; near: +0.002 everywhere; spot: one pixel off by 0.5; big: 64x48; rgba: 4 channels.
oiiotool --pattern fill:topleft=0,0,0:topright=1,0,0:bottomleft=0,1,0:bottomright=0,0,1 64x32 3 -d float -o ref.exr
oiiotool ref.exr --addc 0.002,0.002,0.002 -d float -o near.exr
oiiotool ref.exr --pattern constant:color=0.5,0.5,0.5 1x1 3 --origin +10+7 --add -d float -o spot.exr
oiiotool --pattern fill:topleft=0,0,0:topright=1,0,0:bottomleft=0,1,0:bottomright=0,0,1 64x48 3 -d float -o big.exr
oiiotool ref.exr --ch R,G,B,A=1.0 -d float -o rgba.exr
head -c 300 ref.exr > truncated.exr
echo "not an image" > garbage.exr

cases=0
check() { # idiff-style flags..., then A B
    cases=$((cases + 1))
    set +e
    idiff "$@" >idiff.log 2>&1; want=$?
    n=$#; i=0; long=""
    for a in "$@"; do # the same flags, spelled with two dashes
        i=$((i + 1))
        case "$a" in -o|-od|-abs|-scale|-q|-v) long="$long $a" ;; -*) long="$long -$a" ;; *) long="$long $a" ;; esac
    done
    # shellcheck disable=SC2086
    "$volmorph" diff $long >mine.log 2>&1; got=$?
    set -e
    if [ "$got" != "$want" ]; then
        echo "volmorph diff$long -> $got, idiff $* -> $want"; cat idiff.log mine.log; exit 1
    fi
    verdict_i=$(grep -E '^(PASS|WARNING|FAILURE)$' idiff.log || true)
    verdict_m=$(grep -E '^(PASS|WARNING|FAILURE)$' mine.log || true)
    [ "$verdict_i" = "$verdict_m" ] || { echo "verdicts differ for $*: '$verdict_i' vs '$verdict_m'"; exit 1; }
    echo "  $* -> $got $verdict_m"
}

check ref.exr ref.exr                                                   # pass
check ref.exr near.exr                                                  # fail (default 1e-6)
check -fail 0.01 -warn 0.001 ref.exr near.exr                           # pass: warnings alone (idiff 2.4)
check -fail 0.001 -failpercent 100 -warn 0.0001 ref.exr near.exr        # warn: tolerated failures
check -fail 0.01 -warn 0.01 ref.exr near.exr                            # pass
check -fail 0.01 -warn 0.001 -warnpercent 100 ref.exr near.exr          # pass (all warnings allowed)
check -fail 0.01 ref.exr spot.exr                                       # fail: one pixel
check -fail 0.01 -failpercent 1 ref.exr spot.exr                        # pass or warn: 1 of 2048 allowed
check -fail 0.01 -failpercent 1 -warn 1 ref.exr spot.exr
check -fail 0.01 -failpercent 1 -hardfail 0.25 ref.exr spot.exr         # fail: hard outlier
check -fail 0.01 -failpercent 1 -warn 1 -hardwarn 0.25 ref.exr spot.exr # warn: hard outlier
check -fail 0.01 -allowfailures 1 ref.exr spot.exr                      # pass: one allowed
check -fail 0.001 -failrelative 0.5 ref.exr near.exr                    # relative thresholds
check ref.exr big.exr                                                   # size mismatch
check big.exr ref.exr
check ref.exr rgba.exr                                                  # channel mismatch
check ref.exr missing.exr                                               # file errors
check missing.exr ref.exr
check ref.exr truncated.exr
check ref.exr garbage.exr

# The difference image: written atomically, |A - B| scaled.
"$volmorph" diff ref.exr spot.exr --fail 0.01 -o d.exr --abs --scale 2 >/dev/null || true
oiiotool --stats d.exr | grep -q "Max: 1.0" || { echo "difference image wrong:"; oiiotool --stats d.exr; exit 1; }
"$volmorph" diff ref.exr ref.exr -o same.exr --od >/dev/null
[ ! -e same.exr ] || { echo "--od wrote an image for identical inputs"; exit 1; }
echo "diff: $cases cases agree with idiff"
