#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The three packages as a user gets them: a fresh Debian 12 root (debootstrap, minbase),
# `apt-get install ./sweepers-cli_*.deb` pulling its Depends from Debian's archive and
# nothing that draws, then the modeler's and the module's packages; each program and the
# module used from another directory (the modeler drawing on the X server of $DISPLAY); all
# three purged without a trace.
# fresh_root.sh BUILD_DIR, under xvfb-run. Needs root (chroot) and Debian's archive; exits 77
# (skipped) without root.
set -euo pipefail
build=$(cd "$1" && pwd)
fail() { echo "FAIL: $*"; exit 1; }
[ "$(id -u)" -eq 0 ] || { echo "skipped: a fresh root needs root (debootstrap, chroot)"; exit 77; }
command -v debootstrap >/dev/null || fail "debootstrap is not installed (.ci/install-deps installs it)"
tmp=$(mktemp -d)
root=$tmp/root
cleanup() {
  # /proc first: nothing under a mounted /proc may be removed.
  if mountpoint -q "$root/proc"; then umount "$root/proc" || umount -l "$root/proc"; fi
  mountpoint -q "$root/proc" || rm -rf --one-file-system "$tmp"
}
trap cleanup EXIT

cpack --config "$build/CPackConfig.cmake" -B "$tmp/pkg" >"$tmp/cpack.log" 2>&1 ||
  fail "cpack: $(tail -5 "$tmp/cpack.log")"
started=$(date +%s)
mirror=$(sed -n 's/^URIs: *\(http[^ ]*\/debian\)$/\1/p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -1)
debootstrap --variant=minbase bookworm "$root" "${mirror:-http://deb.debian.org/debian}" \
  >"$tmp/debootstrap.log" 2>&1 || fail "debootstrap: $(tail -3 "$tmp/debootstrap.log")"
mount -t proc proc "$root/proc"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mkdir "$root/debs" "$root/elsewhere"
cp "$tmp"/pkg/*.deb "$root/debs/"
# The sanitizer build's module needs the sanitizer's runtime preloaded, as in the suite. In
# the root the runtime's link-order check refuses even `python3 -c 'print(1)'` with it
# preloaded (on the host it does not), so the check is off there.
preload=""
if [ -n "${SWEEPERS_ASAN_RUNTIME:-}" ]; then
  cp "$SWEEPERS_ASAN_RUNTIME" "$root/asan-runtime.so"
  preload="/asan-runtime.so ASAN_OPTIONS=detect_leaks=0:verify_asan_link_order=0"
fi
in_root() { chroot "$root" env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root \
  DEBIAN_FRONTEND=noninteractive ASAN_OPTIONS=detect_leaks=0 bash -euo pipefail -c "$1"; }
in_root "apt-get update -qq" >"$tmp/apt.log" 2>&1 || fail "apt-get update: $(tail -3 "$tmp/apt.log")"
drawing='^(libgl|libglx|libegl|libopengl|libglvnd|libglfw|libx11|libxcb|libxext|libdrm|libllvm|libwayland|mesa|libgbm|xserver|x11-)'

# --- the command line alone: nothing that draws -----------------------------------------
in_root "apt-get install -y -qq --no-install-recommends ./debs/sweepers-cli_*.deb" \
  >"$tmp/cli.log" 2>&1 || fail "apt-get install sweepers-cli: $(tail -5 "$tmp/cli.log")"
installed=$(in_root "dpkg-query -W -f='\${Package}\n'")
echo "$installed" | grep -E "$drawing" && fail "installing sweepers-cli installed packages that draw"
cli_size=$(in_root "du -sm /usr | cut -f1")
in_root 'cd /elsewhere && ex=$(sweepers-cli examples) && [ "$ex" = /usr/share/sweepers/examples ] &&
  sweepers-cli apply $ex/finger.json -o finger.vdb --voxel-size 0.05 -q &&
  sweepers-cli info finger.vdb --json | grep -q "\"genus\": 0" && [ -e /usr/share/man/man1/sweepers-cli.1.gz ]' ||
  fail "the installed sweepers-cli did not work"
echo "sweepers-cli alone: $(echo "$installed" | wc -l) packages, none that draws; /usr $cli_size MB; an example sculpted"

# --- the modeler and the module ---------------------------------------------------------
others=(./debs/sweepers_*.deb)
packages=(sweepers-cli sweepers)
if [ -e "$build/python" ]; then
  others+=(./debs/python3-sweepers_*.deb)
  packages+=(python3-sweepers)
fi
in_root "apt-get install -y -qq --no-install-recommends ${others[*]}" >"$tmp/all.log" 2>&1 ||
  fail "apt-get install ${others[*]}: $(tail -5 "$tmp/all.log")"
in_root 'sweepers --help | grep -q "^Examples: /usr/share/sweepers/examples " &&
  [ -e /usr/share/sweepers/shaders/clay.frag ] && [ -e /usr/share/man/man1/sweepers.1.gz ]' ||
  fail "the installed modeler does not name its examples"
# The modeler draws an example with the root's own Mesa, on this machine's X server (its
# socket is reached by name, the abstract one the root shares).
if [ -n "${DISPLAY:-}" ]; then
  [ -n "${XAUTHORITY:-}" ] && cp "$XAUTHORITY" "$root/xauthority"
  echo '{"events": []}' >"$root/elsewhere/none.json"
  in_root "cd /elsewhere && DISPLAY=$DISPLAY XAUTHORITY=/xauthority sweepers \
    /usr/share/sweepers/examples/horn.json --voxel-size 0.05 --size 640x480 --hide-ui \
    --screenshot shot.png --replay-input none.json" >"$tmp/modeler.log" 2>&1 ||
    fail "the installed modeler did not draw: $(tail -3 "$tmp/modeler.log")"
  /usr/bin/python3 "$(dirname "$0")/../app/check_image.py" centred "$root/elsewhere/shot.png" ||
    fail "the installed modeler's picture shows no clay in the middle"
fi
if [ -e "$build/python" ]; then
  in_root "cd /elsewhere && LD_PRELOAD=$preload python3 -c '
import sweepers
shape = sweepers.apply(sweepers.examples() + \"/horn.json\", voxel_size=0.05)
assert sweepers.__file__.startswith(\"/usr/lib/python3/dist-packages/\"), sweepers.__file__
assert shape.topology[\"genus\"] == 0
vertices, triangles = shape.mesh()
assert vertices.shape[1] == 3
'" || fail "the installed Python module did not work"
fi
all_size=$(in_root "du -sm /usr | cut -f1")
echo "all three: /usr $all_size MB; the modeler draws an example, the module sculpts one"

# --- removed without a trace ------------------------------------------------------------
ours=$(in_root "dpkg -L ${packages[*]}" | sort -u)
in_root "apt-get purge -y -qq ${packages[*]}" >"$tmp/purge.log" 2>&1 ||
  fail "apt-get purge: $(tail -5 "$tmp/purge.log")"
left=""
while read -r f; do
  [ -f "$root$f" ] && left="$left $f"
done <<<"$ours"
[ -z "$left" ] || fail "purging left files:$left"
echo "purged: none of the packages' $(echo "$ours" | wc -l) paths is left"
echo "fresh root: all checks passed in $(($(date +%s) - started)) s"
