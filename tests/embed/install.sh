#!/bin/sh
# install.sh BUILD — make install into a scratch DESTDIR, then build the README's
# embedding example the way a user of the installed copy would
# (cc ... $(pkg-config --cflags --libs ombra)), run it, and check that it draws the
# frame the in-tree build draws; then make uninstall, which must leave nothing.
set -eu
cd "$(dirname "$0")/../.."
O=${1:-build}
CC=${CC:-cc}
command -v pkg-config >/dev/null 2>&1 || { echo "install: FAIL — pkg-config is not installed"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
make --no-print-directory -s install O="$O" DESTDIR="$tmp/root" PREFIX=/usr/local >/dev/null
export PKG_CONFIG_PATH="$tmp/root/usr/local/lib/pkgconfig" PKG_CONFIG_SYSROOT_DIR="$tmp/root"
[ "$(pkg-config --modversion ombra)" = "$(sed -n 's/^#define OMBRA_VERSION_STRING "\(.*\)"/\1/p' include/ombra.h)" ] ||
    { echo "install: FAIL — pkg-config's version is not the header's"; exit 1; }
# shellcheck disable=SC2046
$CC -std=c99 -Wall -Wextra -Wpedantic -Werror -O2 -o "$tmp/example" tests/embed/render_once.c \
    $(pkg-config --cflags --libs ombra)
want=$("$O/embed-render-once")
got=$("$tmp/example")
[ "$got" = "$want" ] || { echo "install: FAIL — the installed copy drew another frame: $got"; exit 1; }
"$tmp/root/usr/local/bin/ombra" --version >/dev/null
make --no-print-directory -s uninstall DESTDIR="$tmp/root" PREFIX=/usr/local >/dev/null
left=$(find "$tmp/root" -type f | wc -l)
[ "$left" -eq 0 ] || { echo "install: FAIL — make uninstall left $left files"; exit 1; }
echo "install: the example builds with pkg-config against the installed copy and draws the same frame"
