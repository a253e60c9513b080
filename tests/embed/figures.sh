#!/bin/sh
# figures.sh — the figures README.md gives for its first embedding example are what the
# command it names prints: the `memory:` line of
#   ombra render small.scene --size 160x120 --strip 8 --format rgb565 --map 96 --threads 1
# (small.scene from `ombra scene --small`), the bytes the example's static arenas must
# hold. Those bytes differ on a 32-bit build, so there the check only says so (the
# example itself still fails when its frame arena no longer holds the bins).
# Usage: sh tests/embed/figures.sh BUILD_DIR (after make has built ombra there).
set -u
O=$(cd "$1" && pwd) || exit 1
cd "$(dirname "$0")/../.." || exit 1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmd="ombra render small.scene --size 160x120 --strip 8 --format rgb565 --map 96 --threads 1"
if ! grep -qF "    $cmd" README.md; then
    echo "embed: FAIL — README.md no longer names the command '$cmd' that figures.sh runs: update one or the other"
    exit 1
fi
# ELF class, the fifth byte: 1 for a 32-bit program, 2 for a 64-bit one
if [ "$(od -An -tu1 -j4 -N1 "$O/ombra" | tr -d ' ')" != 2 ]; then
    echo "embed: the README's figures are a 64-bit build's; not compared in this one"
    exit 0
fi
"$O/ombra" scene --small >"$tmp/small.scene" || exit 1
# shellcheck disable=SC2086
got=$(cd "$tmp" && "$O/ombra" ${cmd#ombra } --out /dev/null | grep '^memory:')
if [ -z "$got" ]; then
    echo "embed: FAIL — '$cmd' printed no memory line"
    exit 1
fi
if grep -qF "\`$got\`" README.md; then
    echo "embed: the README's arena figures are what '$cmd' prints"
else
    echo "embed: FAIL — README.md's first embedding example gives other arena figures than '$cmd' prints:"
    echo "    $got"
    echo "  update README.md (and the arenas of tests/embed/render_once.c, if they no longer hold these)"
    exit 1
fi
