#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What `cmake --install` and `cpack` give a user: the programs, the shaders where the
# installed modeler finds them, the examples and the guides, used from another directory,
# every command of the README and the guides run as written; and the three Debian packages,
# what each holds and depends on, checked by lintian. Run under xvfb-run:
# install.sh BUILD_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
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
  share/sweepers/examples/tools/finger.vdb share/doc/sweepers-cli/README.md \
  share/doc/sweepers-cli/docs/cli.md share/doc/sweepers-cli/docs/stroke-scripts.md \
  share/doc/sweepers-cli/docs/images/modeler.png share/doc/sweepers-cli/LICENSE \
  share/blender/scripts/addons/sweepers_blender/__init__.py \
  share/applications/sweepers.desktop share/icons/hicolor/scalable/apps/sweepers.svg \
  share/mime/packages/sweepers.xml share/man/man1/sweepers.1.gz share/man/man1/sweepers-cli.1.gz \
  share/doc/sweepers/copyright share/doc/sweepers-cli/copyright \
  share/doc/python3-sweepers/copyright share/doc/sweepers/changelog.Debian.gz \
  share/doc/sweepers-cli/changelog.Debian.gz share/doc/python3-sweepers/changelog.Debian.gz; do
  [ -e "$prefix/$f" ] || fail "cmake --install put no $f"
done
# The menu entry, its icon and the .vdb type are what the desktop's tools accept; the
# copyright file is Debian's machine-readable format.
desktop-file-validate "$prefix/share/applications/sweepers.desktop" ||
  fail "desktop-file-validate refuses sweepers.desktop"
grep -qx "Exec=sweepers %f" "$prefix/share/applications/sweepers.desktop" || fail "the menu entry runs no sweepers"
xmllint --noout "$prefix/share/icons/hicolor/scalable/apps/sweepers.svg" \
  "$prefix/share/mime/packages/sweepers.xml" || fail "the icon or the MIME type is not well-formed"
copyright=$prefix/share/doc/sweepers-cli/copyright
head -1 "$copyright" | grep -qx "Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/" ||
  fail "the copyright file is not in Debian's format"
grep -qx "License: Apache-2.0" "$copyright" && grep -qx "License: Expat" "$copyright" ||
  fail "the copyright file names neither licence"
# Debian's changelog: an entry for the version packaged, in the format dpkg reads.
version=$("$prefix/bin/sweepers-cli" --version | awk '{print $2}')
zcat "$prefix/share/doc/sweepers-cli/changelog.Debian.gz" >"$tmp/changelog"
[ "$(dpkg-parsechangelog -l "$tmp/changelog" -S Version)" = "$version-1" ] ||
  fail "changelog.Debian.gz does not begin with $version-1"
# The man pages are the programs' --help, naming the installed examples, not the checkout.
for program in sweepers sweepers-cli; do
  page=$(man -l "$prefix/share/man/man1/$program.1.gz" 2>&1 | col -b) || fail "man cannot read $program.1.gz"
  echo "$page" | grep -q -- "--threads" || fail "$program.1.gz holds no options"
  echo "$page" | grep -q "/usr/share/sweepers/examples" || fail "$program.1.gz names no examples"
  ! echo "$page" | grep -q "$source_dir" || fail "$program.1.gz names the checkout"
done
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
[ "$guides" = "$prefix/share/doc/sweepers-cli" ] || fail "sweepers-cli --help: guides at '$guides'"
[ "$("$prefix/bin/sweepers-cli" examples)" = "$examples" ] || fail "sweepers-cli examples: $("$prefix/bin/sweepers-cli" examples)"
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
preload=""
[ -n "${SWEEPERS_ASAN_RUNTIME:-}" ] && preload=$SWEEPERS_ASAN_RUNTIME
python_path=()
if [ -e "$build/python" ]; then
  ls "$prefix/$site"/sweepers.*.so >/dev/null 2>&1 || fail "cmake --install put no module in $site"
  [ -e "$prefix/$site/sweepers.pyi" ] || fail "cmake --install put no sweepers.pyi in $site"
  LD_PRELOAD=$preload ASAN_OPTIONS=detect_leaks=0 PYTHONPATH="$prefix/$site" "$py" -c '
import sweepers, sys
s = sweepers.Sculptor(voxel_size=0.0625)
s.apply({"type": "inflate", "at": [0, 1, 0], "radius": 0.4})
assert sweepers.__file__.startswith(sys.argv[1]), sweepers.__file__
assert s.topology["genus"] == 0 and s.mesh()[0].shape[1] == 3
assert sweepers.examples() == sys.argv[1] + "/share/sweepers/examples", sweepers.examples()
' "$prefix" || fail "the installed Python module did not work"
  echo "installed Python module: imported from $site, sculpts, finds the installed examples"
  python_path=(--python-path "$prefix/$site")
fi

