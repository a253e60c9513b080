#!/bin/sh
# cli.sh — the `ombra` command as a user runs it: help, a default render, strips and
# budgets giving the same frame, and errors that name the file, line and fix.
# Usage: sh tests/cli.sh path/to/ombra
set -u
OMBRA=$1
dir=$(dirname "$OMBRA")/cli-test
rm -rf "$dir"
mkdir -p "$dir"
pass=0
fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "  FAIL cli: $1"; }
# expect CODE DESCRIPTION -- command...: runs it, checks the exit code, keeps stderr/stdout
expect() {
    code=$1; what=$2; shift 3
    "$@" >"$dir/out" 2>"$dir/err"
    got=$?
    if [ "$got" -eq "$code" ]; then ok; else bad "$what: exit $got, wanted $code ($(head -c 300 "$dir/err"))"; fi
}
has() {  # has FILE TEXT DESCRIPTION
    if grep -q -- "$2" "$1"; then ok; else bad "$3: '$2' not in $(head -c 300 "$1")"; fi
}

expect 0 "ombra --help" -- "$OMBRA" --help
has "$dir/out" "render" "top-level help lists render"
expect 0 "render --help" -- "$OMBRA" render --help
has "$dir/out" "--budget" "render help documents --budget"
expect 0 "info --help" -- "$OMBRA" info --help
expect 2 "no command" -- "$OMBRA"
expect 2 "unknown command" -- "$OMBRA" frobnicate
expect 2 "unknown option" -- "$OMBRA" render --frob
has "$dir/err" "unknown option '--frob'" "unknown option named"
expect 2 "bad size" -- "$OMBRA" render --size 0x10
has "$dir/err" "WxH" "bad size explains the form"
expect 2 "unknown method" -- "$OMBRA" render --method nope
has "$dir/err" "ombra methods" "unknown method points at the list"

# The default scene renders; PPM and PGM headers are right.
expect 0 "default render" -- "$OMBRA" render --size 160x120 --out "$dir/a.ppm" --mask "$dir/a.pgm"
if [ "$(head -c 15 "$dir/a.ppm" | head -n 2 | tr '\n' ' ')" = "P6 160 120 " ]; then ok; else bad "ppm header"; fi
if [ "$(head -c 15 "$dir/a.pgm" | head -n 2 | tr '\n' ' ')" = "P5 160 120 " ]; then ok; else bad "pgm header"; fi
size=$(wc -c <"$dir/a.ppm")
if [ "$size" -eq $((15 + 160 * 120 * 3)) ]; then ok; else bad "ppm size $size"; fi
hash_whole=$(grep '^hash:' "$dir/out")

# Strips and a tight budget give the very same frame.
expect 0 "quiet render" -- "$OMBRA" render --size 16x16 -q --out "$dir/q.ppm"
if [ -s "$dir/out" ]; then bad "-q printed: $(head -c 200 "$dir/out")"; else ok; fi
expect 0 "strip render" -- "$OMBRA" render --size 160x120 --strip 7 --out "$dir/b.ppm"
if [ "$(grep '^hash:' "$dir/out")" = "$hash_whole" ]; then ok; else bad "strips changed the frame"; fi
cmp -s "$dir/a.ppm" "$dir/b.ppm" && ok || bad "strip PPM differs from whole PPM"
expect 0 "info" -- "$OMBRA" info --size 160x120 --map 256
scene_bytes=$(sed -n 's/.*scene \([0-9]*\), frame.*/\1/p' "$dir/out")
sm_bytes=$(sed -n 's/^ *sm *min \([0-9]*\),.*/\1/p' "$dir/out")
budget=$((scene_bytes + sm_bytes + 160 * 44 * 10 + 4096))
expect 0 "whole render, small map" -- "$OMBRA" render --size 160x120 --map 256 --out "$dir/c0.ppm"
hash_small=$(grep '^hash:' "$dir/out")
expect 0 "budget render" -- "$OMBRA" render --size 160x120 --map 256 --budget "$budget" --out "$dir/c.ppm"
if [ "$(grep '^hash:' "$dir/out")" = "$hash_small" ]; then ok; else bad "a budget changed the frame"; fi
has "$dir/out" "strip(s) of" "budget render reports strips"
expect 1 "budget too small" -- "$OMBRA" render --size 160x120 --budget 1000 --out "$dir/d.ppm"
has "$dir/err" "too small" "small budget explained"
has "$dir/err" "need" "small budget names the minimum"
expect 0 "rgb565 render" -- "$OMBRA" render --size 160x120 --format rgb565 --out "$dir/e.ppm"

