#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: installs what is needed, builds,
# and runs the whole test suite (unit, meshlabserver and GUI tests) with ctest.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_BUILD_DIR:-$root/build}"
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
cd "$build"
ctest --output-on-failure -j "${GI_TEST_JOBS:-2}" "$@"
