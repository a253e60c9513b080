#!/bin/sh
# count-table.sh — the firmware README's figures from what `make cross-test`'s Cortex-M
# count and code sizes wrote (out/cross/: m4.csv, m7.csv, m4-methods.csv,
# code-size.csv; `CROSS_ONLY=m4-count make cross-test` writes them all): the toolchain
# they came from, the whole footprints, the instructions a frame with the frames a
# second they make at a stated clock and cycles per instruction (CPI: a Cortex-M4F at
# 168 MHz (STM32F4) and 1.25, a Cortex-M7 at 600 MHz (i.MX RT1062, Teensy 4) and 1.0,
# assumptions, as qemu counts instructions, not cycles), and the code sizes. Prints
# Markdown, to paste into platform/cortex-m/README.md.
#
# count-table.sh --check FILE: every line it prints but blank ones must be in FILE as
# printed (tests/cross/run.sh checks the firmware README so after each count). Another
# compiler or emulator counts other figures: where FILE's "Counted with" line names
# other versions than this machine's, it says so, compares nothing and exits 2.
set -eu
cd "$(dirname "$0")/../.."
check=
if [ "${1:-}" = --check ]; then
    check=${2:?"usage: count-table.sh [--check FILE]"}
    [ -f "$check" ] || { echo "count-table.sh: no $check" >&2; exit 1; }
fi
d=out/cross
for f in m4.csv m7.csv m4-methods.csv code-size.csv; do
    [ -f "$d/$f" ] || { echo "count-table.sh: no $d/$f: run CROSS_ONLY=m4-count make cross-test first" >&2; exit 1; }
done
m4=$d/m4.csv m7=$d/m7.csv

# 1234567 as 1,234,567
commas='function commas(n,   s) { s = sprintf("%d", n); while (s ~ /[0-9][0-9][0-9][0-9]/) sub(/[0-9][0-9][0-9]([,]|$)/, ",&", s); return s }'

# table CSV MHZ CPI FPS_DIGITS HEADER CELLS: a row per method in the CSV's order; each
# cell of CELLS is WHAT:SCENE@WxH, WHAT m (millions of instructions), e (of which the
# eye pass), 1 (the method's first frame) or f (frames a second at MHZ and CPI).
table() {
    awk -F, -v mhz="$2" -v cpi="$3" -v fd="$4" -v head="$5" -v cells="$6" '
        NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        { key = $1 "@" $3 "x" $4; m = $col["method"]; ins[m, key] = $col["instructions"]; eye[m, key] = $col["eye"]
          if ("first_frame" in col) first[m, key] = $col["first_frame"]
          if (!(m in seen)) { seen[m] = 1; order[++n] = m } }
        END {
            nc = split(cells, c, " ")
            print head
            line = "| ---"
            for (j = 1; j <= nc; j++) line = line " | ---:"
            print line " |"
            for (i = 1; i <= n; i++) {
                k = order[i]
                line = "| `" k "`"
                for (j = 1; j <= nc; j++) {
                    what = substr(c[j], 1, 1); at = substr(c[j], 3)
                    v = what == "f" ? sprintf("%." fd "f", mhz * 1e6 / (cpi * ins[k, at])) \
                                    : sprintf("%.1f", (what == "e" ? eye[k, at] : what == "1" ? first[k, at] : ins[k, at]) / 1e6)
                    line = line " | " v
                }
                print line " |"
            }
        }' "$1"
}

tables() {
    echo "Counted with arm-none-eabi-gcc $(arm-none-eabi-gcc -dumpversion 2>/dev/null || echo '?') and" \
         "QEMU $(qemu-system-arm --version 2>/dev/null | awk 'NR == 1 {print $4}')."
    echo
    echo "| method | least arena | whole footprint |"
    echo "| --- | ---: | ---: |"
    awk -F, "$commas"' NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        { print "| `" $col["method"] "` | " commas($col["min_bytes"]) " | " commas($col["whole_bytes"]) " |" }' \
        "$d/m4-methods.csv"
    echo
    echo "Cortex-M4F at 168 MHz and 1.25 cycles an instruction (M: millions of instructions a frame):"
    echo
    table "$m4" 168 1.25 1 \
        "| method | small 160x120, M | of which eye | fps | small 320x240, M | of which eye | fps | default 160x120, M | moving 160x120, M | first frame, small 160x120, M |" \
        "m:small@160x120 e:small@160x120 f:small@160x120 m:small@320x240 e:small@320x240 f:small@320x240 m:default@160x120 m:moving@160x120 1:small@160x120"
    echo
    echo "Cortex-M7 at 600 MHz and 1.0 cycles an instruction, small scene:"
    echo
    table "$m7" 600 1.0 0 "| method | 160x120, M | fps | 320x240, M | fps |" \
        "m:small@160x120 f:small@160x120 m:small@320x240 f:small@320x240"
    echo
    echo "| part | bytes |"
    echo "| --- | ---: |"
    awk -F, "$commas"' NR == 1 || $1 ~ /^example-/ { next }
        { p = $1 == "shadow/common" ? "shared by methods (`shadow/common/`)" : $1 == "shadow/registry" ? \
              "registry and the method calls" : $1 ~ /^(core|raster|scene|frame|measure)$/ ? $1 : "`" $1 "`"
          print "| " p " | " commas($2) " |" }' "$d/code-size.csv"
    echo
    awk -F, "$commas"' $1 == "example-m4-all" { all = $2 } $1 == "example-m4-sm" { sm = $2 }
        END { print "The embedding example as Cortex-M4 firmware (gcc -O2): " commas(all) " bytes of code with every"
              print "method, " commas(sm) " with `sm` alone." }' "$d/code-size.csv"
}

if [ -z "$check" ]; then
    tables
    exit 0
fi
have=$(tables | head -1)
said=$(grep '^Counted with ' "$check" | head -1 || true)
if [ -n "$said" ] && [ "$have" != "$said" ]; then
    echo "count-table: $check's figures say \"$said\"; this machine: \"$have\": not compared"
    exit 2
fi
missing=$(tables | grep -v '^$' | while IFS= read -r l; do grep -qxF -- "$l" "$check" || echo "    $l"; done)
if [ -n "$missing" ]; then
    echo "count-table: FAIL $check lacks these lines of what sh tests/cross/count-table.sh prints (paste its tables there):"
    echo "$missing"
    exit 1
fi
echo "count-table: $check's tables are what sh tests/cross/count-table.sh prints"