# Scene files: errors name the file, line and column; OBJ meshes load relative to it.
printf 'camera eye 0 2 5 target 0 0 0\nsphere radius 1 segmnts 8\n' >"$dir/bad.scene"
expect 1 "malformed scene" -- "$OMBRA" render "$dir/bad.scene" --out "$dir/f.ppm"
has "$dir/err" "bad.scene" "parse error names the file"
has "$dir/err" "line 2" "parse error names the line"
expect 1 "missing scene" -- "$OMBRA" render "$dir/none.scene"
has "$dir/err" "none.scene" "missing scene named"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1/1/1 3/1/1 4/1/1\nf -4 -2 -3\n' >"$dir/m.obj"
printf 'camera eye 0 2 5 target 0 0 0 size 64 48\nlight spot pos 2 6 3 target 0 0 0\nplane size 8 8\nmesh m.obj scale 2\n' >"$dir/ok.scene"
expect 0 "scene with mesh" -- "$OMBRA" render "$dir/ok.scene" --out "$dir/g.ppm"
has "$dir/out" "3 triangles\|, 5 triangles" "mesh triangles counted"
printf 'camera eye 0 2 5 target 0 0 0\nmesh missing.obj\n' >"$dir/miss.scene"
expect 1 "scene naming a missing mesh" -- "$OMBRA" render "$dir/miss.scene" --out "$dir/h.ppm"
has "$dir/err" "missing.obj" "missing mesh named"
expect 1 "unwritable output" -- "$OMBRA" render --size 16x16 --out "$dir/no/such/dir/x.ppm"
has "$dir/err" "x.ppm" "unwritable output named"

# Accuracy against the reference, in one run and from two mask files: the same figures.
expect 0 "render --against ref" -- "$OMBRA" render --size 160x120 --map 512 --against ref --mask "$dir/sm.pgm" --diff "$dir/diff.ppm" --out "$dir/sm.ppm"
has "$dir/out" "accuracy of sm against ref: match" "--against prints the match share"
against=$(grep '^accuracy' "$dir/out" | sed 's/.*match/match/')
if [ "$(head -c 2 "$dir/diff.ppm")" = "P6" ]; then ok; else bad "diff image written"; fi
expect 0 "reference mask" -- "$OMBRA" render --size 160x120 --method ref --mask "$dir/ref.pgm" --out "$dir/ref.ppm"
expect 0 "compare masks" -- "$OMBRA" compare "$dir/ref.pgm" "$dir/sm.pgm" --diff "$dir/diff2.ppm"
if [ "$(grep '^accuracy' "$dir/out" | sed 's/.*match/match/')" = "$against" ]; then ok; else bad "compare disagrees with --against"; fi
cmp -s "$dir/diff.ppm" "$dir/diff2.ppm" && ok || bad "compare's diff image differs from --against's"
expect 0 "small mask" -- "$OMBRA" render --size 16x12 --mask "$dir/small.pgm" --out "$dir/small.ppm"
expect 1 "compare masks of different sizes" -- "$OMBRA" compare "$dir/ref.pgm" "$dir/small.pgm"
has "$dir/err" "one size" "size mismatch explained"
expect 1 "compare a non-PGM" -- "$OMBRA" compare "$dir/ref.pgm" "$dir/ok.scene"
has "$dir/err" "ok.scene" "bad mask file named"

# A small sweep: one CSV row per point with every column filled, well-formed SVG.
expect 0 "bench sweep" -- "$OMBRA" bench --scenes "$dir/ok.scene" --size 48x36 --runs 1 --methods ref,izb --out "$dir/bench"
rows=$(tail -n +2 "$dir/bench/bench.csv" | wc -l)
if [ "$rows" -eq 4 ]; then ok; else bad "bench.csv has $rows rows, wanted 4 (ref + 3 izb pools)"; fi
if awk -F, 'NR == 1 {n = NF} NF != n {exit 1} {for (i = 1; i <= NF; i++) if ($i == "") exit 1}' "$dir/bench/bench.csv"; then ok; else bad "bench.csv has empty or missing columns"; fi
if [ -s "$dir/bench/ok.scene-time.svg" ] && [ -s "$dir/bench/ok.scene-bytes.svg" ]; then ok; else bad "bench charts written"; fi
if command -v xmllint >/dev/null 2>&1; then
    xmllint --noout "$dir"/bench/*.svg && ok || bad "bench SVG is not well-formed"
fi
expect 2 "bench with a bad option" -- "$OMBRA" bench --frobnicate 1
expect 0 "report" -- "$OMBRA" report --scenes "$dir/ok.scene" --size 64x48 --runs 1 --out "$dir/report"
if grep -q '<svg' "$dir/report/index.html" && grep -q 'data:image/png;base64' "$dir/report/index.html"; then ok; else bad "report carries its charts and crops"; fi
if command -v xmllint >/dev/null 2>&1; then
    xmllint --noout "$dir/report/index.html" && ok || bad "report page is not well-formed"
fi

# Frame hashes of every method on the default scene, for the cross-build comparison
# that `make test` runs (the same frames from every compiler and optimisation level).
hashes=$(dirname "$OMBRA")/frame-hashes.txt
: >"$hashes"
for m in $("$OMBRA" methods | awk 'NF == 0 {exit} {print $1}'); do
    expect 0 "render --method $m" -- "$OMBRA" render --size 160x120 --method "$m" --map 512 --out "$dir/m.ppm"
    echo "$m $(grep '^hash:' "$dir/out")" >>"$hashes"
done

echo "cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
