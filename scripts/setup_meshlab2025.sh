#!/usr/bin/env bash
# Fetches MeshLab 2025.07's sources (Debian's source package meshlab
# 2025.07~dfsg-N from unstable, which holds MeshLab's and vcglib's sources) and
# builds what our plugins need to load and be tested: libmeshlab-common, the
# GUI (meshlab) and the PLY reader (io_base), not MeshLab's other plugins.
#
#   bash scripts/setup_meshlab2025.sh            (GI_JOBS=N: parallel jobs, default nproc)
#   bash scripts/setup_meshlab2025.sh --sources  only fetch and unpack the sources (seconds): what
#                                                the default build's compile check of the 2025.07
#                                                adapter needs (scripts/setup.sh runs this)
#
# Everything goes to GI_MESHLAB2025_HOME (default .deps/meshlab-2025.07, git-ignored):
#   meshlab/            the sources (meshlab/src holds common/ and vcglib/: the SDK)
#   build/src/distrib/  meshlab, libmeshlab-common.so, plugins/libio_base.so, shaders/
#   .stamp              the version and build settings of a finished build
# A second run with the same version and settings checks the stamp and returns
# at once. Compilation goes through ccache when it is installed.
#
# The source index lives in a private apt state (a deb-src entry for suite sid,
# the archive URL taken from the system's own apt sources): the system's apt
# configuration is not changed. Needs the Debian packages of scripts/setup.sh
# (run first by scripts/build_meshlab2025.sh).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
home="${GI_MESHLAB2025_HOME:-$root/.deps/meshlab-2025.07}"
jobs="${GI_JOBS:-$(nproc)}"
sources_only=0
if [[ "${1:-}" == "--sources" ]]; then sources_only=1; fi
# Debian's source packages 2025.07~dfsg-N (N = 4 when this was written) share one
# upstream tarball; sid keeps only its newest revision, so any N is taken and the
# cache is keyed by the tarball's version, not by N.
orig="2025.07~dfsg"        # Debian's upstream version: the tarball meshlab_2025.07~dfsg.orig.tar.xz
upstream="2025.07"         # MeshLab's version (ML_VERSION), what plugins are checked against
step() { printf '[setup-2025] %s\n' "$*" >&2; }
fail() { printf '[setup-2025] FAILED at step "%s": %s\n' "$1" "$2" >&2; exit 1; }

# What MeshLab is built with; a change rebuilds (the stamp holds it).
cmake_args=(
  -G Ninja -DCMAKE_BUILD_TYPE=Release
  -DMESHLAB_BUILD_MINI=ON                       # common + GUI; plugins only those named below
  -DMESHLAB_PLUGINS=meshlabplugins/io_base      # PLY, OBJ, OFF, STL ... readers and writers
  -DMESHLAB_ALLOW_BUNDLED_SOURCE_GLEW=OFF       # Debian's GLEW
)
targets=(meshlab io_base copy-distrib-files)
settings="$orig ${cmake_args[*]} ${targets[*]}"
distrib="$home/build/src/distrib"
if ((!sources_only)) && [[ -f "$home/.stamp" && "$(cat "$home/.stamp")" == "$settings" && -x "$distrib/meshlab" ]]; then
  step "MeshLab $upstream present in $home (built; remove $home/.stamp to rebuild)"
  exit 0
fi

