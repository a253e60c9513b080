#!/bin/sh
# count-table.sh — the firmware README's tables of instructions a frame, from what the
# Cortex-M count of `make cross-test` wrote (out/cross/m4.csv, out/cross/m7.csv; run
# `CROSS_ONLY=m4-count make cross-test` first): millions of instructions per frame and
# the frames a second they make at a stated clock and cycles per instruction (CPI):
# a Cortex-M4F at 168 MHz (STM32F4) and 1.25, a Cortex-M7 at 600 MHz (i.MX RT1062,
# Teensy 4) and 1.0. The CPIs are assumptions, not measurements: qemu counts
# instructions, not cycles. Prints Markdown.
set -eu
cd "$(dirname "$0")/../.."
m4=out/cross/m4.csv m7=out/cross/m7.csv
for f in "$m4" "$m7"; do
    [ -f "$f" ] || { echo "count-table.sh: no $f: run CROSS_ONLY=m4-count make cross-test first" >&2; exit 1; }
done
echo "Cortex-M4F at 168 MHz and 1.25 cycles an instruction (M: millions of instructions a frame):"
echo
awk -F, -v mhz=168 -v cpi=1.25 '
    function m(n) { return sprintf("%.1f", n / 1e6) }
    function fps(n) { return sprintf("%.1f", mhz * 1e6 / (cpi * n)) }
    NR == 1 { next }
    { key = $1 "@" $3 "x" $4; ins[$2, key] = $6; eye[$2, key] = $7; if (!($2 in seen)) { seen[$2] = 1; order[++n] = $2 } }
    END {
        print "| method | small 160x120, M | of which eye | fps | small 320x240, M | of which eye | fps | default 160x120, M |"
        print "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
        for (i = 1; i <= n; i++) {
            k = order[i]
            printf "| `%s` | %s | %s | %s | %s | %s | %s | %s |\n", k,
                m(ins[k, "small@160x120"]), m(eye[k, "small@160x120"]), fps(ins[k, "small@160x120"]),
                m(ins[k, "small@320x240"]), m(eye[k, "small@320x240"]), fps(ins[k, "small@320x240"]),
                m(ins[k, "default@160x120"])
        }
    }' "$m4"
echo
echo "Cortex-M7 at 600 MHz and 1.0 cycles an instruction, small scene:"
echo
awk -F, -v mhz=600 -v cpi=1.0 '
    function m(n) { return sprintf("%.1f", n / 1e6) }
    function fps(n) { return sprintf("%.0f", mhz * 1e6 / (cpi * n)) }
    NR == 1 { next }
    { key = $3 "x" $4; ins[$2, key] = $6; if (!($2 in seen)) { seen[$2] = 1; order[++n] = $2 } }
    END {
        print "| method | 160x120, M | fps | 320x240, M | fps |"
        print "| --- | ---: | ---: | ---: | ---: |"
        for (i = 1; i <= n; i++) {
            k = order[i]
            printf "| `%s` | %s | %s | %s | %s |\n", k, m(ins[k, "160x120"]), fps(ins[k, "160x120"]),
                m(ins[k, "320x240"]), fps(ins[k, "320x240"])
        }
    }' "$m7"
