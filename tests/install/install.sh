#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What `cmake --install` and `cpack -G DEB` give a user: the programs, the shaders where the
# installed modeler finds them, the examples and the guides, used from another directory;
# and a Debian package holding them. Run under xvfb-run: install.sh BUILD_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
asan=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 # Mesa's driver, as in tests/app/common.sh

# --- install into a prefix of its own --------------------------------------------------
prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" || fail "$(cat "$tmp/install.log")"
for f in bin/sweepers bin/sweepers-cli share/sweepers/shaders/clay.vert \
  share/sweepers/shaders/clay.frag share/sweepers/examples/drag.json \
  share/sweepers/examples/tools/finger.vdb share/doc/sweepers/README.md \
  share/doc/sweepers/docs/cli.md share/doc/sweepers/docs/stroke-scripts.md \
  share/doc/sweepers/docs/images/modeler.png share/doc/sweepers/LICENSE \
  share/blender/scripts/addons/sweepers_blender/__init__.py share/doc/sweepers/copyright \
  share/applications/sweepers.desktop share/icons/hicolor/scalable/apps/sweepers.svg \
  share/mime/packages/sweepers.xml; do
  [ -e "$prefix/$f" ] || fail "cmake --install put no $f"
done
# The menu entry, its icon and the .vdb type are what the desktop's tools accept; the
# copyright file is Debian's machine-readable format.
desktop-file-validate "$prefix/share/applications/sweepers.desktop" ||
  fail "desktop-file-validate refuses sweepers.desktop"
grep -qx "Exec=sweepers %f" "$prefix/share/applications/sweepers.desktop" || fail "the menu entry runs no sweepers"
xmllint --noout "$prefix/share/icons/hicolor/scalable/apps/sweepers.svg" \
  "$prefix/share/mime/packages/sweepers.xml" || fail "the icon or the MIME type is not well-formed"
copyright=$prefix/share/doc/sweepers/copyright
head -1 "$copyright" | grep -qx "Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/" ||
  fail "the copyright file is not in Debian's format"
grep -qx "License: Apache-2.0" "$copyright" && grep -qx "License: Expat" "$copyright" ||
  fail "the copyright file names neither licence"
echo "installed: programs, shaders, examples and guides under $prefix"

# --- the installed programs, from another directory ------------------------------------
mkdir "$tmp/work"
cd "$tmp/work"
examples=$prefix/share/sweepers/examples
# finger.json sculpts with a tool of its own (tools/finger.vdb): the examples keep their files.
ASAN_OPTIONS=$asan "$prefix/bin/sweepers-cli" apply "$examples/finger.json" -o finger.vdb \
  --voxel-size 0.05 -q --json >finger.json || fail "the installed sweepers-cli failed"
"$py" -c 'import json, sys; j = json.load(open(sys.argv[1])); assert j["topology"]["genus"] == 0, j' \
  finger.json
# --help says where the examples and guides are, and its example works as printed.
footer=$("$prefix/bin/sweepers-cli" --help | grep "^Examples: ") || fail "sweepers-cli --help names no examples"
[ "$footer" = "Examples: $prefix/share/sweepers/examples (sweepers-cli apply $prefix/share/sweepers/examples/horn.json -o horn.vdb)" ] ||
  fail "sweepers-cli --help: $footer"
command=$(echo "$footer" | sed 's/^[^(]*(//; s/)$//; s/^sweepers-cli //')
# shellcheck disable=SC2086 # the example's words, as a user pastes them
ASAN_OPTIONS=$asan "$prefix/bin/sweepers-cli" $command -q || fail "the --help example failed: $command"
[ -s horn.vdb ] || fail "the --help example wrote no horn.vdb"
guides=$("$prefix/bin/sweepers-cli" --help | sed -n 's/^Guides: \([^ ]*\)\/README.md .*/\1/p')
[ "$guides" = "$prefix/share/doc/sweepers" ] || fail "sweepers-cli --help: guides at '$guides'"
# The installed README's links and pictures resolve.
grep -o '](docs/[^)]*)' "$guides/README.md" | sed 's/^](//; s/)$//; s/#.*//' | sort -u | while read -r link; do
  [ -e "$guides/$link" ] || fail "the installed README links to $link, which is not installed"
done
ASAN_OPTIONS=$asan "$prefix/bin/sweepers" --help | grep -qx "Examples: $prefix/share/sweepers/examples (sweepers $prefix/share/sweepers/examples/horn.json)" ||
  fail "sweepers --help: $("$prefix/bin/sweepers" --help | tail -2)"