# 1. The sources, unless an earlier run unpacked them.
src="$home/meshlab"
if [[ ! -f "$src/.source-version" || "$(cut -d' ' -f1 "$src/.source-version")" != "$orig"-* ]]; then
  work="$home/apt-src"
  rm -rf "$work" "$src"
  mkdir -p "$work/parts" "$work/lists/partial" "$work/download"
  # The Debian archive the system already uses: the first URI of its apt sources
  # (deb822 .sources or one-line format) whose path ends in /debian, the
  # security archive and third-party repositories aside.
  uri=$( { for f in /etc/apt/sources.list.d/*.sources; do
             [[ -f "$f" ]] && sed -n 's/^URIs:[[:space:]]*//p' "$f" | tr ' ' '\n'
           done
           for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
             [[ -f "$f" ]] && awk '$1 == "deb" { for (i = 2; i <= NF; i++) if ($i ~ /^[a-z+]+:\/\//) { print $i; break } }' "$f"
           done; } | grep -E '^[a-z+]+://[^ ]*/debian/?$' | head -1 || true)
  [[ -n "$uri" ]] || fail "source list" "no Debian archive found in the system's apt sources"
  printf 'Types: deb-src\nURIs: %s\nSuites: sid\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
    "$uri" > "$work/parts/sid.sources"
  aptopts=(-o Dir::Etc::SourceList=/dev/null -o "Dir::Etc::SourceParts=$work/parts"
           -o "Dir::State::Lists=$work/lists" -o APT::Sandbox::User=root)
  step "reading Debian unstable's source index ($uri, private apt state)"
  apt-get "${aptopts[@]}" update -qq >/dev/null 2>"$work/update.log" \
    || fail "apt-get update (sid sources)" "$(tail -1 "$work/update.log")"
  version=$(apt-cache "${aptopts[@]}" showsrc meshlab 2>/dev/null | sed -n 's/^Version: //p' \
            | grep -E "^${orig//./\\.}-[0-9]+\$" | sort -V | tail -1 || true)
  [[ -n "$version" ]] || fail "source index" "Debian unstable no longer has meshlab $orig-N; it has: $(
    apt-cache "${aptopts[@]}" showsrc meshlab 2>/dev/null | sed -n 's/^Version: //p' | tr '\n' ' ')"
  # The files of the source package and their SHA256, from the signed index.
  (cd "$work/download" && apt-get "${aptopts[@]}" source --print-uris -qq "meshlab=$version") > "$work/uris" 2>"$work/uris.log" \
    || fail "apt-get source --print-uris meshlab=$version" "$(tail -1 "$work/uris.log")"
  step "fetching meshlab $version (source package)"
  fetched=1
  (cd "$work/download" && apt-get "${aptopts[@]}" source --download-only -qq "meshlab=$version" >/dev/null 2>"$work/source.log") \
    || fetched=0
  # apt keeps only files whose hash matched; check each against the index once more.
  while read -r url name size hash; do
    f="$work/download/$name"
    [[ -f "$f" ]] || continue
    [[ "$hash" == SHA256:* && "$(sha256sum "$f" | cut -d' ' -f1)" == "${hash#SHA256:}" ]] \
      || fail "checksum" "$name does not match the signed index"
  done < <(tr -d "'" < "$work/uris")
  dsc="$work/download/meshlab_$version.dsc"
  tarball="$work/download/meshlab_$orig.orig.tar.xz"
  mkdir -p "$home"
  if ((fetched)) && [[ -f "$dsc" ]]; then
    step "unpacking with Debian's patches (dpkg-source)"
    dpkg-source --no-check -x "$dsc" "$src" >/dev/null 2>"$work/unpack.log" \
      || fail "dpkg-source -x" "$(tail -1 "$work/unpack.log")"
    how="$version"
  elif [[ -f "$tarball" ]]; then
    # The archive (or its mirror) may serve the upstream tarball but not this
    # revision's .dsc and Debian patches (seen: 404 for -4's). The tarball is the
    # upstream source whatever the revision; Debian's patches only change
    # packaging matters (update check, install paths, build flags), none of which
    # the build below needs.
    step "$(grep -m1 -o "Failed to fetch [^ ]*" "$work/source.log" || echo "the .dsc was not fetched"):" \
         "building the upstream tarball (SHA256 checked against the signed index) without Debian's patches"
    mkdir -p "$src"
    tar -xJf "$tarball" -C "$src" --strip-components=1 || fail "tar -x" "could not unpack $(basename "$tarball")"
    how="$version upstream-tarball"
  else
    fail "apt-get source meshlab=$version" "$(tail -1 "$work/source.log")"
  fi
  got=$(cat "$src/ML_VERSION" 2>/dev/null || true)
  [[ "$got" == "$upstream" ]] || fail "version check" "the sources are MeshLab '$got', not $upstream"
  [[ -f "$src/src/vcglib/vcg/complex/complex.h" ]] || fail "sources" "vcglib is missing from the source package"
  echo "$how" > "$src/.source-version"
  rm -rf "$work"
fi

if ((sources_only)); then
  step "MeshLab $upstream sources in $src"
  exit 0
fi

# 2. Packages MeshLab 2025.07 needs beyond scripts/setup.sh's (its GUI uses GLU).
extra=(libglu1-mesa-dev xz-utils)
missing=()
for p in "${extra[@]}"; do
  s=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$s" == "install ok installed" ]] || missing+=("$p")
done
if ((${#missing[@]})); then
  step "installing ${missing[*]}"
  if [[ $(id -u) -ne 0 ]]; then sudo=sudo; else sudo=; fi
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null \
    || fail "apt-get install" "could not install: ${missing[*]}"
fi

# 3. Build (ccache when installed: a rebuild after a wiped build folder is quick).
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
step "configuring MeshLab $upstream (GUI + io_base) in $home/build"
cmake -S "$src" -B "$home/build" "${cmake_args[@]}" "${launcher[@]}" >"$home/configure.log" 2>&1 \
  || fail "cmake configure" "see $home/configure.log: $(grep -m1 -A2 'CMake Error' "$home/configure.log" | tr '\n' ' ')"
step "building ${targets[*]} with $jobs jobs (cold: about 40 min at 2 jobs; log: $home/build.log)"
t0=$SECONDS
nice cmake --build "$home/build" -j "$jobs" --target "${targets[@]}" >"$home/build.log" 2>&1 \
  || fail "build" "see $home/build.log: $(grep -m1 -B1 -A3 'error' "$home/build.log" | tr '\n' ' ')"
for f in meshlab libmeshlab-common.so plugins/libio_base.so; do
  [[ -e "$distrib/$f" ]] || fail "build" "$distrib/$f was not built"
done
echo "$settings" > "$home/.stamp"
step "MeshLab $upstream built in $((SECONDS - t0)) s: $distrib"
