#!/bin/sh
# run.sh — `make cross-test`: builds the cross driver (driver.c) for every compiler and
# CPU below, runs each (natively, under qemu-user, or as Cortex-M firmware under
# qemu-system-arm) and checks that every build prints the reference build's frame and
# mask hashes, line for line, for the cases it renders (driver.c lists them).
#
# A toolchain or emulator that is missing fails the run, unless CROSS_SKIP_MISSING=1
# (then it is reported and skipped); .ci/run installs them all. Builds marked "loose"
# are outside the promise (tests/README.md, make cross-test): they must render every case and end,
# and their differing frames are counted, not failed. CROSS_ONLY=REGEX runs only the
# builds whose names match (and the reference), for working on one target.
set -u
cd "$(dirname "$0")/../.."
out=build/cross
t_start=$(date +%s)
skip_missing=${CROSS_SKIP_MISSING:-0}
if [ "${1:-}" != --one ]; then   # (--one: one build, run by this script in parallel)
    rm -rf "$out"
    mkdir -p "$out"
    # The stability case's scene as a C string for the driver (a board has no files).
    sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' -e 's/^/"/' -e 's/$/\\n"/' tests/stability/fast-camera.scene \
        >"$out/stab_scene.h"
fi

ENGINE=$(find engine -name '*.c' | sort | tr '\n' ' ')
WARN="-std=c99 -Wall -Wextra -Wpedantic -Werror -Iinclude -I$out"
# What the Makefile passes gcc (clang has no such flag): see its DETERM.
GX=-fexcess-precision=standard
# Which cases a build renders (driver.c's OM_CROSS_ONLY: bit 5 * size + case; sizes
# 160x120, 320x240, 640x480; cases default, default-aa, cloud, stab, moving). x86 renders them
# all; the CPUs under qemu-user the 640x480 ones, where last-bit differences show; the
# boards, about 100x slower under qemu-system-arm (those without a double FPU, M0, M3
# and M4, 3-6x slower again), all five at 160x120 and the default scene at 320x240,
# through strips; the M0, the slowest (soft float, Thumb-1), the 160x120 ones, its
# arithmetic checked at 320x240 by the M3's (soft float too). Builds run in parallel
# (below), which keeps the whole run within 20 minutes on two cores.
ALL=0x7fff
BIG=0x7c00
BOARD=0x3f

# The boards' CPUs. The M0 firmware runs on the M3 board (QEMU has no M0 board) with
# the traps of driver.c on, so that it faults where an M0 would.
M0="-mcpu=cortex-m0 -DOM_CROSS_TRAPS=0x18"
M3="-mcpu=cortex-m3 -DOM_CROSS_TRAPS=0x10"
M4="-mcpu=cortex-m4 -mfloat-abi=hard -mfpu=fpv4-sp-d16 -DOM_CROSS_TRAPS=0x10"
M7="-mcpu=cortex-m7 -mfloat-abi=hard -mfpu=fpv5-d16 -DOM_CROSS_TRAPS=0x10"

