#!/usr/bin/env bash
# Writes the fuzz harnesses' seed corpus (tests/fuzz/corpus/<harness>/) with the tool itself:
# small CoNUS files of every kind the writer makes (compressions, pixel types, map kinds, a height
# field, a tiled part), the small hostile reproducers, and byte strings for the sampling-map
# harness. The seeds are committed; run this again when the format changes.
# Usage: tests/fuzz/make_seeds.sh [BUILD_DIR]   (default build/; needs bin/conus)
set -euo pipefail
cd "$(dirname "$0")/../.."
conus="${1:-build}/bin/conus"
[ -x "$conus" ] || { echo "make_seeds: $conus not built" >&2; exit 1; }
out=tests/fuzz/corpus
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out/container" "$out/sampling_map"

c="$out/container"
"$conus" map foci --focus 0.4,0.5,0.2,2 --grid 9 -o "$c/map-foci.exr" --preview "$work/picture.png" >/dev/null 2>&1
"$conus" map ground --eye-height 1 --near 1 --far 20 --fov 60 --grid 9 -o "$c/map-ground.exr" >/dev/null 2>&1
for compression in none zip piz dwaa; do
  "$conus" encode "$work/picture.png" --size 12x10 --grid 9 --focus 0.4,0.5,0.2,2 --compression $compression \
    -o "$c/encode-$compression.exr" >/dev/null 2>&1
done
"$conus" encode "$work/picture.png" --size 12x10 --grid 9 --focus 0.3,0.3,0.15,2 --focus 0.7,0.6,0.15,2 \
  --compose add --float -o "$c/encode-add-float.exr" >/dev/null 2>&1
"$conus" uniform "$work/picture.png" --size 8x8 -o "$c/uniform.exr" >/dev/null 2>&1
"$conus" heightfield encode procedural:32:3 --size 12x10 --grid 9 -o "$c/heightfield.exr" >/dev/null 2>&1
# A tiled `conus` part (readers accept it; the writer makes scanlines): OpenImageIO and exrmultipart.
if command -v oiiotool >/dev/null && command -v exrmultipart >/dev/null; then
  oiiotool "$c/encode-zip.exr" --subimage 0 --tile 8 8 -o "$work/part0.exr"
  oiiotool "$c/encode-zip.exr" --subimage 1 -o "$work/part1.exr"
  exrmultipart -combine -i "$work/part0.exr" "$work/part1.exr" -o "$c/tiled.exr" >/dev/null
fi
# The hostile reproducers that are small (the large ones are replayed from ../shared/data/hostile).
hostile=../shared/data/hostile
if [ -d "$hostile" ]; then
  for f in "$hostile"/*.exr; do
    if [ "$(stat -c %s "$f")" -le 16384 ]; then install -m 644 "$f" "$c/hostile-$(basename "$f")"; fi
  done
fi

# Sampling-map harness: columns byte, rows byte, mode byte (even: moves of the identity's nodes,
# odd: raw floats), then the data (fuzz_sampling_map.cpp).
python3 - "$out/sampling_map" <<'PY'
import os, random, struct, sys
d = sys.argv[1]
rng = random.Random(15)
def put(name, b):
    open(os.path.join(d, name), "wb").write(bytes(b))
put("identity-9x9", [7, 7, 0])
put("identity-2x2", [0, 0, 0])
put("moves-9x7", [7, 5, 0] + [rng.randrange(256) for _ in range(2 * 9 * 7)])
put("moves-33x33", [31, 31, 0] + [rng.randrange(256) for _ in range(2 * 33 * 33)])
put("moves-extreme-17x5", [15, 3, 0] + [127 if i % 3 else 128 for i in range(2 * 17 * 5)])
raw = [2, 2, 1]
for j in range(4):
    for i in range(4):
        raw += struct.pack("<ff", i / 3, j / 3)
put("raw-identity-4x4", raw)
raw[3 + 8 * 5: 3 + 8 * 5 + 4] = struct.pack("<f", float("nan"))
put("raw-nan-4x4", raw)
PY
du -sh "$out"
