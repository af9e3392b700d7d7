#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The project is under the Apache License 2.0 (LICENSE at the root), and every source file says
# so in its first lines, where tools that collect licences (reuse, licensecheck, Debian's
# copyright tools) look.
set -euo pipefail
cd "$(dirname "$0")/.."
tag='SPDX-License-Identifier: Apache-2.0'
grep -q 'Apache License' LICENSE && grep -q 'Version 2.0, January 2004' LICENSE ||
  { echo "licence: LICENSE is not the Apache License 2.0"; exit 1; }
files=$(git ls-files '*.cpp' '*.h' '*.vert' '*.frag' '*.sh' '*.py' '*.pyi' 'CMakeLists.txt' \
  '*/CMakeLists.txt' '.ci/*' | grep -v -E '^(data|docs|tests/histories)/')
missing=0
for f in $files; do
  head -n 3 "$f" | grep -q "$tag" || { echo "licence: $f does not carry '$tag'"; missing=1; }
done
[ "$missing" = 0 ] || exit 1
echo "licence: $(echo "$files" | wc -w) files carry the Apache-2.0 identifier"
