#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The layers of src/ only depend downwards:
#   core < vdb < tools < deform < levelset < mesh < sculpt < study < io < document < app, cli
#   < python < blender (the Blender add-on: Python on the module, no C++); src/package holds
#   the package's own files (copyright, menu entry, icon), no code
# A file may include headers of its own layer and of layers below it; app and cli do not
# include each other; the window-free part of app (app_core) includes no GL, GLFW window
# or ImGui code. CMake links one library per layer in the same order.
set -euo pipefail
src=$(cd "$(dirname "$0")/../src" && pwd)
rank() {
  case $1 in
    core) echo 0 ;; vdb) echo 1 ;; tools) echo 2 ;; deform) echo 3 ;; levelset) echo 4 ;;
    mesh) echo 5 ;; sculpt) echo 6 ;; study) echo 7 ;; io) echo 8 ;; document) echo 9 ;;
    app | cli) echo 10 ;; python) echo 11 ;; blender) echo 12 ;; package) echo 13 ;;
    *) echo "unknown layer $1" >&2; exit 2 ;;
  esac
}
bad=0
for dir in "$src"/*/; do
  layer=$(basename "$dir")
  own=$(rank "$layer")
  for file in "$dir"*; do
    [ -f "$file" ] || continue
    while IFS= read -r included; do
      target=${included%%/*}
      theirs=$(rank "$target")
      if [ "$theirs" -gt "$own" ] || { [ "$theirs" -eq "$own" ] && [ "$target" != "$layer" ]; }; then
        echo "layers: src/$layer/$(basename "$file") includes $included (layer $target is not below $layer)"
        bad=1
      fi
    done < <(sed -n 's/^#include "\([a-z_]*\/[^"]*\)".*/\1/p' "$file")
  done
done
# The modeler's window-free core: tested without a window, so no window code in it (no GL or
# ImGui header, no call of a GL or GLFW function). Every file
# of app/ but the window's own (the sources CMake compiles into the `sweepers` program, and
# their headers) belongs to it.
root=$(dirname "$src")
window=$(sed -n '/^add_executable(sweepers$/,/)/p' "$root/CMakeLists.txt" |
  sed -n 's/.*src\/app\/\([a-z_]*\)\.cpp.*/\1/p')
[ -n "$window" ] || { echo "layers: the window's sources are not found in CMakeLists.txt" >&2; exit 2; }
checked=0
for f in "$src"/app/*; do
  name=$(basename "$f")
  if printf '%s\n' $window | grep -qx "${name%.*}"; then continue; fi
  checked=$((checked + 1))
  # GLFW's header is allowed for its key codes (GLFW_INCLUDE_NONE), not its functions.
  if grep -nE '#include ["<](app/(gl_renderer|modeler)\.h|imgui|backends/|GL/)' "$f" ||
    grep -nE '\bglfw[A-Z][A-Za-z]*[[:space:]]*\(|\bgl[A-Z][A-Za-z]*[[:space:]]*\(' "$f"; then
    echo "layers: $f (app_core) holds window code"
    bad=1
  fi
done
echo "layers: $checked files of app/ checked for window code"
# The Python module works on the document, not on the modeler: it includes no app/ header
# (CMake links it to the document's library, not to app_core).
if grep -n '#include "app/' "$src"/python/*; then
  echo "layers: src/python includes the modeler's code"
  bad=1
fi
[ "$bad" -eq 0 ] && echo "layers: every include points down"
exit "$bad"