# Every command of the installed README and guides, as a reader pastes them, from a folder
# of its own (coarse voxel sizes under SWEEPERS_COARSE_TESTS).
coarse=()
[ -n "${SWEEPERS_COARSE_TESTS:-}" ] && coarse=(--coarse)
ASAN_OPTIONS=$asan "$py" "$here/doc_commands.py" "$guides" "$prefix/bin" \
  "$tmp/docs" "${coarse[@]}" "${python_path[@]}" || fail "a command of the docs failed"

# --- the Debian packages ----------------------------------------------------------------
cpack --config "$build/CPackConfig.cmake" -B "$tmp/pkg" >"$tmp/cpack.log" 2>&1 ||
  fail "cpack: $(tail -5 "$tmp/cpack.log")"
cd "$tmp/pkg"
debs=(sweepers-cli_*.deb sweepers_*.deb)
[ -e "$build/python" ] && debs+=(python3-sweepers_*.deb)
for deb in "${debs[@]}"; do
  [ -e "$deb" ] || fail "cpack made no $deb: $(ls)"
done
# What each holds, and what it does not: the command line's package nothing of the modeler's.
holds() { # holds DEB FILE... : each FILE is in DEB
  local deb=$1
  shift
  dpkg-deb -c "$deb" | awk '{print $NF}' >"$tmp/contents"
  for f in "$@"; do
    grep -qx "$f" "$tmp/contents" || fail "$deb holds no $f"
  done
}
holds sweepers-cli_*.deb ./usr/bin/sweepers-cli ./usr/share/sweepers/examples/drag.json \
  ./usr/share/doc/sweepers-cli/docs/cli.md ./usr/share/doc/sweepers-cli/copyright \
  ./usr/share/doc/sweepers-cli/changelog.Debian.gz ./usr/share/man/man1/sweepers-cli.1.gz
! grep -q "shaders\|bin/sweepers\$\|python3" "$tmp/contents" || fail "sweepers-cli holds the modeler's or the module's files"
holds sweepers_*.deb ./usr/bin/sweepers ./usr/share/sweepers/shaders/clay.vert \
  ./usr/share/applications/sweepers.desktop ./usr/share/doc/sweepers/copyright \
  ./usr/share/man/man1/sweepers.1.gz
if [ -e "$build/python" ]; then
  holds python3-sweepers_*.deb ./usr/share/blender/scripts/addons/sweepers_blender/__init__.py \
    ./usr/lib/python3/dist-packages/sweepers.pyi ./usr/share/doc/python3-sweepers/copyright
  grep -q "^./usr/lib/python3/dist-packages/sweepers\..*\.so\$" "$tmp/contents" ||
    fail "python3-sweepers holds no module in /usr/lib/python3/dist-packages"
fi
# Their programs and module are stripped.
for deb in "${debs[@]}"; do dpkg-deb -x "$deb" "$tmp/unpacked"; done
for f in "$tmp"/unpacked/usr/bin/sweepers "$tmp"/unpacked/usr/bin/sweepers-cli \
  "$tmp"/unpacked/usr/lib/python3/dist-packages/sweepers.*.so; do
  [ -e "$f" ] || continue
  file -b "$f" | grep -q ", stripped" || fail "$(basename "$f") is not stripped: $(file -b "$f")"
done
# Depends: the modeler's on the command line's of the same version; the module's on the
# python3 it is built for and numpy (fresh_root.sh: the command line's on nothing that draws).
field() { dpkg-deb -f "$1" "$2"; }
version=$(field sweepers-cli_*.deb Version)
field sweepers_*.deb Depends | grep -q "sweepers-cli (= $version)" ||
  fail "sweepers does not depend on sweepers-cli (= $version): $(field sweepers_*.deb Depends)"
if [ -e "$build/python" ]; then
  for d in "python3 (>= 3.11)" "python3 (<< 3.12)" python3-numpy; do
    field python3-sweepers_*.deb Depends | grep -qF "$d" || fail "python3-sweepers does not depend on $d"
  done
  for s in python3-pandas python3-matplotlib python3-openvdb; do
    field python3-sweepers_*.deb Suggests | grep -qF "$s" || fail "python3-sweepers does not suggest $s"
  done
fi
for deb in "${debs[@]}"; do
  echo "$deb: $(($(stat -c %s "$deb") / 1024)) kB; Depends: $(field "$deb" Depends)"
done

# lintian, Debian's own checks: no error, and each warning one docs/packages.md explains.
status=0
lintian --tag-display-limit 0 "${debs[@]}" >"$tmp/lintian.txt" 2>&1 || status=$?
[ $status -le 1 ] || fail "lintian could not check the packages: $(tail -5 "$tmp/lintian.txt")"
grep "^E: " "$tmp/lintian.txt" && fail "lintian reports errors"
grep -E "^[EW]: " "$tmp/lintian.txt" | awk '{print $3}' | sort -u | while read -r tag; do
  grep -q "\`$tag\`" "$source_dir/docs/packages.md" || fail "lintian warns $tag, which docs/packages.md does not explain"
done
echo "lintian: no errors; warnings, each explained: $(grep -c "^W: " "$tmp/lintian.txt" || true)"

# (fresh_root.sh installs them on a fresh Debian root, as a user does.)
echo "install: all checks passed"
