#!/usr/bin/env bash
# The main job, from a fresh Debian 12 machine: installs what is missing, builds the
# host preset and runs `jointguard demo`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
cmake --preset host >/dev/null
cmake --build --preset host --target jointguard
./build/host/jointguard demo --out "${1:-out}"
