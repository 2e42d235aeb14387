#!/usr/bin/env bash
# Configures and builds the project in build/ (Release, ccache, Ninja).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_BUILD_DIR:-$root/build}"
jobs="${GI_JOBS:-$(nproc)}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null \
  || { echo "[build] FAILED: cmake configure (see above)" >&2; exit 1; }
cmake --build "$build" -j "$jobs" || { echo "[build] FAILED: compilation" >&2; exit 1; }
echo "[build] done: $build" >&2
