#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: installs what is needed, builds,
# and runs the whole test suite with ctest: unit, meshlabserver and GUI tests
# in build/, then the checking build in build-san/ (clang, AddressSanitizer +
# UndefinedBehaviorSanitizer: unit tests and hostile-input test, label
# 'sanitize'; the readers' libFuzzer target for a bounded run, label 'fuzz').
# GI_SANITIZE=0 skips the checking build. Arguments go to both ctest runs.
# build/ is configured with the MPI option (GI_MPI=0 leaves it off), so that
# `mpirun -np 1, 2, 4 gi ...` is tested against the plain run; the Slurm test
# starts its own single-node Slurm (munged, slurmctld, slurmd) and stops it.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${GI_BUILD_DIR:-$root/build}"
san="${GI_SAN_BUILD_DIR:-$root/build-san}"
jobs="${GI_JOBS:-$(nproc)}"
bash "$root/scripts/setup.sh"
mpi=$([[ "${GI_MPI:-1}" != 0 ]] && echo ON || echo OFF)
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGI_MPI="$mpi" >/dev/null \
  || { echo "[test] FAILED: cmake configure with GI_MPI=$mpi" >&2; exit 1; }
bash "$root/scripts/build.sh"
if [[ "${GI_SANITIZE:-1}" != 0 ]]; then
  cmake -S "$root" -B "$san" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
        -DGI_SANITIZE=ON -DGI_FUZZ=ON -DGI_BUILD_MESHLAB=OFF -DGI_BUILD_BENCH=OFF >/dev/null \
    || { echo "[test] FAILED: cmake configure of the sanitizer build" >&2; exit 1; }
  cmake --build "$san" -j "$jobs" || { echo "[test] FAILED: sanitizer build" >&2; exit 1; }
fi
status=0
(cd "$build" && ctest --output-on-failure -j "${GI_TEST_JOBS:-2}" "$@") || status=1
if [[ "${GI_SANITIZE:-1}" != 0 ]]; then
  (cd "$san" && ctest --output-on-failure -j "${GI_TEST_JOBS:-2}" "$@") || status=1
fi
exit $status
