#!/usr/bin/env bash
# Our plugins for MeshLab 2025.07, from a fresh Debian 12 clone:
#
#   bash scripts/build_meshlab2025.sh          set up, build MeshLab 2025.07 (cached) and the plugins
#   bash scripts/build_meshlab2025.sh --test   ... then run the GUI tests in MeshLab 2025.07 (ctest -L gui2025)
#
# Runs scripts/setup.sh (Debian packages), scripts/setup_meshlab2025.sh (MeshLab
# 2025.07's sources and a build of its GUI and PLY reader, cached in
# GI_MESHLAB2025_HOME, default .deps/meshlab-2025.07), then configures build-ml2025/
# with -DGI_MESHLAB_TARGET=2025.07 and builds the plugins and a staged MeshLab
# (build-ml2025/stage/bin/meshlab with our plugins). Other arguments after
# --test go to ctest. GI_JOBS=N limits parallel jobs.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_ML2025_BUILD_DIR:-$root/build-ml2025}"
home="${GI_MESHLAB2025_HOME:-$root/.deps/meshlab-2025.07}"
jobs="${GI_JOBS:-$(nproc)}"
test=0
if [[ "${1:-}" == "--test" ]]; then test=1; shift; fi

bash "$root/scripts/setup.sh"
GI_MESHLAB2025_HOME="$home" bash "$root/scripts/setup_meshlab2025.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGI_MESHLAB_TARGET=2025.07 \
      -DGI_MESHLAB2025_HOME="$home" -DGI_BUILD_BENCH=OFF >/dev/null \
  || { echo "[build-2025] FAILED: cmake configure (see above)" >&2; exit 1; }
# The plugins, the staged MeshLab and the CLI (the gui2025 tests compare the
# meshes MeshLab writes with the CLI's); the engine's unit tests are build/'s.
cmake --build "$build" -j "$jobs" --target stage_meshlab gi || { echo "[build-2025] FAILED: compilation" >&2; exit 1; }
echo "[build-2025] done: plugins in $build/plugins, MeshLab 2025.07 with them: $build/stage/bin/meshlab" >&2
if ((test)); then
  cd "$build" && exec ctest --output-on-failure -L gui2025 "$@"
fi
