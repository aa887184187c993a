#!/usr/bin/env bash
# Install LinuxCNC's standalone G-code interpreter `rs274` (the differential oracle of
# tests/test_gcode_linuxcnc.py) without installing LinuxCNC: the Debian package
# linuxcnc-uspace is downloaded and unpacked into a prefix, its shared libraries are
# found through LD_LIBRARY_PATH in a wrapper script, and the libraries it links against
# that Debian ships separately (libboost-python) are installed with apt-get.
#
#   tools/setup_rs274.sh [PREFIX]      (default /opt/linuxcnc-rs274; needs root for apt)
#
# Afterwards PREFIX/rs274 runs the interpreter; the tests find it there or through
# OPENMOTION_RS274. Running it again is a no-op once the wrapper works.
set -euo pipefail
PREFIX="${1:-/opt/linuxcnc-rs274}"
WRAPPER="$PREFIX/rs274"

works() {
    [ -x "$WRAPPER" ] && { "$WRAPPER" -h 2>&1 || true; } | grep -q 'Usage'
}

if works; then
    echo "rs274 ready: $WRAPPER"
    exit 0
fi
command -v apt-get >/dev/null || { echo "setup_rs274: apt-get not found (Debian needed)" >&2; exit 1; }
SUDO=""
[ "$(id -u)" = 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
chmod 777 "$TMP"
( cd "$TMP" && apt-get download -qq linuxcnc-uspace )
$SUDO mkdir -p "$PREFIX"
$SUDO dpkg -x "$TMP"/linuxcnc-uspace_*.deb "$PREFIX"
$SUDO tee "$WRAPPER" >/dev/null <<WRAP
#!/bin/sh
# LinuxCNC rs274 from the unpacked Debian package (tools/setup_rs274.sh)
LD_LIBRARY_PATH="$PREFIX/usr/lib\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}" exec "$PREFIX/usr/bin/rs274" "\$@"
WRAP
$SUDO chmod +x "$WRAPPER"
# Libraries the binary needs that the package does not carry (libboost-python, ...):
# ask apt for the package owning each missing soname.
missing="$(LD_LIBRARY_PATH="$PREFIX/usr/lib" ldd "$PREFIX/usr/bin/rs274" | awk '/not found/ {print $1}')"
pkgs="libboost-python1.74.0"
for so in $missing; do
    case "$so" in
        libboost_python*) ;;
        *) pkgs="$pkgs $(apt-cache search --names-only "^$(echo "$so" | sed 's/\.so.*//; s/_/-/g')" | awk 'NR==1 {print $1}')" ;;
    esac
done
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq $pkgs >/dev/null
if ! works; then
    echo "setup_rs274: $WRAPPER does not run; missing libraries:" >&2
    LD_LIBRARY_PATH="$PREFIX/usr/lib" ldd "$PREFIX/usr/bin/rs274" | grep 'not found' >&2 || true
    exit 1
fi
echo "rs274 ready: $WRAPPER"
