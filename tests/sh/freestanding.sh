#!/bin/sh
# freestanding.sh — builds every engine file with -ffreestanding and checks with nm
# that together they need nothing from outside but memcpy/memset/memmove/memcmp and
# exactly-rounded libm functions (no malloc, no stdio, no sin/cos/tan/atan/pow/exp).
set -eu
cd "$(dirname "$0")/../.."
CC=${CC:-cc}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
n=0
for f in $(find engine -name '*.c' | sort); do
    n=$((n + 1))
    $CC -std=c99 -O2 -ffreestanding -fno-pic -ffp-contract=off -Iinclude -c "$f" -o "$tmp/$n.o"
done
ld -r -o "$tmp/all.o" "$tmp"/[0-9]*.o
allowed='mem(cpy|set|move|cmp)|(sqrt|fabs|floor|ceil|fmin|fmax|ldexp|frexp|trunc|round|copysign)f?|_GLOBAL_OFFSET_TABLE_'
bad=$(nm -u "$tmp/all.o" | awk '{print $2}' | grep -vxE "$allowed" || true)
if [ -n "$bad" ]; then
    echo "freestanding: FAIL — engine/ needs: $bad"
    exit 1
fi
# No writable global state: the engine's objects have no .data or .bss symbols.
state=$(nm "$tmp/all.o" | awk '$2 ~ /^[BbDdCc]$/ {print $3}' || true)
if [ -n "$state" ]; then
    echo "freestanding: FAIL — engine/ has writable globals: $state"
    exit 1
fi
echo "freestanding: ok ($n files; external symbols: $(nm -u "$tmp/all.o" | awk '{print $2}' | tr '\n' ' '))"
