#!/usr/bin/env bash
# Installs everything the project needs on Debian 12 and fetches the MeshLab
# 2020.09 plugin SDK (src/common + vcglib from Debian's meshlab source package)
# into .deps/. Idempotent: a second run checks and returns in about a second.
# It never edits the system's apt sources: the source index lives in .deps/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
deps="$root/.deps"
step() { printf '[setup] %s\n' "$*" >&2; }
fail() { printf '[setup] FAILED at step "%s": %s\n' "$1" "$2" >&2; exit 1; }

packages=(
  build-essential cmake ninja-build ccache pkg-config dpkg-dev
  clang libclang-rt-14-dev llvm
  meshlab qtbase5-dev libqt5opengl5-dev libqt5xmlpatterns5-dev libglew-dev libeigen3-dev
  libembree-dev libglm-dev libopenmesh-dev libtbb-dev libnanoflann-dev
  libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev libcli11-dev libpng-dev
  xvfb xauth imagemagick xdotool x11-utils
  python3 python3-numpy python3-matplotlib
  openmpi-bin libopenmpi-dev slurm-wlm munge
)

# 1. Debian packages: install only what is missing.
missing=()
for p in "${packages[@]}"; do
  s=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$s" == "install ok installed" ]] || missing+=("$p")
done
if ((${#missing[@]})); then
  step "installing ${#missing[@]} Debian packages: ${missing[*]}"
  if [[ $(id -u) -ne 0 ]]; then sudo=sudo; else sudo=; fi
  $sudo apt-get update -qq || fail "apt-get update" "could not read the package index"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null \
    || fail "apt-get install" "could not install: ${missing[*]}"
else
  step "Debian packages: all ${#packages[@]} present"
fi

# 2. MeshLab plugin SDK from the source package matching the installed binary.
version=$(dpkg-query -W -f='${Version}' meshlab 2>/dev/null) || fail "meshlab version" "meshlab is not installed"
sdk="$deps/meshlab-sdk"
if [[ -f "$sdk/.version" && "$(cat "$sdk/.version")" == "$version" ]]; then
  step "MeshLab SDK $version present in .deps/meshlab-sdk"
  exit 0
fi
step "fetching MeshLab $version source package (plugin SDK)"
work="$deps/apt-src"
rm -rf "$work" "$sdk"
mkdir -p "$work/parts" "$work/lists/partial" "$work/download"
# A private source list derived from the system's own binary entries.
found=0
for f in /etc/apt/sources.list.d/*.sources; do
  [[ -f "$f" ]] || continue
  sed 's/^Types:.*$/Types: deb-src/' "$f" > "$work/parts/$(basename "$f")"; found=1
done
if [[ $found -eq 0 && -f /etc/apt/sources.list ]]; then
  grep -E '^deb ' /etc/apt/sources.list | sed 's/^deb /deb-src /' > "$work/parts/src.list" || true
  [[ -s "$work/parts/src.list" ]] && found=1
fi
[[ $found -eq 1 ]] || fail "source list" "no apt source entries found in /etc/apt"
aptopts=(-o Dir::Etc::SourceList=/dev/null -o "Dir::Etc::SourceParts=$work/parts"
         -o "Dir::State::Lists=$work/lists" -o APT::Sandbox::User=root)
apt-get "${aptopts[@]}" update -qq >/dev/null 2>"$work/update.log" \
  || fail "apt-get update (sources)" "$(tail -1 "$work/update.log")"
(cd "$work/download" && apt-get "${aptopts[@]}" source --download-only -qq "meshlab=$version" >/dev/null 2>"$work/source.log") \
  || fail "apt-get source meshlab=$version" "$(tail -1 "$work/source.log")"
dsc=$(ls "$work/download"/meshlab_*.dsc 2>/dev/null | head -1)
[[ -n "$dsc" ]] || fail "source package" "no .dsc downloaded"
src_version=$(sed -n 's/^Version: //p' "$dsc")
[[ "$src_version" == "$version" ]] || fail "version check" "source $src_version != installed meshlab $version"
step "unpacking and patching (dpkg-source)"
dpkg-source --no-check -x "$dsc" "$work/src" >/dev/null 2>"$work/unpack.log" \
  || fail "dpkg-source -x" "$(tail -1 "$work/unpack.log")"
mkdir -p "$sdk/src"
cp -a "$work/src/src/common" "$sdk/src/common"
cp -a "$work/src/vcglib" "$sdk/vcglib"
cp -a "$work/src/ML_VERSION" "$sdk/" 2>/dev/null || true
echo "$version" > "$sdk/.version"
rm -rf "$work"
step "MeshLab SDK $version ready in .deps/meshlab-sdk"
