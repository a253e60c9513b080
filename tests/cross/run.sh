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
    ok=true
    $runner "$out/$name" >"$out/$name.txt" 2>&1 || ok=false
    # A kernel built without 32-bit support cannot exec the i386 build: run it under
    # qemu-user then, which gives the same bits (it emulates the SSE arithmetic).
    if ! $ok && [ -z "$runner" ] && grep -q "Exec format error" "$out/$name.txt" &&
       command -v qemu-i386 >/dev/null 2>&1; then
        echo "cross: $name: this kernel does not run it natively, so under qemu-i386"
        ok=true
        qemu-i386 "$out/$name" >"$out/$name.txt" 2>&1 || ok=false
    fi
    if ! $ok; then
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
# Cortex-M3 (mps2-an385) and Cortex-M4 (mps2-an386) under qemu-system-arm, through
# platform/cortex-m: the same driver, the scene compiled into the firmware (the
# default scene's text), every method in an arena of 256 KiB (the target for small
# machines): a method whose minimum is larger prints "too big" and fails the run; the
# others render in their lean modes there and must give the host's hashes.
MFLAGS="-std=c99 -Wall -Wextra -Werror -O2 -ffp-contract=off -ffreestanding -mthumb -Iinclude"
MFLAGS="$MFLAGS -DOM_CROSS_METHOD_MEM=(256u<<10) -DOM_CROSS_SCENE_MEM=(512u<<10) -ffunction-sections -fdata-sections"
for board in "cortex-m3 mps2-an385" "cortex-m4 mps2-an386"; do
    IFS=' '
    set -- $board
    cpu=$1
    machine=$2
    name="$cpu-gcc-O2"
    extra=""
    [ "$cpu" = cortex-m4 ] && extra="-mfloat-abi=hard -mfpu=fpv4-sp-d16"
    if ! command -v arm-none-eabi-gcc >/dev/null 2>&1 || ! command -v qemu-system-arm >/dev/null 2>&1; then
        echo "cross: skip $name (arm-none-eabi-gcc or qemu-system-arm is not installed)"
        skip=$((skip + 1))
        continue
    fi
    msrc="$(ls engine/*/*.c | tr '\n' ' ') tests/cross/driver.c platform/cortex-m/startup.c platform/cortex-m/semihost.c"
    if ! arm-none-eabi-gcc $MFLAGS -mcpu=$cpu $extra $msrc -T platform/cortex-m/mps2.ld \
            -nostartfiles -Wl,--gc-sections -lm -lc -lgcc -o "$out/$name.elf" 2>"$out/$name.err"; then
        echo "cross: FAIL $name does not build: $(head -c 400 "$out/$name.err")"
        fail=$((fail + 1))
        continue
    fi
    if ! timeout 300 qemu-system-arm -M "$machine" -nographic -monitor none -serial none \
            -semihosting-config enable=on,target=native -kernel "$out/$name.elf" >"$out/$name.txt" 2>&1; then
        echo "cross: FAIL $name exits non-zero: $(head -c 400 "$out/$name.txt")"
        fail=$((fail + 1))
    elif [ -n "$ref" ] && [ "$(grep -v '^bytes' "$out/$ref.txt")" = "$(grep -v '^bytes' "$out/$name.txt")" ]; then
        pass=$((pass + 1))
        echo "cross: $name matches ($(arm-none-eabi-size "$out/$name.elf" | awk 'NR == 2 {print $1}') bytes of code)"
        grep '^bytes' "$out/$name.txt" | awk '{printf "    %-5s peak %8d, minimum %8d: %s\n", $2, $3, $5, $5 <= 262144 ? "fits 256 KiB" : "over 256 KiB"}'
    else
        fail=$((fail + 1))
        echo "cross: FAIL $name differs from $ref:"
        diff "$out/$ref.txt" "$out/$name.txt" | grep -v bytes | sed 's/^/    /'
    fi
done

# Code size: .text of each part of the engine for Cortex-M3 at -Os.
IFS=' 	
'
if command -v arm-none-eabi-gcc >/dev/null 2>&1; then
    echo "cross: .text bytes for Cortex-M3 at -Os:"
    for part in core raster scene frame measure shadow/occlude shadow/bvh shadow/smlookup shadow/registry \
                $(ls engine/shadow/*.c | sed -n 's|engine/shadow/\([a-z]*\)\.c|\1|p' | \
                  grep -v -x -e occlude -e bvh -e registry -e smlookup -e asm_tree -e rtw_warp -e spsm_texel -e spsm_outline); do
        case $part in
            core|raster|scene|frame|measure) files=$(ls engine/$part/*.c) ;;
            shadow/*) files=engine/$part.c ;;
            *) files=$(ls engine/shadow/$part.c engine/shadow/${part}_*.c 2>/dev/null) ;;
        esac
        total=0
        for f in $files; do
            arm-none-eabi-gcc -std=c99 -Os -mcpu=cortex-m3 -mthumb -ffreestanding -ffp-contract=off \
                -Iinclude -c "$f" -o "$out/size.o" 2>/dev/null || continue
            t=$(arm-none-eabi-size "$out/size.o" | awk 'NR == 2 {print $1}')
            total=$((total + t))
        done
        printf '    %-16s %7d\n' "$part" "$total"
    done
fi

echo "cross: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
