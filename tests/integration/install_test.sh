#!/usr/bin/env bash
# `cmake --install` puts the plugins where Debian's MeshLab loads them
# (/usr/lib/<arch>/meshlab/plugins), and the installed copies (run path
# stripped) load in meshlabserver: installed into a DESTDIR, then put into a
# copy of the staged MeshLab, which must list every GI filter.
set -euo pipefail
build=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
DESTDIR="$tmp/root" cmake --install "$build" --component plugins >/dev/null
arch_plugins=$(find "$tmp/root" -type d -name plugins -path "*/meshlab/plugins")
case "$arch_plugins" in
  "$tmp"/root/usr/lib/*/meshlab/plugins) ;;
  *) echo "FAIL: plugins installed into '${arch_plugins#$tmp/root}', not /usr/lib/<arch>/meshlab/plugins"; exit 1 ;;
esac
cp -r "$build/stage" "$tmp/stage"
dst=$(find "$tmp/stage" -type d -name plugins)
for so in "$arch_plugins"/*.so; do
  rm -f "$dst/$(basename "$so")"
  cp "$so" "$dst/"
done
(cd "$tmp" && xvfb-run -a "$tmp/stage/bin/meshlabserver" -d "$tmp/filters.txt" >/dev/null 2>&1) || true
n=$(grep -c '\\section .* GI: ' "$tmp/filters.txt" || true)
want=$("$build/tools/gi" filters | wc -l)  # the catalogue
if [[ "$n" -ne "$want" ]]; then echo "FAIL: the installed plugins show $n GI filters in meshlabserver -d, not $want"; exit 1; fi
echo "PASS: installed into ${arch_plugins#$tmp/root}; meshlabserver lists the $want GI filters"
