#!/bin/sh
# sized.sh — the README's second embedding example (render_sized.c) draws the frame
# `ombra render` draws with the same settings: the default scene at 640x480, `sm` at
# its defaults. Usage: sh tests/embed/sized.sh BUILD_DIR (after make has built
# embed-render-sized and ombra there).
set -u
O=$1
got=$("$O/embed-render-sized" | sed -n 's/.*frame hash //p')
want=$("$O/ombra" render --size 640x480 --method sm --out /dev/null | sed -n 's/^hash: image \([0-9a-f]*\) .*/\1/p')
if [ -n "$got" ] && [ "$got" = "$want" ]; then
    echo "embed: render_sized ok, the frame ombra render draws ($got)"
else
    echo "embed: FAIL — render_sized drew '$got', ombra render '$want'"
    exit 1
fi
