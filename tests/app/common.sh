# SPDX-License-Identifier: Apache-2.0
# What every test script of the windowed modeler starts with; sourced as
# `. common.sh "$@"`: app (sweepers) and cli (sweepers-cli) from the arguments, here (this
# directory), the Python that has pyopenvdb and Pillow, a temporary directory removed on
# exit, fail, and app_asan.
set -euo pipefail
app=$1
cli=$2
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
py=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
# Under AddressSanitizer, the windowed modeler runs without the leak check: Mesa unloads its
# driver first, so the driver's allocations can be neither named nor suppressed. The sculpt
# controller and the command line keep theirs.
app_asan=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0
