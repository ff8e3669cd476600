#!/usr/bin/env bash
# Quality on real photographs: CoNUS vs the uniform image of the same pixel count (1/16), PSNR (in
# linear light) of zoomed views of each focus (k = 4) at source resolution and of the whole frame. Photographs come
# from Debian's python3-skimage (installed here if missing). Pictures land in build/quality/<name>/.
set -euo pipefail
cd "$(dirname "$0")/.."
data=/usr/lib/python3/dist-packages/skimage/data
if [ ! -d "$data" ]; then
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo=sudo
  $sudo apt-get install -y -qq --no-install-recommends python3-skimage >/dev/null
fi
[ -x build/bin/conus ] || scripts/setup.sh

run() {  # name file [--importance SRC] focus...   (with --importance the foci only name the views)
  local name=$1 file=$2; shift 2
  local args=()
  if [ "${1:-}" = --importance ]; then args+=(--importance "$2"); shift 2; fi
  for f in "$@"; do args+=(--focus "$f"); done
  echo "== $name ($file)"
  build/bin/conus demo --input "$data/$file" "${args[@]}" --out "build/quality/$name" 2>/dev/null |
    sed -n '/view/,/whole frame/p'
}
run astronaut astronaut.png 0.44,0.23,0.08,4 0.33,0.75,0.06,4
run chelsea chelsea.png 0.37,0.38,0.07,4 0.71,0.45,0.07,4
run motorcycle motorcycle_left.png 0.55,0.62,0.08,4 0.72,0.31,0.05,4
run hubble hubble_deep_field.jpg 0.5,0.5,0.1,4
run astronaut-faces astronaut.png --importance faces 0.44,0.23,0.08,4
run chelsea-detail chelsea.png --importance detail 0.37,0.38,0.07,4 0.71,0.45,0.07,4
