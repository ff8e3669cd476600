#!/usr/bin/env bash
# Set-up command 1: install, build, and run the main job (`conus demo`) on its built-in input.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/bin/conus demo --out "${1:-demo-out}"
