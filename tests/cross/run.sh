#!/bin/sh
# run.sh — `make cross-test`: builds the cross driver (driver.c) for every compiler and
# CPU this machine has, runs each (natively or under qemu-user), and checks that every
# build prints the same per-method frame and mask hashes. A missing toolchain is
# reported and skipped; CI installs them all (see .ci/run).
set -u
cd "$(dirname "$0")/../.."
out=build/cross
mkdir -p "$out"
SRC="$(ls engine/*/*.c | tr '\n' ' ') tests/cross/driver.c tests/cross/host_linux.c"
FLAGS="-std=c99 -Wall -Wextra -Wpedantic -Werror -ffp-contract=off -Iinclude"
pass=0
fail=0
skip=0
ref=""
# name | compiler | flags | runner
configs="x86_64-gcc-O0|gcc|-O0|
x86_64-gcc-O2|gcc|-O2|
x86_64-gcc-O3|gcc|-O3|
x86_64-clang-O0|clang|-O0|
x86_64-clang-O2|clang|-O2|
x86_64-clang-O3|clang|-O3|
i386-gcc-O2|gcc|-O2 -m32 -msse2 -mfpmath=sse|
aarch64-gcc-O2|aarch64-linux-gnu-gcc|-O2|qemu-aarch64 -L /usr/aarch64-linux-gnu
aarch64-clang-O2|clang|-O2 --target=aarch64-linux-gnu|qemu-aarch64 -L /usr/aarch64-linux-gnu
riscv64-gcc-O2|riscv64-linux-gnu-gcc|-O2|qemu-riscv64 -L /usr/riscv64-linux-gnu
armhf-gcc-O2|arm-linux-gnueabihf-gcc|-O2|qemu-arm -L /usr/arm-linux-gnueabihf"
IFS='
'
for c in $configs; do
    name=$(echo "$c" | cut -d'|' -f1)
    cc=$(echo "$c" | cut -d'|' -f2)
    flags=$(echo "$c" | cut -d'|' -f3)
    runner=$(echo "$c" | cut -d'|' -f4)
    IFS=' '
    if ! command -v "$cc" >/dev/null 2>&1 || { [ -n "$runner" ] && ! command -v ${runner%% *} >/dev/null 2>&1; }; then
        echo "cross: skip $name ($cc or its emulator is not installed)"
        skip=$((skip + 1))
        IFS='
'
        continue
    fi
    if ! $cc $FLAGS $flags $SRC -lm -o "$out/$name" 2>"$out/$name.err"; then
        echo "cross: FAIL $name does not build: $(head -c 400 "$out/$name.err")"
        fail=$((fail + 1))
        IFS='
'
        continue
    fi
    if ! $runner "$out/$name" >"$out/$name.txt" 2>&1; then
        echo "cross: FAIL $name exits non-zero: $(head -c 400 "$out/$name.txt")"
        fail=$((fail + 1))
    elif [ -z "$ref" ]; then
        ref=$name
        pass=$((pass + 1))
        echo "cross: $name (reference)"
        sed 's/^/    /' "$out/$name.txt"
    elif [ "$(grep -v '^bytes' "$out/$ref.txt")" = "$(grep -v '^bytes' "$out/$name.txt")" ]; then
        pass=$((pass + 1))
        echo "cross: $name matches"
    else
        fail=$((fail + 1))
        echo "cross: FAIL $name differs from $ref:"
        diff "$out/$ref.txt" "$out/$name.txt" | grep -v bytes | sed 's/^/    /'
    fi
    IFS='
'
done
echo "cross: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
