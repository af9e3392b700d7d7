#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The layers of src/ only depend downwards:
#   core < tools < deform < levelset < mesh < sculpt < study < io < app, cli < python
# A file may include headers of its own layer and of layers below it; app and cli do not
# include each other; the window-free part of app (app_core) includes no GL, GLFW window
# or ImGui code. CMake links one library per layer in the same order.
set -euo pipefail
src=$(cd "$(dirname "$0")/../src" && pwd)
rank() {
  case $1 in
    core) echo 0 ;; tools) echo 1 ;; deform) echo 2 ;; levelset) echo 3 ;; mesh) echo 4 ;;
    sculpt) echo 5 ;; study) echo 6 ;; io) echo 7 ;; app | cli) echo 8 ;; python) echo 9 ;;
    *) echo "unknown layer $1" >&2; exit 2 ;;
  esac
}
bad=0
for dir in "$src"/*/; do
  layer=$(basename "$dir")
  own=$(rank "$layer")
  for file in "$dir"*; do
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
# The modeler's window-free core: tested without a window, so no window code in it.
for file in document sculpt_controller camera input_replay; do
  for f in "$src/app/$file".h "$src/app/$file".cpp; do
    if grep -nE '#include ["<](app/(gl_renderer|modeler)\.h|imgui|backends/|GL/)' "$f"; then
      echo "layers: $f (app_core) includes window code"
      bad=1
    fi
  done
done
[ "$bad" -eq 0 ] && echo "layers: every include points down"
exit "$bad"
