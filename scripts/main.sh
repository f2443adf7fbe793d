#!/usr/bin/env bash
# The main job: install what is missing, build godrays (Release) into build/, and run it on
# the default scene. Run as root on a fresh Debian bookworm: ./scripts/main.sh
set -euo pipefail
cd "$(dirname "$0")/.."

SCENE=${1:-data/scenes/default.json}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}

./scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$JOBS"

# ---- the main job: ground truth (cached after the first run) + every real-time technique + leaderboard report ----
build/godrays run "$SCENE"

build/godrays info