echo "installed --help: examples and guides named, the example runs, the README's links resolve"
echo '{"events": []}' >none.json
# The installed modeler must find its installed shaders: only a modeler in its build tree
# reads the source tree's (src/app/gl_renderer.cpp).
ASAN_OPTIONS=$asan "$prefix/bin/sweepers" --size 640x480 --voxel-size 0.03125 --hide-ui \
  --screenshot shot.png --replay-input none.json 2>modeler.err || fail "$(cat modeler.err)"
"$py" "$here/../app/check_image.py" centred shot.png
mv "$prefix/share/sweepers/shaders" "$tmp/moved"
if ASAN_OPTIONS=$asan "$prefix/bin/sweepers" --size 640x480 --hide-ui --screenshot none.png \
  --replay-input none.json 2>moved.err; then
  fail "the installed modeler ran without its installed shaders"
fi
grep -q "cannot find the shaders" moved.err || fail "without shaders: $(cat moved.err)"
echo "installed modeler: clay on screen with its own shaders, one line without them"

# The installed Python module, with its type hints, where Debian's python3 looks under the
# prefix (lib/python3.X/dist-packages), imported from elsewhere.
site=$("$py" -c 'import sys; print(f"lib/python3.{sys.version_info[1]}/dist-packages")')
if [ -e "$build/python" ]; then
  ls "$prefix/$site"/sweepers.*.so >/dev/null 2>&1 || fail "cmake --install put no module in $site"
  [ -e "$prefix/$site/sweepers.pyi" ] || fail "cmake --install put no sweepers.pyi in $site"
  preload=""
  [ -n "${SWEEPERS_ASAN_RUNTIME:-}" ] && preload=$SWEEPERS_ASAN_RUNTIME
  LD_PRELOAD=$preload ASAN_OPTIONS=detect_leaks=0 PYTHONPATH="$prefix/$site" "$py" -c '
import sweepers, sys
s = sweepers.Sculptor(voxel_size=0.0625)
s.apply({"type": "inflate", "at": [0, 1, 0], "radius": 0.4})
assert sweepers.__file__.startswith(sys.argv[1]), sweepers.__file__
assert s.topology["genus"] == 0 and s.mesh()[0].shape[1] == 3
' "$prefix" || fail "the installed Python module did not work"
  echo "installed Python module: imported from $site, sculpts"
fi

# --- the Debian package -----------------------------------------------------------------
cpack -G DEB --config "$build/CPackConfig.cmake" -B "$tmp/pkg" >"$tmp/cpack.log" 2>&1 ||
  fail "cpack: $(tail -5 "$tmp/cpack.log")"
deb=$(ls "$tmp"/pkg/sweepers_*.deb)
dpkg-deb -c "$deb" >"$tmp/contents"
for f in ./usr/bin/sweepers ./usr/bin/sweepers-cli ./usr/share/sweepers/shaders/clay.vert \
  ./usr/share/sweepers/examples/drag.json \
  ./usr/share/blender/scripts/addons/sweepers_blender/__init__.py \
  ./usr/share/doc/sweepers/copyright ./usr/share/applications/sweepers.desktop; do
  grep -q " $f\$" "$tmp/contents" || fail "$(basename "$deb") holds no $f"
done
if [ -e "$build/python" ]; then
  grep -q " ./usr/lib/python3/dist-packages/sweepers\..*\.so\$" "$tmp/contents" ||
    fail "$(basename "$deb") holds no Python module in /usr/lib/python3/dist-packages"
fi
# Its programs and module are stripped.
dpkg-deb -x "$deb" "$tmp/unpacked"
for f in "$tmp"/unpacked/usr/bin/sweepers "$tmp"/unpacked/usr/bin/sweepers-cli \
  "$tmp"/unpacked/usr/lib/python3/dist-packages/sweepers.*.so; do
  [ -e "$f" ] || continue
  file -b "$f" | grep -q ", stripped" || fail "$(basename "$f") is not stripped: $(file -b "$f")"
done
depends=$(dpkg-deb -f "$deb" Depends)
# Every package it depends on is one Debian has (here, installed by the build's own needs).
for p in $(echo "$depends" | tr ',' '\n' | sed 's/(.*//; s/|.*//' | tr -d ' '); do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
    fail "Depends names $p, which is not an installed Debian package"
done
echo "$depends" | grep -q libopenvdb || fail "Depends does not name OpenVDB's runtime: $depends"
echo "$(basename "$deb"): both programs, the shaders and the examples; Depends: $depends"
echo "install: all checks passed"
