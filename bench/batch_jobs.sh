#!/usr/bin/env bash
# Batch conversion of photographs: a shell loop of single encodes against `conus encode --out-dir
# --jobs N`, in the same run, with the defaults and with --fast; photos an hour, CPU seconds a
# photo and the gain of each batch over the loop.
#
#   bench/batch_jobs.sh [build-dir] [folder of .jpg] [extra encode options...]
#
# Without a folder, eight 3000x2000 JPEGs are made from Debian's wallpapers (lomiri-wallpapers,
# scripts/packages.txt) with oiiotool. CPU seconds are user + sys of the whole run (/usr/bin/time).
set -euo pipefail

build=${1:-build}
shots=${2:-}
shift $(($# > 2 ? 2 : $#))
conus="$build/bin/conus"
[[ -x $conus ]] || { echo "batch_jobs.sh: $conus not found (build first)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [[ -z $shots ]]; then
    shots=$work/shots
    mkdir -p "$shots"
    i=0
    for f in /usr/share/backgrounds/{Bridge_by_Sander_Klootwijk,Dragonfly_by_Bolly,Fossa_by_Jasper_Roks,Kleiber_by_Lukas_Baubkus,Wine_by_Jakkub_Mede,friends_by_Aitzol_Berasategi,sunset_by_Aitzol_Berasategi,life_by_Aitzol_Berasategi}.jpg; do
        i=$((i + 1))
        oiiotool "$f" --fit:fillmode=height 3000x2000 --cut 3000x2000 -d uint8 --attrib Compression jpeg:92 -o "$shots/p$i.jpg"
    done
fi
photos=("$shots"/*.jpg)
n=${#photos[@]}

# timed NAME COMMAND...: "NAME wall cpu photos/hour"
timed() {
    local name=$1
    shift
    rm -rf "$work/out"
    mkdir -p "$work/out"
    /usr/bin/time -f "%e %U %S" -o "$work/time" "$@" >/dev/null 2>&1 || { echo "batch_jobs.sh: $name failed" >&2; exit 1; }
    awk -v name="$name" -v n="$n" '{ printf "%s %.2f %.2f %.0f\n", name, $1, $2 + $3, 3600 * n / $1 }' "$work/time"
}
# The shell loop a user would write: one `conus encode` a photo, one after the other.
cat >"$work/loop.sh" <<EOF
for f in "$shots"/*.jpg; do "$conus" encode "\$f" -o "$work/out/\$(basename "\${f%.*}").exr" -q "\$@"; done
EOF

results=$work/results
for mode in defaults fast; do
    opts=("$@")
    [[ $mode == fast ]] && opts+=(--fast)
    timed "$mode:loop" bash "$work/loop.sh" "${opts[@]}"
    timed "$mode:jobs1" "$conus" encode "${photos[@]}" --out-dir "$work/out" --jobs 1 -q "${opts[@]}"
    timed "$mode:jobs2" "$conus" encode "${photos[@]}" --out-dir "$work/out" --jobs 2 -q "${opts[@]}"
done >"$results"

echo "$n photos of $(oiiotool --info "${photos[0]}" | sed 's/.*: \([0-9]* x [0-9]*\).*/\1/'), $(nproc) cores, load before: $(cut -d' ' -f1-3 /proc/loadavg)"
awk -v n="$n" '
    { split($1, k, ":"); wall[$1] = $2; cpu[$1] = $3; rate[$1] = $4; order[NR] = $1; loopOf[$1] = k[1] ":loop" }
    END {
        printf "| run | wall s | CPU s | CPU s a photo | photos an hour | vs the shell loop |\n|---|---|---|---|---|---|\n"
        for (i = 1; i <= NR; ++i) {
            r = order[i]
            printf "| %s | %.2f | %.2f | %.2f | %.0f | %.2fx |\n", r, wall[r], cpu[r], cpu[r] / n, rate[r], wall[loopOf[r]] / wall[r]
        }
    }' "$results"
