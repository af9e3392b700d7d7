#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The Blender add-on in Debian's Blender, headless: installed from its zip into a user
# scripts folder of its own, it imports a level set, a three-frame film and a stroke script
# that sweepers-cli also meshed, and must give the same meshes (check_addon.py).
# blender.sh CLI DATA MODULE_DIR ADDON_ZIP
. "$(dirname "$0")/../cli/common.sh" "$1" "$2"
module=$3
zip=$4
here=$(cd "$(dirname "$0")" && pwd)
command -v blender >/dev/null || fail "no blender (.ci/install-deps installs Debian's)"
h=0.05
cp "$data/horn.json" "$tmp/horn.json"
"$cli" apply "$tmp/horn.json" -o "$tmp/horn.vdb" --voxel-size $h --mesh "$tmp/horn.ply" --up z -q
"$cli" apply "$tmp/horn.json" -o "$tmp/horn_04.vdb" --voxel-size 0.04 --mesh "$tmp/horn_04.ply" \
  --up z -q
# 2 seconds at 1 fps: frames at 0, 1 and 2 s.
"$cli" animate "$data/animation/horn_film.json" -o "$tmp/film/horn_####.vdb" --fps 1 \
  --voxel-size $h --mesh "$tmp/film/horn_####.ply" --up z -q
[ "$(ls "$tmp/film"/*.vdb | wc -l)" = 3 ] || fail "the film has $(ls "$tmp/film")"
echo "not a VDB file" >"$tmp/broken.vdb"
echo '{"sweepers": 1, "strokes": [{"type": "smudge"}]}' >"$tmp/bad.json"
# The module under the sanitizers needs their runtime loaded first (Blender is not built
# with them), as the Python tests do.
preload=${SWEEPERS_ASAN_RUNTIME:-}
BLENDER_USER_SCRIPTS=$tmp/scripts LD_PRELOAD=$preload ASAN_OPTIONS=detect_leaks=0 \
  blender -b --factory-startup --python-exit-code 1 --python "$here/check_addon.py" -- \
  "$zip" "$module" "$tmp" "$here/.." >"$tmp/blender.log" 2>&1 ||
  fail "blender: $(grep -v '^$' "$tmp/blender.log" | tail -25)"
grep -E "^(level set|film frame|script|refused|blender:)" "$tmp/blender.log"
grep -q "^blender: all checks passed" "$tmp/blender.log" || fail "$(tail -25 "$tmp/blender.log")"