# name | kind | compiler | flags | runner (qemu-user command, or the board) | cases
# kind: same (must match the reference), loose (out of the promise), board.
# The first is the reference; it renders every case.
configs="x86_64-gcc-O2|same|gcc|-O2 $GX|-|$ALL
x86_64-gcc-O0|same|gcc|-O0 $GX|-|$ALL
x86_64-gcc-O3-native|same|gcc|-O3 -march=native $GX|-|$ALL
x86_64-clang-O0|same|clang|-O0|-|$ALL
x86_64-clang-O2|same|clang|-O2|-|$ALL
x86_64-clang-O3-native|same|clang|-O3 -march=native|-|$ALL
i386-gcc-O2|same|gcc|-O2 -m32 -msse2 -mfpmath=sse $GX|-|$ALL
i386-clang-O2|same|clang|-O2 -m32 -msse2 -mfpmath=sse|-|$ALL
i386-x87-gcc-O2|loose|gcc|-O2 -m32 -mfpmath=387 $GX -DOM_ALLOW_EXCESS_PRECISION|-|$ALL
i386-x87-clang-O2|loose|clang|-O2 -m32 -mno-sse -DOM_ALLOW_EXCESS_PRECISION|-|$ALL
aarch64-gcc-O2|same|aarch64-linux-gnu-gcc|-O2 $GX|qemu-aarch64 -L /usr/aarch64-linux-gnu|$BIG
aarch64-clang-O2-nocontractflag|same|clang|-O2 --target=aarch64-linux-gnu|qemu-aarch64 -L /usr/aarch64-linux-gnu|$BIG
riscv64-gcc-O2|same|riscv64-linux-gnu-gcc|-O2 $GX|qemu-riscv64 -L /usr/riscv64-linux-gnu|$BIG
armhf-gcc-O2|same|arm-linux-gnueabihf-gcc|-O2 $GX|qemu-arm -L /usr/arm-linux-gnueabihf|$BIG
ppc32-gcc-O2|same|powerpc-linux-gnu-gcc|-O2 $GX|qemu-ppc -L /usr/powerpc-linux-gnu|$BIG
s390x-gcc-O2|same|s390x-linux-gnu-gcc|-O2 -fexcess-precision=fast|qemu-s390x -L /usr/s390x-linux-gnu|$BIG
s390x-clang-O0|same|clang|-O0 --target=s390x-linux-gnu|qemu-s390x -L /usr/s390x-linux-gnu|$BIG
cortex-m0-gcc-O2|board|arm-none-eabi-gcc|-O2 $M0|mps2-an385|0x1f
cortex-m0-clang-O2|board|clang|-O2 $M0|mps2-an385|0x1f
cortex-m3-gcc-O2|board|arm-none-eabi-gcc|-O2 $M3|mps2-an385|$BOARD
cortex-m3-clang-O2|board|clang|-O2 $M3|mps2-an385|$BOARD
cortex-m4-gcc-O2|board|arm-none-eabi-gcc|-O2 $M4|mps2-an386|$BOARD
cortex-m4-clang-O2|board|clang|-O2 $M4|mps2-an386|$BOARD
cortex-m7-gcc-O2|board|arm-none-eabi-gcc|-O2 $M7|mps2-an500|$BOARD
cortex-m7-gcc-O0|board|arm-none-eabi-gcc|-O0 $M7|mps2-an500|$BOARD
cortex-m7-gcc-Os|board|arm-none-eabi-gcc|-Os $M7|mps2-an500|$BOARD
cortex-m7-clang-O0|board|clang|-O0 $M7|mps2-an500|$BOARD
cortex-m7-clang-O2|board|clang|-O2 $M7|mps2-an500|$BOARD
cortex-m7-clang-Os|board|clang|-Os $M7|mps2-an500|$BOARD"
# s390x clang at -O1 and above runs only where the emulator multiplies two floats into
# a double (mdebr, mdeb) right: QEMU 7.2 does not, and clang's optimised code uses the
# instruction (asm.c) where gcc's does not, so the frames would differ through the
# emulator's fault, not the engine's (tests/README.md, make cross-test). A probe decides.

# The board build: the same driver, the firmware of platform/cortex-m, every method in
# an arena of 256 KiB (the target for small machines; a method whose minimum is
# larger prints "too big" and fails the run), the scene in 640 KiB.
BFLAGS="-std=c99 -Wall -Wextra -Werror -ffp-contract=off -ffreestanding -mthumb -Iinclude -I$out \
-DOM_CROSS_METHOD_MEM=(256u<<10) -DOM_CROSS_SCENE_MEM=(640u<<10) -ffunction-sections -fdata-sections"
BSRC="$ENGINE tests/cross/driver.c platform/cortex-m/startup.c platform/cortex-m/semihost.c"

# The case names a selection renders, one a line, in the driver's order.
case_names() {
    m=$(($1))
    z=0
    for size in 160x120 320x240 640x480; do
        c=0
        for cs in default default-aa cloud stab moving; do
            if [ $(((m >> (5 * z + c)) & 1)) -eq 1 ]; then
                case $cs in
                    stab|moving) echo "$cs-t0@$size"; echo "$cs-t1@$size" ;;
                    *) echo "$cs@$size" ;;
                esac
            fi
            c=$((c + 1))
        done
        z=$((z + 1))
    done
}

