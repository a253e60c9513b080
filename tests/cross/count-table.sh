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
# table CSV MHZ CPI FPS_DIGITS HEADER CELLS: a row per method in the CSV's order; each
# cell of CELLS is WHAT:SCENE@WxH, WHAT m (millions of instructions), e (of which the
# eye pass), 1 (the method's first frame after its init) or f (frames a second at MHZ
# and CPI). The scene "moving" is the small scene with its ball rolling: a frame after
# a move, counted with what the move made the method redo (the pose apart).
table() {
    awk -F, -v mhz="$2" -v cpi="$3" -v fd="$4" -v head="$5" -v cells="$6" '
        NR == 1 { next }
        { key = $1 "@" $3 "x" $4; ins[$2, key] = $6; eye[$2, key] = $7; first[$2, key] = $19
          if (!($2 in seen)) { seen[$2] = 1; order[++n] = $2 } }
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
