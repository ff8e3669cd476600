#!/usr/bin/env bash
# End-to-end speed of the `conus` program, next to `oiiotool` measured in the same run:
# start-up, a 4096^2 -> 1024^2 encode, a 1920x1080 decode to PNG and to EXR, the brush
# (`map springs`) to its stable state, and the encode on one core vs two.
#
#   bench/end_to_end.sh [build-dir] [runs]      (defaults: build, 5)
#
# Each row is the median of `runs` runs of /usr/bin/time: wall seconds, CPU seconds (user + sys)
# and peak resident memory; the ratio column is CPU time against the oiiotool row named beside
# it. CPU time is what a shared machine disturbs least; wall time is shown for the thread rows.
# The encode runs with its defaults (fitted to the decoder, the loss budget) and with --fast (the
# filtered encode alone): the difference is what the fit costs.
# The input is a real photograph (scikit-image's astronaut, Debian python3-skimage) enlarged to
# 4096^2 with film-grain noise so that its PNG is as hard to decode as a photograph that size
# (32 MB).
set -euo pipefail

build=${1:-build}
runs=${2:-5}
conus="$build/bin/conus"
[[ -x $conus ]] || { echo "end_to_end.sh: $conus not found (build first)" >&2; exit 1; }
command -v oiiotool >/dev/null || { echo "end_to_end.sh: oiiotool not found (Debian openimageio-tools)" >&2; exit 1; }
photo=/usr/lib/python3/dist-packages/skimage/data/astronaut.png
[[ -f $photo ]] || { echo "end_to_end.sh: $photo not found (Debian python3-skimage)" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
big=$work/photo4096.png
oiiotool "$photo" --resize 4096x4096 --noise:type=gaussian:mean=0:stddev=0.02 -d uint8 -o "$big"
"$conus" encode "$big" -o "$work/view_source.exr" --size 2048x2048 --focus 0.5,0.4,0.1,3 -q
strokes='[{"u":0.35,"v":0.4,"radius":0.15,"strength":4,"duration":0.3},{"u":0.65,"v":0.6,"radius":0.1,"strength":3,"duration":0.3},{"u":0.5,"v":0.8,"radius":0.08,"strength":4,"duration":0.2}]'

# measure NAME COMMAND...: prints "NAME wall cpu rssMiB" (medians over $runs runs).
measure() {
    local name=$1
    shift
    local i samples=()
    for ((i = 0; i < runs; ++i)); do
        /usr/bin/time -f "%e %U %S %M" -o "$work/time" "$@" >/dev/null 2>&1 || { echo "end_to_end.sh: '$*' failed" >&2; exit 1; }
        samples+=("$(awk '{printf "%.3f %.3f %.1f", $1, $2 + $3, $4 / 1024}' "$work/time")")
    done
    printf '%s\n' "${samples[@]}" | awk -v name="$name" '
        { wall[NR] = $1; cpu[NR] = $2; rss[NR] = $3 }
        function median(a, n,   i, j, t) {
            for (i = 1; i <= n; ++i) for (j = i + 1; j <= n; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
            return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
        }
        END { printf "%s %.3f %.3f %.1f\n", name, median(wall, NR), median(cpu, NR), median(rss, NR) }'
}

results=$work/results
{
    measure oiiotool-help oiiotool --help
    measure conus-help "$conus" --help
    measure conus-info "$conus" info "$work/view_source.exr"
    measure oiiotool-resize oiiotool "$big" --resize:filter=box 1024x1024 -o "$work/resized.png"
    measure conus-encode "$conus" encode "$big" -o "$work/encoded.exr" --size 1024x1024 --focus 0.5,0.4,0.1,3 -q
    measure conus-encode-fast "$conus" encode "$big" -o "$work/encoded.exr" --size 1024x1024 --focus 0.5,0.4,0.1,3 --fast -q
    measure oiiotool-resize-1core taskset -c 0 oiiotool "$big" --resize:filter=box 1024x1024 -o "$work/resized.png"
    measure conus-encode-1core taskset -c 0 "$conus" encode "$big" -o "$work/encoded.exr" --size 1024x1024 --focus 0.5,0.4,0.1,3 -q
    measure oiiotool-view-png oiiotool "$work/view_source.exr" --resize 1920x1080 -o "$work/view.png"
    measure conus-decode-png "$conus" decode "$work/view_source.exr" -o "$work/view.png" --size 1920x1080 -q
    measure conus-decode-exr "$conus" decode "$work/view_source.exr" -o "$work/view.exr" --size 1920x1080 -q
    measure conus-springs "$conus" map springs --strokes "$strokes" -o "$work/springs.exr" -q
} >"$results"

awk '
    { wall[$1] = $2; cpu[$1] = $3; rss[$1] = $4; order[NR] = $1 }
    END {
        base["conus-help"] = "oiiotool-help"; base["conus-info"] = "oiiotool-help"
        base["conus-encode"] = "oiiotool-resize"; base["conus-encode-fast"] = "oiiotool-resize"
        base["conus-encode-1core"] = "oiiotool-resize-1core"
        base["conus-decode-png"] = "oiiotool-view-png"; base["conus-decode-exr"] = "oiiotool-view-png"
        printf "| %-22s | %8s | %8s | %9s | %-32s |\n", "run", "wall s", "CPU s", "peak MiB", "wall, CPU and peak memory vs oiiotool"
        printf "|%s|%s|%s|%s|%s|\n", "------------------------", "----------", "----------", "-----------", "----------------------------------"
        for (i = 1; i <= NR; ++i) {
            n = order[i]; vs = ""
            if (n in base) vs = sprintf("%.2fx wall, %.2fx CPU, %.2fx memory (%s)", wall[n] / wall[base[n]], cpu[n] / cpu[base[n]], rss[n] / rss[base[n]], base[n])
            printf "| %-22s | %8.3f | %8.3f | %9.1f | %-32s |\n", n, wall[n], cpu[n], rss[n], vs
        }
        printf "\nthreads, end to end (wall, 1 core / 2 cores): conus encode %.2fx, oiiotool resize %.2fx\n",
               wall["conus-encode-1core"] / wall["conus-encode"], wall["oiiotool-resize-1core"] / wall["oiiotool-resize"]
    }' "$results"

# The encode's stages (its own stage lines, "conus encode: <stage> done (0.21 s)"), each the median
# over $runs runs, against the oiiotool resize's wall time measured above and against the encode
# kernel's ("encode ..." stage): where the time goes, as ratios read off one run.
stages() {
    local name=$1
    shift
    local i
    for ((i = 0; i < runs; ++i)); do
        "$conus" encode "$big" -o "$work/staged.exr" --size 1024x1024 --focus 0.5,0.4,0.1,3 "$@" 2>&1 >/dev/null |
            tr '\r' '\n' | sed -n 's/^conus encode: \(.*\) done (\([0-9.]*\) s).*/\1\t\2/p' |
            awk -F'\t' -v run="$i" '{ split($1, w, " "); printf "%s\t%s\t%s\n", run, w[1] (w[2] == "to" ? " to" : ""), $2 }'
    done | awk -F'\t' -v name="$name" -v resize="$(awk '$1 == "oiiotool-resize" { print $2 }' "$results")" '
        { key = $2; if (!(key in n)) order[++stages] = key; v[key, ++n[key]] = $3 }
        function median(k, m,   i, j, t, a) {
            for (i = 1; i <= m; ++i) a[i] = v[k, i]
            for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
            return m % 2 ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
        }
        END {
            for (s = 1; s <= stages; ++s) { k = order[s]; med[k] = median(k, n[k]); if (k == "encode") kernel = med[k] }
            printf "\n%s: stage, median wall s, vs oiiotool resize wall, vs the encode kernel\n", name
            for (s = 1; s <= stages; ++s) {
                k = order[s]
                vs = kernel > 0 ? sprintf("%6.2fx", med[k] / kernel) : "-"
                printf "| %-10s | %7.3f | %6.2fx | %s |\n", k, med[k], med[k] / resize, vs
            }
        }'
}
stages "conus encode (defaults)"
stages "conus encode --fast" --fast
