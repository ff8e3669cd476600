#!/usr/bin/env bash
# Installs every Debian package CoNUS uses (a fast no-op when all are present) and builds the
# project into build/ (Release, Ninja); with --packages-only, only the first. Safe to run again at
# any time.
set -euo pipefail
cd "$(dirname "$0")/.."

mapfile -t packages < <(grep -v '^\s*#' scripts/packages.txt | sed '/^\s*$/d')
scripts/install-packages.sh setup "${packages[@]}"

if [ "${1:-}" = "--packages-only" ]; then exit 0; fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --parallel "$(nproc)"