# One build: compiles the driver, runs it, compares its lines with the reference's
# ($ref, empty while the reference itself runs). Prints what it found and writes
# "$out/NAME.result": the outcome (ref, pass, loose, fail or skip) and the summary's
# note. Builds run in parallel (CROSS_JOBS at a time, default the CPUs online), each
# in its own files; the summary then lists them in the order above.
result() { printf '%s\t%s\n' "$1" "$2" >"$out/$name.result"; }
run_one() {
    c=$1
    IFS='|'
    set -- $c
    name=$1 kind=$2 cc=$3 flags=$4 runner=$5 only=$6
    IFS=' 	
'
    t0=$(date +%s)
    [ "$runner" = - ] && runner=""
    needs="$cc ${runner%% *}"
    [ "$kind" = board ] && needs="$cc arm-none-eabi-gcc qemu-system-arm"
    missing=""
    for t in $needs; do command -v "$t" >/dev/null 2>&1 || missing="$missing $t"; done
    if [ -n "$missing" ]; then
        if [ "$skip_missing" = 1 ]; then
            echo "cross: skip $name (not installed:$missing; CROSS_SKIP_MISSING=1)"
            result skip "skipped: not installed:$missing"
        else
            echo "cross: FAIL $name: not installed:$missing (CROSS_SKIP_MISSING=1 skips it)"
            result fail "FAIL: not installed:$missing"
        fi
        return
    fi
    if [ "$kind" = board ] && [ "$cc" = clang ]; then
        # clang compiles for its bare-metal target with newlib's headers and enum size
        # (arm-none-eabi-gcc's -fshort-enums); arm-none-eabi-gcc links
        mkdir -p "$out/$name.obj"
        : >"$out/$name.err"
        for f in $BSRC; do
            # shellcheck disable=SC2086
            clang --target=arm-none-eabi --sysroot=/usr/lib/arm-none-eabi -fshort-enums $BFLAGS $flags \
                -DOM_CROSS_ONLY=$only -c "$f" -o "$out/$name.obj/$(echo "$f" | tr / _).o" 2>>"$out/$name.err" ||
                echo "build failed: $f" >>"$out/$name.err"
        done
        ! grep -q "^build failed" "$out/$name.err" &&
        # shellcheck disable=SC2086
        arm-none-eabi-gcc -mthumb $flags "$out/$name.obj"/*.o -T platform/cortex-m/mps2.ld -nostartfiles \
            -Wl,--gc-sections -lm -lc -lgcc -o "$out/$name" 2>>"$out/$name.err"
    elif [ "$kind" = board ]; then
        # shellcheck disable=SC2086
        $cc $BFLAGS $flags -DOM_CROSS_ONLY=$only $BSRC -T platform/cortex-m/mps2.ld -nostartfiles \
            -Wl,--gc-sections -lm -lc -lgcc -o "$out/$name" 2>"$out/$name.err"
    else
        # A build named *-nocontractflag goes without -ffp-contract=off: the engine's
        # FP_CONTRACT pragma must keep clang from fusing (core.h).
        fpc=-ffp-contract=off
        case $name in *-nocontractflag) fpc="" ;; esac
        # shellcheck disable=SC2086
        $cc $WARN $fpc $flags -DOM_CROSS_BIG -DOM_CROSS_ONLY=$only $ENGINE \
            tests/cross/driver.c tests/cross/host_linux.c -lm -o "$out/$name" 2>"$out/$name.err"
    fi
    if [ $? -ne 0 ]; then
        echo "cross: FAIL $name does not build: $(head -c 600 "$out/$name.err")"
        result fail "FAIL: does not build"
        return
    fi
    ok=true
    if [ "$kind" = board ]; then
        # semihosting writes to stderr; the exit status says whether the driver succeeded
        timeout 900 qemu-system-arm -M "$runner" -nographic -monitor none -serial none \
            -semihosting-config enable=on,target=native -kernel "$out/$name" >"$out/$name.txt" 2>&1 || ok=false
    else
        # shellcheck disable=SC2086
        timeout 600 $runner "$out/$name" >"$out/$name.txt" 2>&1 || ok=false
        # A kernel built without 32-bit support cannot exec the i386 builds: run them
        # under qemu-i386 then, which gives the same bits (it emulates the arithmetic).
        # The refusal reads "Exec format error", or, where the C library's execvp hands
        # the file to /bin/sh as a script, the shell's complaint about it.
        if ! $ok && [ -z "$runner" ] &&
           grep -Eq "Exec format error|Syntax error|cannot execute binary file" "$out/$name.txt" &&
           command -v qemu-i386 >/dev/null 2>&1; then
            echo "cross: $name: this kernel does not run it natively, so under qemu-i386"
            ok=true
            timeout 600 qemu-i386 "$out/$name" >"$out/$name.txt" 2>&1 || ok=false
        fi
    fi
    secs=$(($(date +%s) - t0))
    case_names "$only" >"$out/$name.cases"
    grep -v '^bytes' "$out/$name.txt" >"$out/$name.hashes"
    if ! $ok; then
        echo "cross: FAIL $name exits non-zero (or ran past its time): $(tail -c 600 "$out/$name.txt")"
        result fail "FAIL: exits non-zero or ran past its time (${secs} s)"
        return
    fi
    if [ -z "$ref" ]; then
        n=$(grep -c . "$out/$name.hashes")
        echo "cross: $name is the reference: $n frames (${secs} s)"
        result ref "reference, $n frames (${secs} s)"
        return
    fi
    # What the reference printed for this build's cases.
    awk 'NR == FNR { want[$1] = 1; next } ($1 in want)' "$out/$name.cases" "$out/$ref.hashes" >"$out/$name.want"
    n=$(grep -c . "$out/$name.want")
    if [ "$kind" = loose ]; then
        if [ "$(cut -d' ' -f1,2 "$out/$name.want")" != "$(cut -d' ' -f1,2 "$out/$name.hashes")" ]; then
            echo "cross: FAIL $name did not render every case:"
            diff "$out/$name.want" "$out/$name.hashes" | sed 's/^/    /' | head -20
            result fail "FAIL: missing cases"
        else
            d=$(diff "$out/$name.want" "$out/$name.hashes" | grep -c '^>')
            echo "cross: $name (outside the promise) renders every case; $d of $n frames differ (${secs} s)"
            result loose "out of the promise: ends, $d of $n frames differ (${secs} s)"
        fi
    elif cmp -s "$out/$name.want" "$out/$name.hashes"; then
        extra=""
        [ "$kind" = board ] && extra=", $(arm-none-eabi-size "$out/$name" | awk 'NR == 2 {print $1}') bytes of code"
        echo "cross: $name matches: $n frames (${secs} s$extra)"
        result pass "matches, $n frames (${secs} s)"
        if [ "$kind" = board ] && [ "${name#*-gcc-O2}" != "$name" ]; then
            grep '^bytes' "$out/$name.txt" | awk '{printf "    %-6s peak %8d, minimum %8d: %s\n", $2, $3, $5, $5 <= 262144 ? "fits 256 KiB" : "over 256 KiB"}'
        fi
    else
        d=$(diff "$out/$name.want" "$out/$name.hashes" | grep -c '^>')
        echo "cross: FAIL $name differs from $ref in $d of $n frames:"
        diff "$out/$name.want" "$out/$name.hashes" | sed 's/^/    /' | head -40
        result fail "FAIL: $d of $n frames differ (${secs} s)"
    fi
}

if [ "${1:-}" = --one ]; then
    name=${2%%|*}
    run_one "$2" >"$out/$name.log" 2>&1
    cat "$out/$name.log"
    exit 0
fi

pass=0
fail=0
skip=0
loose=0
summary=""
note() { summary="$summary$(printf '    %-40s %s' "$1" "$2")
"; }

if command -v clang >/dev/null 2>&1 && command -v qemu-s390x >/dev/null 2>&1 &&
   clang --target=s390x-linux-gnu $WARN -O2 tests/cross/mdebr_probe.c -o "$out/mdebr-probe" \
       >"$out/mdebr-probe.txt" 2>&1; then
    if qemu-s390x -L /usr/s390x-linux-gnu "$out/mdebr-probe" >"$out/mdebr-probe.txt" 2>&1; then
        configs="$configs
s390x-clang-O2|same|clang|-O2 --target=s390x-linux-gnu|qemu-s390x -L /usr/s390x-linux-gnu|$BIG"
    else
        echo "cross: s390x-clang-O2 not run: this QEMU's mdebr is wrong ($(cat "$out/mdebr-probe.txt"))"
        note s390x-clang-O2 "not run: the emulator's mdebr is wrong (tests/cross/mdebr_probe.c)"
    fi
fi

# The reference first, alone; then every other build (or those CROSS_ONLY names),
# CROSS_JOBS at a time.
ref=""
todo=""
IFS='
'
for c in $configs; do
    name=${c%%|*}
    if [ -z "$ref" ]; then
        run_one "$c"
        [ "$(cut -f1 "$out/$name.result" 2>/dev/null)" = ref ] || { printf 'cross: FAIL the reference %s did not run\n' "$name"; exit 1; }
        ref=$name
        continue
    fi
    if [ -n "${CROSS_ONLY:-}" ] && ! echo "$name" | grep -Eq -- "$CROSS_ONLY"; then continue; fi
    todo="$todo$c
"
done
IFS=' 	
'
jobs=${CROSS_JOBS:-$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 2)}
export ref CROSS_SKIP_MISSING
printf '%s' "$todo" | tr '\n' '\0' | xargs -0 -r -n 1 -P "$jobs" sh tests/cross/run.sh --one
all="$ref
$todo"
IFS='
'
for c in $all; do
    name=${c%%|*}
    [ -n "$name" ] || continue
    IFS='	' read -r what why <"$out/$name.result" || { what=fail why="FAIL: no result"; }
    case $what in
        ref|pass) pass=$((pass + 1)) ;;
        loose) loose=$((loose + 1)) ;;
        skip) skip=$((skip + 1)) ;;
        *) fail=$((fail + 1)) ;;
    esac
    note "$name" "$why"
done
IFS=' 	
'

# Instructions per frame on the Cortex-M4 (driver.c's OM_CROSS_COUNT): every method on
# the small scene at 160x120 and 320x240, its animated variant (the ball rolling: a
# frame after a move, the pose apart) and the default scene at 160x120, strips of 8
# rows, counted under qemu-system-arm -icount shift=0, with each method's least arena,
# whole footprint and first frame (the driver fails when a footprint on the small scene
# or its animated variant at 160x120 passes 256 KiB). Written to out/cross/m4.csv (the report reads it) with the
# firmware's sizes in out/cross/m4-size.csv; a table here. Then the Cortex-M7
# (mps2-an500, double FPU) on the small scene for none, sm and hybrid, in
# out/cross/m7.csv: what an M7-class chip runs.
count_cpu() {   # count_cpu NAME FLAGS BOARD [METHODS]
    cpu=$1 cflags=$2 board=$3 only=${4:+-DOM_CROSS_COUNT_ONLY=\"$4\"}
    csv=out/cross/$cpu.csv
    mkdir -p out/cross
    # shellcheck disable=SC2086
    arm-none-eabi-gcc $BFLAGS -O2 $cflags -DOM_CROSS_COUNT -DOM_CROSS_ROWS=8 ${only:+"$only"} $BSRC -T platform/cortex-m/mps2.ld \
        -nostartfiles -Wl,--gc-sections -lm -lc -lgcc -o "$out/$cpu-count" 2>"$out/$cpu-count.err" || {
        echo "cross: FAIL the $cpu counting firmware does not build: $(head -c 600 "$out/$cpu-count.err")"
        return 1
    }
    rm -f "$csv"
    ok=true
    timeout 900 qemu-system-arm -M "$board" -icount shift=0 -nographic -monitor none -serial none \
        -semihosting-config enable=on,target=native -kernel "$out/$cpu-count" >"$out/$cpu-count.txt" 2>&1 || ok=false
    { echo "scene,method,width,height,strip_rows,instructions,eye,observe,build,resolve,shade,method_bytes,frame_bytes,scene_bytes,min_bytes,static_bytes,stack_bytes,whole_bytes,first_frame,pose"
      awk '$1 == "count" {printf "%s,%s,%s,%s,8", $2, $5, $3, $4; for (i = 6; i <= 20; i++) printf ",%s", $i; print ""}' \
          "$out/$cpu-count.txt"; } >"$csv.tmp" && mv "$csv.tmp" "$csv"
    echo "cross: $cpu ($board) instructions per frame, strips of 8 rows ($csv); fps at a clock and CPI in"
    echo "    platform/cortex-m/README.md; bytes: the method's least arena, and the whole footprint (scene,"
    echo "    frame and method arenas' peaks, other .data/.bss, the stack's deepest point), at most 256 KiB"
    echo "    on the small scene and its animated variant (moving) at 160x120; the method's first frame"
    echo "    after its init, and on moving the objects' pose and the view before the frame counted:"
    awk -F, 'function k(n,  s) { s = sprintf("%.0f", n); while (s ~ /[0-9][0-9][0-9][0-9]/) sub(/[0-9][0-9][0-9]($|,)/, ",&", s); return s }
        NR > 1 {
        g = $1 "@" $3 "x" $4
        if (g != last) { printf "    %-16s %-7s %14s %12s %12s %12s %10s %10s %14s %10s\n", "scene", "method", "instructions", "eye", "shadow", "shade", "least", "whole", "first frame", "pose"; last = g }
        printf "    %-16s %-7s %14s %12s %12s %12s %10s %10s %14s %10s\n", g, $2, k($6), k($7), k($8 + $9 + $10), k($11), k($15), k($18), k($19), k($20) }' "$csv"
    $ok || {
        echo "cross: FAIL the $cpu counting firmware: $(grep -v '^count' "$out/$cpu-count.txt" | tail -c 600)"
        return 1
    }
}
count_m4() {
    count_cpu m4 "$M4" mps2-an386 || return 1
    arm-none-eabi-size "$out/m4-count" | awk 'NR == 2 {print "build,text,data,bss"; print "cortex-m4-gcc-O2," $1 "," $2 "," $3}' \
        >out/cross/m4-size.csv
    awk -F, 'NR == 2 {printf "    firmware (every method, both scenes): .text %d, .data %d, .bss %d bytes\n", $2, $3, $4}' out/cross/m4-size.csv
    count_cpu m7 "$M7 -DOM_CROSS_COUNT_SMALL" mps2-an500 "none sm hybrid"
}
if [ -z "${CROSS_ONLY:-}" ] || echo "m4-count" | grep -Eq -- "$CROSS_ONLY"; then
    if command -v arm-none-eabi-gcc >/dev/null 2>&1 && command -v qemu-system-arm >/dev/null 2>&1; then
        t0=$(date +%s)
        if count_m4; then
            counted=1
            note m4-count "instructions per frame counted ($(($(date +%s) - t0)) s)"
        else
            fail=$((fail + 1))
            note m4-count "FAIL"
        fi
    elif [ "$skip_missing" = 1 ]; then
        skip=$((skip + 1))
        note m4-count "skipped: not installed"
    else
        fail=$((fail + 1))
        note m4-count "FAIL: arm-none-eabi-gcc or qemu-system-arm not installed"
    fi
fi

# Code size: .text of each part of the engine for Cortex-M4 at -Os, and of the README's
# embedding example as Cortex-M4 firmware (gcc -O2) with every method and with `sm`
# alone (OM_WITH_*=0 for the others); also in out/cross/code-size.csv. Then per method
# (out/cross/m4-methods.csv, for the report): its own files' code, its least arena and
# its whole footprint on the small scene at 160x120, its instructions a frame on each
# scene (m4.csv).
if command -v arm-none-eabi-gcc >/dev/null 2>&1; then
    mkdir -p out/cross
    sizes="$out/code-size.csv"
    echo "part,text" >"$sizes"
    printf 'int render_once(void);\nint om_cross_main(void);\nint om_cross_main(void) { return render_once(); }\n' \
        >"$out/example_main.c"
    for methods in all sm; do
        only=""
        [ "$methods" = sm ] && only="-DOM_WITH_NONE=0 -DOM_WITH_REF=0 -DOM_WITH_CSM=0 -DOM_WITH_ASM=0 -DOM_WITH_RTW=0 -DOM_WITH_SPSM=0 -DOM_WITH_IZB=0 -DOM_WITH_HYBRID=0"
        # shellcheck disable=SC2086
        if arm-none-eabi-gcc $BFLAGS -O2 $M4 $only -Dmain=host_main $ENGINE tests/embed/render_once.c \
               "$out/example_main.c" platform/cortex-m/startup.c platform/cortex-m/semihost.c \
               -T platform/cortex-m/mps2.ld -nostartfiles -Wl,--gc-sections -lm -lc -lgcc \
               -o "$out/example-$methods" 2>"$out/example-$methods.err"; then
            t=$(arm-none-eabi-size "$out/example-$methods" | awk 'NR == 2 {print $1}')
            [ "$methods" = sm ] && with="sm alone" || with="every method"
            echo "cross: the README's example as Cortex-M4 firmware (gcc -O2) with $with: $t bytes of code"
            echo "example-m4-$methods,$t" >>"$sizes"
        else
            echo "cross: FAIL the README's example does not build as firmware ($methods): $(head -c 400 "$out/example-$methods.err")"
            fail=$((fail + 1))
            note "example-$methods" "FAIL: does not build"
        fi
    done
    echo "cross: .text bytes for Cortex-M4 at -Os:"
    # A part: a folder of the engine, the shadow methods' shared folder, the registry,
    # and each method's folder (named by the method, as m4.csv names it).
    for part in core raster scene frame measure shadow/common shadow/registry \
                $(ls -d engine/shadow/*/ | sed 's|engine/shadow/\([a-z]*\)/|\1|' | grep -v -x common); do
        case $part in
            core|raster|scene|frame|measure|shadow/common) files=$(ls engine/$part/*.c) ;;
            shadow/registry) files=engine/$part.c ;;
            *) files=$(ls engine/shadow/$part/*.c) ;;
        esac
        total=0
        for f in $files; do
            arm-none-eabi-gcc -std=c99 -Os -mcpu=cortex-m4 -mfloat-abi=hard -mfpu=fpv4-sp-d16 -mthumb \
                -ffreestanding -ffp-contract=off \
                -Iinclude -c "$f" -o "$out/size.o" 2>/dev/null || continue
            t=$(arm-none-eabi-size "$out/size.o" | awk 'NR == 2 {print $1}')
            total=$((total + t))
        done
        printf '    %-16s %7d\n' "$part" "$total"
        echo "$part,$total" >>"$sizes"
    done
    cp "$sizes" out/cross/code-size.csv
    if [ -f out/cross/m4.csv ]; then
        awk -F, 'FNR == 1 { for (i = 1; i <= NF; i++) col[FILENAME, $i] = i; next }
            FILENAME ~ /code-size/ { text[$1] = $2; next }
            { c = col[FILENAME, "method"]; m = $c
              if ($1 == "small" && $col[FILENAME, "width"] == 160) { order[++n] = m; mn[m] = $col[FILENAME, "min_bytes"]
                                   whole[m] = $col[FILENAME, "whole_bytes"]; small[m] = $col[FILENAME, "instructions"] }
              else if ($1 == "default") big[m] = $col[FILENAME, "instructions"] }
            END { print "method,text,min_bytes,whole_bytes,instructions_small,instructions_default"
                  for (i = 1; i <= n; i++) { m = order[i]; print m "," text[m] "," mn[m] "," whole[m] "," small[m] "," big[m] } }' \
            out/cross/code-size.csv out/cross/m4.csv >out/cross/m4-methods.csv
    fi
fi

# The firmware README's figures are what count-table.sh prints from this count.
if [ -n "${counted:-}" ]; then
    rc=0
    sh tests/cross/count-table.sh --check platform/cortex-m/README.md || rc=$?
    case $rc in
        0) note readme "platform/cortex-m/README.md's tables are this count's" ;;
        2) note readme "not compared: the README was counted with another toolchain" ;;
        *) fail=$((fail + 1))
           note readme "FAIL: platform/cortex-m/README.md's tables are not this count's" ;;
    esac
fi

echo "cross: summary ($(($(date +%s) - t_start)) s in all):"
printf '%s' "$summary"
echo "cross: $pass matched, $loose outside the promise, $fail failed, $skip skipped"
[ "$fail" -eq 0 ] && [ -n "$ref" ]
