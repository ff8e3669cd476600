#!/usr/bin/env bash
# Set-up command 2: install, build, and run the whole test suite (ctest). CI calls exactly this.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
ctest --test-dir build --output-on-failure --parallel "$(nproc)" --timeout 900
