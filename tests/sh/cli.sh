#!/bin/sh
# cli.sh — the `ombra` command as a user runs it: help, a default render, strips and
# budgets giving the same frame, and errors that name the file, line and fix.
# Usage: sh tests/sh/cli.sh path/to/ombra
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
expect 0 "scene --small" -- "$OMBRA" scene --small
cp "$dir/out" "$dir/small.scene"
expect 0 "small scene info" -- "$OMBRA" info "$dir/small.scene"
tris=$(sed -n 's/^triangles \([0-9]*\),.*/\1/p' "$dir/out")
if [ -n "$tris" ] && [ "$tris" -le 2000 ]; then ok; else bad "the small scene has '$tris' triangles"; fi
expect 0 "small scene whole" -- "$OMBRA" render "$dir/small.scene" --size 160x120 --out "$dir/s0.ppm"
hash_s=$(grep '^hash:' "$dir/out")
expect 0 "small scene strips" -- "$OMBRA" render "$dir/small.scene" --size 160x120 --strip 8 --out "$dir/s1.ppm"
if [ "$(grep '^hash:' "$dir/out")" = "$hash_s" ]; then ok; else bad "strips (with row bins) changed the small scene"; fi
# The town: printed, read back with the triangles and bounds its help states, rendered
# (sm against ref, whole and in strips: one frame); tests/stability/town-walk.scene holds
# the same objects, light and materials; bench knows it by name.
expect 0 "scene --town" -- "$OMBRA" scene --town
cp "$dir/out" "$dir/town.scene"
expect 0 "scene --help" -- "$OMBRA" scene --help
has "$dir/out" "--town .*(10,100$" "scene help states the town's triangles"
expect 0 "town info" -- "$OMBRA" info "$dir/town.scene"
has "$dir/out" "^triangles 10100, " "the town has the triangles it states"
has "$dir/out" "^bounds: (-500, 0, -500) .. (500, 85.6, 500)$" "the town's bounds"
expect 0 "town render" -- "$OMBRA" render "$dir/town.scene" --size 160x120 --against ref --out "$dir/t0.ppm"
has "$dir/out" "^accuracy of sm against ref: match" "the town renders against ref"
hash_t=$(grep '^hash:' "$dir/out")
expect 0 "town strips" -- "$OMBRA" render "$dir/town.scene" --size 160x120 --strip 8 --out "$dir/t1.ppm"
if [ "$(grep '^hash:' "$dir/out")" = "$hash_t" ]; then ok; else bad "strips changed the town"; fi
objects() { grep -v '^#\|^camera \|^key \|^$' "$1"; }
walk=$(dirname "$0")/../stability/town-walk.scene
if [ "$(objects "$walk")" = "$(objects "$dir/town.scene")" ]; then ok; else bad "$walk is not the town's objects"; fi
expect 0 "bench on the town" -- "$OMBRA" bench --scenes town@64x48 --methods sm --runs 1 --no-scaling --out "$dir/bench-town"
has "$dir/out" "^town *sm " "bench measures the town"
# Every value a setting takes renders: an importance map asked below 8 texels is 8.
expect 0 "rtw.importance 3" -- "$OMBRA" render --size 64x48 --method rtw --set rtw.importance=3 --out "$dir/i3.ppm"
hash_i=$(grep '^hash:' "$dir/out")
expect 0 "rtw.importance 8" -- "$OMBRA" render --size 64x48 --method rtw --set rtw.importance=8 --out "$dir/i8.ppm"
if [ "$(grep '^hash:' "$dir/out")" = "$hash_i" ]; then ok; else bad "rtw.importance 3 is not 8"; fi
expect 2 "scene --big" -- "$OMBRA" scene --big
has "$dir/err" "only --small" "scene names its one option"
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
has "$dir/out" "match [0-9.]*% of [0-9]* covered samples" "the accuracy line counts covered samples"
has "$dir/out" "^samples: [0-9]* covered (not background), [0-9]* of them exposed" "render tells covered from exposed samples"
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
# masks of different frames (here another scene) are refused, not compared
expect 0 "mask of another scene" -- "$OMBRA" render "$dir/ok.scene" --size 160x120 --mask "$dir/other.pgm" --out "$dir/other.ppm"
expect 1 "compare masks of different scenes" -- "$OMBRA" compare "$dir/ref.pgm" "$dir/other.pgm" --diff "$dir/other-diff.ppm"
has "$dir/err" "not masks of one frame" "different frames explained"
has "$dir/err" "same SCENE, --size and --time" "different frames: the fix named"
[ -e "$dir/other-diff.ppm" ] && bad "compare of different frames wrote a diff" || ok
if [ -s "$dir/out" ]; then bad "compare of different frames printed figures: $(head -c 200 "$dir/out")"; else ok; fi

# A small sweep: one CSV row per point with every column filled, well-formed SVG.
expect 0 "bench sweep" -- "$OMBRA" bench --scenes "$dir/ok.scene" --runs 1 --methods ref,izb --out "$dir/bench"
rows=$(tail -n +2 "$dir/bench/bench.csv" | wc -l)
if [ "$rows" -eq 4 ]; then ok; else bad "bench.csv has $rows rows, wanted 4 (ref + 3 izb pools)"; fi
if awk -F, 'NR == 1 {n = NF} NF != n {exit 1} {for (i = 1; i <= NF; i++) if ($i == "") exit 1}' "$dir/bench/bench.csv"; then ok; else bad "bench.csv has empty or missing columns"; fi
if [ -s "$dir/bench/ok.scene-time.svg" ] && [ -s "$dir/bench/ok.scene-bytes.svg" ]; then ok; else bad "bench charts written"; fi
has "$dir/out" "^machine *compute *[0-9.]* *[0-9.]* *[0-9.]*x" "bench scaling table has the machine's compute row"
has "$dir/out" "^machine *memory *[0-9.]* *[0-9.]* *[0-9.]*x" "bench scaling table has the machine's memory row"
has "$dir/out" "^ok.scene *izb *[0-9.]* *[0-9.]* *[0-9.]*x" "bench scaling table has a method's row"
# the footnote on '*' only under a starred row
if grep -q '[0-9]x\*' "$dir/out"; then has "$dir/out" "^(\* fewer jobs" "a starred row has its footnote"
elif grep -q "fewer jobs ran" "$dir/out"; then bad "bench prints the '*' footnote with no starred row"; else ok; fi
if command -v xmllint >/dev/null 2>&1; then
    xmllint --noout "$dir"/bench/*.svg && ok || bad "bench SVG is not well-formed"
fi
expect 2 "bench with a bad option" -- "$OMBRA" bench --frobnicate 1
expect 0 "report" -- "$OMBRA" report --scenes "$dir/ok.scene" --size 64x48 --runs 1 --out "$dir/report"
if grep -q '<svg' "$dir/report/index.html" && grep -q 'data:image/png;base64' "$dir/report/index.html"; then ok; else bad "report carries its charts and crops"; fi
if command -v xmllint >/dev/null 2>&1; then
    xmllint --noout "$dir/report/index.html" && ok || bad "report page is not well-formed"
fi

# Nothing lost: every output is written to a temporary beside it and renamed over the
# old file only once whole, so a later failure, a kill or a full device leaves the old
# file's bytes; streams and devices are written directly, with errors naming the path.
cp "$dir/a.ppm" "$dir/good.ppm"
cp "$dir/a.ppm" "$dir/keep.ppm"
leftovers() { ls -A "$dir" | grep '^\.' ; }
expect 1 "a failing mask leaves the old image" -- "$OMBRA" render --size 64x48 --out "$dir/good.ppm" --mask "$dir/no/such/m.pgm"
has "$dir/err" "m.pgm: cannot create: No such file or directory" "failed output named with its reason"
if grep -q "input/output error" "$dir/err"; then bad "a missing directory reads as an I/O error"; else ok; fi
cmp -s "$dir/good.ppm" "$dir/keep.ppm" && ok || bad "the old image was damaged by a failed render"
expect 1 "a render onto a full device" -- "$OMBRA" render --size 64x48 --out /dev/full
has "$dir/err" "/dev/full: cannot write: No space left on device" "full device named, with the reason"
# killed midway (a file-size limit kills it while it writes): the old file survives whole
(ulimit -f 20; "$OMBRA" render --size 160x120 --out "$dir/good.ppm" -q; echo $? >"$dir/code") >/dev/null 2>&1
if [ "$(cat "$dir/code")" -ne 0 ]; then ok; else bad "a render over the file-size limit succeeded"; fi
cmp -s "$dir/good.ppm" "$dir/keep.ppm" && ok || bad "a killed render damaged the old image"
if [ -z "$(leftovers)" ]; then ok; else bad "temporaries left behind: $(leftovers)"; fi
# a write that fails (the file-size limit with its signal ignored: EFBIG, as a full
# disk gives ENOSPC) leaves the old file and names the reason
(ulimit -f 20; trap '' XFSZ; "$OMBRA" render --size 160x120 --out "$dir/good.ppm" -q; echo $? >"$dir/code") >/dev/null 2>"$dir/err"
if [ "$(cat "$dir/code")" -eq 1 ]; then ok; else bad "a render past the file-size limit: exit $(cat "$dir/code"), wanted 1"; fi
has "$dir/err" "good.ppm: cannot write: File too large" "a failed write names the file and the reason"
cmp -s "$dir/good.ppm" "$dir/keep.ppm" && ok || bad "a failed write damaged the old image"
if [ -z "$(leftovers)" ]; then ok; else bad "temporaries left behind: $(leftovers)"; fi
expect 2 "an empty output name" -- "$OMBRA" render --size 16x12 --out ''
has "$dir/err" "--out '': no extension" "an empty output name is refused"
expect 2 "--out and --mask the same file" -- "$OMBRA" render --size 16x12 --out "$dir/good.ppm" --mask "$dir/./good.ppm"
has "$dir/err" "same file" "the same path twice explained"
# threads under a budget: counted in it, capped to a sixteenth of it, the same frame
expect 0 "many threads under a budget" -- "$OMBRA" render --size 160x120 --budget 1M --threads 1024 --method izb --out "$dir/t1024.ppm"
h1024=$(grep '^hash' "$dir/out")
expect 0 "one thread under a budget" -- "$OMBRA" render --size 160x120 --budget 1M --threads 1 --method izb --out "$dir/t1.ppm"
if [ -n "$h1024" ] && [ "$h1024" = "$(grep '^hash' "$dir/out")" ]; then ok; else bad "--threads 1024 under --budget drew another frame"; fi
expect 0 "info names the threads' share" -- "$OMBRA" info
has "$dir/out" "counts 16384 bytes" "info reports what a thread counts of a budget"
# nor may an output be a mesh the scene reads: refused before anything is written (a
# mesh under an image's name, since an .obj is no name for an image at all)
printf 'v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n' >"$dir/tri.png"
printf 'mesh tri.png\n' >"$dir/mesh.scene"
expect 2 "--out over a mesh the scene reads" -- "$OMBRA" render "$dir/mesh.scene" --size 16x12 --out "$dir/tri.png"
has "$dir/err" "a mesh of the scene and --out name the same file" "the mesh named"
if [ "$(head -c 6 "$dir/tri.png")" = "v 0 0 " ]; then ok; else bad "the mesh was overwritten"; fi
expect 2 "--mask over a mesh the scene reads" -- "$OMBRA" render "$dir/mesh.scene" --size 16x12 --out "$dir/m.ppm" --mask "$dir/./tri.png"
cp "$dir/tri.png" "$dir/tri.obj"
expect 2 "--out over an .obj" -- "$OMBRA" render --size 16x12 --out "$dir/tri.obj"
has "$dir/err" "unknown extension '.obj'" "an .obj output refused by its extension"
# a binary file as the scene is refused at its first bytes, not read whole
head -c 3000000 /dev/zero >"$dir/zeros.scene"
expect 1 "a file of zeros as the scene" -- "$OMBRA" render "$dir/zeros.scene" --size 16x12 --out "$dir/z.ppm"
has "$dir/err" "not a text file: byte 0 is NUL" "the NUL byte named"
cmp -s "$dir/good.ppm" "$dir/keep.ppm" && ok || bad "--out x --mask x damaged x"
expect 2 "--diff over --out" -- "$OMBRA" render --size 16x12 --against ref --out "$dir/good.ppm" --diff "$dir/good.ppm"
expect 2 "--out over the scene" -- "$OMBRA" render "$dir/ok.scene" --out "$dir/ok.scene"
has "$dir/ok.scene" "mesh m.obj" "the scene survives --out over it"
expect 0 "--out /dev/null --mask /dev/null" -- "$OMBRA" render --size 16x12 --out /dev/null --mask /dev/null
# '-' is standard output; the report then goes to standard error
"$OMBRA" render --size 16x12 --out - >"$dir/stdout.ppm" 2>"$dir/err"
if [ $? -eq 0 ] && [ "$(wc -c <"$dir/stdout.ppm")" -eq $((13 + 16 * 12 * 3)) ] && [ "$(head -c 2 "$dir/stdout.ppm")" = "P6" ]; then ok; else bad "--out - is not the image alone on standard output"; fi
has "$dir/err" "hash:" "with --out - the report goes to standard error"
expect 0 "reference 16x12 image" -- "$OMBRA" render --size 16x12 --out "$dir/r16.ppm"
cp "$dir/out" "$dir/r16.out"
cmp -s "$dir/stdout.ppm" "$dir/r16.ppm" && ok || bad "--out - differs from the file"
if command -v mkfifo >/dev/null 2>&1; then
    rm -f "$dir/fifo"
    mkfifo "$dir/fifo"
    cat "$dir/fifo" >"$dir/fifo.ppm" &
    expect 0 "render into a FIFO" -- "$OMBRA" render --size 16x12 --out "$dir/fifo"
    wait
    cmp -s "$dir/fifo.ppm" "$dir/r16.ppm" && ok || bad "the FIFO got other bytes"
    rm -f "$dir/fifo"
fi
# a symlink stays a link to the file that is replaced, a dangling one is followed,
# and a replaced file keeps its permissions
rm -f "$dir/real.ppm" "$dir/link.ppm" "$dir/dangling.pgm"
cp "$dir/keep.ppm" "$dir/real.ppm"
chmod 640 "$dir/real.ppm"
ln -s real.ppm "$dir/link.ppm"
ln -s sub/made.pgm "$dir/dangling.pgm"
mkdir -p "$dir/sub"
expect 0 "render through a symlink" -- "$OMBRA" render --size 16x12 --out "$dir/link.ppm" --mask "$dir/dangling.pgm"
if [ -L "$dir/link.ppm" ] && [ -L "$dir/dangling.pgm" ] && cmp -s "$dir/real.ppm" "$dir/r16.ppm" && [ "$(head -c 2 "$dir/sub/made.pgm")" = "P5" ]; then ok; else bad "symlinks were replaced instead of their files"; fi
if [ "$(ls -l "$dir/real.ppm" | cut -c1-10)" = "-rw-r-----" ]; then ok; else bad "the replaced file lost its permissions: $(ls -l "$dir/real.ppm")"; fi
# two renders racing to one name: the file is one of them whole, never a mix
expect 0 "reference 160x120 image" -- "$OMBRA" render --size 160x120 --out "$dir/r160.ppm"
"$OMBRA" render --size 160x120 --out "$dir/race.ppm" -q & p1=$!
"$OMBRA" render --size 16x12 --out "$dir/race.ppm" -q & p2=$!
wait $p1; r1=$?; wait $p2; r2=$?
if [ $r1 -eq 0 ] && [ $r2 -eq 0 ] && { cmp -s "$dir/race.ppm" "$dir/r160.ppm" || cmp -s "$dir/race.ppm" "$dir/r16.ppm"; }; then ok; else bad "racing renders left a mixed file"; fi
if [ -z "$(leftovers)" ]; then ok; else bad "temporaries left behind: $(leftovers)"; fi

# Grey frames are PGM files.
expect 0 "--format l8 writes a PGM" -- "$OMBRA" render --size 16x12 --format l8 --out "$dir/grey.pgm"
if [ "$(head -c 2 "$dir/grey.pgm")" = "P5" ] && [ "$(wc -c <"$dir/grey.pgm")" -eq $((13 + 16 * 12)) ]; then ok; else bad "--format l8 did not write a 16x12 PGM"; fi

# Files are what their names say: .png through tools/png.c, the extension decides.
# png_head FILE: the signature and IHDR's width, height, depth and colour type, in hex
png_head() { od -An -tx1 -N26 "$1" | tr -d ' \n' | sed 's/^\(.\{16\}\).\{16\}\(.*\)/\1 \2/'; }
expect 0 "render --out x.png --mask m.png" -- "$OMBRA" render --size 16x12 --out "$dir/x.png" --mask "$dir/xm.png" --against ref --diff "$dir/xd.png"
if [ "$(png_head "$dir/x.png")" = "89504e470d0a1a0a 000000100000000c0802" ]; then ok; else bad "--out x.png is no 16x12 RGB PNG: $(png_head "$dir/x.png")"; fi
if [ "$(png_head "$dir/xm.png")" = "89504e470d0a1a0a 000000100000000c0800" ]; then ok; else bad "--mask m.png is no 16x12 grey PNG: $(png_head "$dir/xm.png")"; fi
if [ "$(png_head "$dir/xd.png")" = "89504e470d0a1a0a 000000100000000c0802" ]; then ok; else bad "--diff d.png is no 16x12 RGB PNG: $(png_head "$dir/xd.png")"; fi
[ "$(grep '^hash:' "$dir/out")" = "$(grep '^hash:' "$dir/r16.out")" ] && ok || bad "a PNG render drew another frame"
expect 0 "--format l8 --out x.png" -- "$OMBRA" render --size 16x12 --format l8 --out "$dir/xg.PNG"
if [ "$(png_head "$dir/xg.PNG")" = "89504e470d0a1a0a 000000100000000c0800" ]; then ok; else bad "a grey frame's PNG is not grey: $(png_head "$dir/xg.PNG")"; fi
expect 0 "--format l8 --out x.ppm" -- "$OMBRA" render --size 16x12 --format l8 --out "$dir/xg.ppm"
if [ "$(head -c 2 "$dir/xg.ppm")" = "P6" ] && [ "$(wc -c <"$dir/xg.ppm")" -eq $((13 + 16 * 12 * 3)) ]; then ok; else bad "--format l8 --out x.ppm is no 16x12 PPM"; fi
for bad_out in "--out x.jpg" "--out x.PGMX" "--mask x.ppm" "--out x" "--mask x.tga"; do
    flag=${bad_out% *}
    name=$dir/${bad_out#* }
    rm -f "$name"
    expect 2 "render $bad_out is refused" -- "$OMBRA" render --size 16x12 $flag "$name"
    has "$dir/err" "^ombra render: $flag '$name': " "the refusal names $flag and the file"
    has "$dir/err" ".png" "the refusal names the extensions accepted"
    [ -e "$name" ] && bad "render $bad_out wrote the file" || ok
done
expect 2 "--out x.pgm of a colour frame" -- "$OMBRA" render --size 16x12 --out "$dir/colour.pgm"
has "$dir/err" "--format l8" "a colour frame's PGM points at --format l8"
expect 2 "compare --diff x.gif" -- "$OMBRA" compare "$dir/ref.pgm" "$dir/sm.pgm" --diff "$dir/d.gif"
has "$dir/err" "compare: --diff '$dir/d.gif': unknown extension '.gif'" "compare --diff's refusal named"
expect 0 "compare --diff x.png" -- "$OMBRA" compare "$dir/ref.pgm" "$dir/sm.pgm" --diff "$dir/d.png"
if [ "$(png_head "$dir/d.png")" = "89504e470d0a1a0a 000000a0000000780802" ]; then ok; else bad "compare --diff d.png is no 160x120 PNG"; fi

# Budgets: 0 is refused, 'none' is spelled out.
expect 2 "--budget 0" -- "$OMBRA" render --size 16x12 --budget 0 --out "$dir/z.ppm"
has "$dir/err" "none" "--budget 0 points at 'none'"
expect 0 "--budget none" -- "$OMBRA" render --size 16x12 --budget none --out "$dir/z.ppm"
expect 1 "asm under a small budget" -- "$OMBRA" render --size 64x48 --method asm --budget 1M --out "$dir/z.ppm"
has "$dir/err" "asm.cap" "asm's budget hint names asm.cap"
if grep -q -- "--map" "$dir/err"; then bad "asm's budget hint suggests --map"; else ok; fi

# Messages say a thing once, and help is everywhere.
expect 2 "unknown setting" -- "$OMBRA" render --set foo=1
if [ "$(grep -o "see 'ombra methods'" "$dir/err" | wc -l)" -eq 1 ]; then ok; else bad "unknown setting: $(cat "$dir/err")"; fi
expect 1 "missing scene, once named" -- "$OMBRA" render "$dir/none.scene"
if grep -q "none.scene: .*none.scene" "$dir/err"; then bad "the scene is named twice: $(cat "$dir/err")"; else ok; fi
expect 2 "unknown method near a real one" -- "$OMBRA" render --method asn
has "$dir/err" "did you mean 'asm'" "unknown method suggests the nearest"
has "$dir/err" "izb" "unknown method lists the methods"
expect 0 "--version" -- "$OMBRA" --version
if grep -q '^ombra [0-9][0-9]*\.[0-9][0-9]*\.[0-9][0-9]*$' "$dir/out"; then ok; else bad "--version: $(cat "$dir/out")"; fi
expect 0 "methods" -- "$OMBRA" methods
if grep -q '^  bias  *6e-05  ' "$dir/out" && ! grep -q '5\.99' "$dir/out"; then ok; else bad "methods prints bias as $(grep bias "$dir/out")"; fi
if [ "$(awk '/^settings/ {s = 1; next} s {match($0, /^  [^ ]+ +[^ ]+ +/); print RLENGTH}' "$dir/out" | sort -u | wc -l)" -eq 1 ]; then ok; else bad "methods' settings are not in aligned columns"; fi
for c in render info compare bench report methods scene; do
    expect 0 "$c --help" -- "$OMBRA" $c --help
    has "$dir/out" "usage: ombra $c" "$c --help prints its usage"
done
expect 2 "methods with an argument" -- "$OMBRA" methods sm
expect 0 "methods, again" -- "$OMBRA" methods
has "$dir/out" "^  izb.pool .*(izb, hybrid)$" "methods lists who takes a setting"
expect 0 "a setting of another method" -- "$OMBRA" render --size 16x12 --method sm --set spsm.aa=2 --out "$dir/z.ppm"
has "$dir/err" "sm takes no setting 'spsm.aa' (ignored)" "render says a setting of another method is ignored"
expect 2 "a setting out of range" -- "$OMBRA" render --size 16x12 --method spsm --set spsm.aa=65 --out "$dir/z.ppm"
has "$dir/err" "spsm.aa takes a whole number from 0 to 64" "a setting out of range names its range"

# Meshes: each read once (a FIFO works), any number of them, long directories.
awk 'BEGIN {print "camera eye 0 2 5 target 0 0 0 size 32 24"; for (i = 0; i < 70; i++) printf "mesh m%d.obj translate %d 0 0\n", i, i % 5}' >"$dir/many.scene"
i=0; while [ $i -lt 70 ]; do cp "$dir/m.obj" "$dir/m$i.obj"; i=$((i + 1)); done
expect 0 "70 meshes" -- "$OMBRA" render "$dir/many.scene" --out "$dir/many.ppm"
has "$dir/out" "210 triangles" "70 meshes of 3 triangles"
if command -v mkfifo >/dev/null 2>&1; then
    rm -f "$dir/mesh.fifo"
    mkfifo "$dir/mesh.fifo"
    printf 'camera eye 0 2 5 target 0 0 0 size 32 24\nmesh mesh.fifo\n' >"$dir/fifo.scene"
    cat "$dir/m.obj" >"$dir/mesh.fifo" &
    tmo=$(command -v timeout >/dev/null 2>&1 && echo "timeout 60")
    expect 0 "a mesh that is a FIFO (read once)" -- $tmo "$OMBRA" render "$dir/fifo.scene" --out "$dir/fifo-mesh.ppm"
    has "$dir/out" "3 triangles" "the FIFO mesh loaded"
    kill $! 2>/dev/null; wait 2>/dev/null
    rm -f "$dir/mesh.fifo"
fi
long="$dir/long"
while [ ${#long} -lt 1300 ]; do long="$long/dddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddd"; done
mkdir -p "$long"
cp "$dir/ok.scene" "$dir/m.obj" "$long/"
expect 0 "a scene under a 1.3 KB directory finds its mesh there" -- "$OMBRA" render "$long/ok.scene" --out "$dir/long.ppm"
has "$dir/out" "5 triangles" "the long directory's mesh loaded"

# Budgets hold from the first byte: a scene whose arena cannot fit is refused by its
# bytes query before anything is made, a file is read no further than the budget
# allows, a mask no further than its header states. With GNU time the peak RSS is
# checked against the budget plus what the process needs to do nothing at all.
rss() {  # rss COMMAND...: peak resident KB, or nothing without GNU time
    /usr/bin/time -f %M -o "$dir/rss" "$@" >/dev/null 2>&1
    [ -s "$dir/rss" ] && tail -n 1 "$dir/rss"
}
rss_ok() {  # rss_ok BUDGET_KB WHAT COMMAND...: peak RSS within budget + idle + 4 MB
    limit=$1; what=$2; shift 2
    if [ -n "$idle" ]; then
        got=$(rss "$@")
        if [ -n "$got" ] && [ "$got" -le $((idle + limit + 4096)) ]; then ok; else bad "$what: peak RSS $got KB, over $limit KB + idle $idle KB + 4 MB"; fi
    fi
}
idle=""
if [ -x /usr/bin/time ] && /usr/bin/time -f %M -o "$dir/rss" true >/dev/null 2>&1; then idle=$(rss "$OMBRA" --version); fi
printf 'camera eye 0 2 5 target 0 0 0 size 160 120\ntriangles count 10000000\n' >"$dir/tenmillion.scene"
expect 1 "10M triangles under --budget 64K" -- "$OMBRA" render "$dir/tenmillion.scene" --budget 64K --out "$dir/z.ppm"
has "$dir/err" "too small for the scene alone: its arena needs 500000026 bytes" "the scene is refused by its bytes query"
rss_ok 64 "10M triangles under --budget 64K" "$OMBRA" render "$dir/tenmillion.scene" --budget 64K --out "$dir/z.ppm"
yes 'v 0 0 0' | head -c 400000 >"$dir/bigmesh.obj"
printf 'camera eye 0 2 5 target 0 0 0 size 32 24\nmesh bigmesh.obj\n' >"$dir/bigmesh.scene"
expect 1 "a mesh larger than --budget" -- "$OMBRA" render "$dir/bigmesh.scene" --budget 64K --out "$dir/z.ppm"
has "$dir/err" "bigmesh.obj: larger than the" "the mesh over budget is named"
rss_ok 64 "a 400 KB mesh under --budget 64K" "$OMBRA" render "$dir/bigmesh.scene" --budget 64K --out "$dir/z.ppm"
expect 0 "the same mesh without a budget" -- "$OMBRA" render "$dir/bigmesh.scene" --out "$dir/z.ppm"
rss_ok 2048 "the default scene at --budget 2M" "$OMBRA" render --map 512 --budget 2M --out "$dir/z.ppm" --mask "$dir/z.pgm"
rss_ok 1024 "izb at --budget 1M" "$OMBRA" render --method izb --budget 1M --out "$dir/z.ppm"
# a mask is read as far as its header says, not to the end of the file
"$OMBRA" render --size 16x12 --mask "$dir/m16.pgm" --out "$dir/z.ppm" -q
{ cat "$dir/m16.pgm"; head -c 50000000 /dev/zero; } >"$dir/long.pgm"
expect 0 "compare a mask with 50 MB after its pixels" -- "$OMBRA" compare "$dir/m16.pgm" "$dir/long.pgm"
rss_ok 0 "compare reads a mask's stated size only" "$OMBRA" compare "$dir/m16.pgm" "$dir/long.pgm"
rm -f "$dir/long.pgm"

# What the parser accepts renders, and what would not is refused with its line and
# column: values as floats (fov 179.999999 is 180), near below 1e7, far below 1e8,
# and key paths along which the eye meets its target or a light's dir meets zero.
regress=$(dirname "$0")/../fuzz/regress
for f in far-1e8 far-99999999 near-1e7 fov-179 keys-eye-on-target; do
    expect 1 "$f.scene is refused" -- "$OMBRA" render "$regress/$f.scene" --time 1 --out "$dir/z.ppm"
    has "$dir/err" "$f.scene: line [0-9]*, col [0-9]*: " "$f.scene's error has a line and column"
done
has "$dir/err" "the eye passes through its target" "the key path's fault is said"
printf 'light directional dir 0 -1 0\nkey light 0 dir 1 -1 0\nkey light 1 dir -1 1 0\nbox\n' >"$dir/dirkeys.scene"
expect 1 "directional keys through zero" -- "$OMBRA" render "$dir/dirkeys.scene" --out "$dir/z.ppm"
has "$dir/err" "line 3, col 17: key light: .*'dir' passes through zero" "the dir path's fault is placed"
printf 'camera eye 0 2 5 target 0 0 0 fov 179.99998 near 9999999 far 99999990 size 24 16\nlight spot pos 2 6 3 target 0 0 0 fov 179.99998 near 1e-6 far 99999990\nbox\nplane size 8 8\nkey camera 0 eye 0 1 0 target 2 1 0\nkey camera 2 eye 2 1 0 target 0 1.001 0\n' >"$dir/edges.scene"
for m in $("$OMBRA" methods | awk 'NF == 0 {exit} {print $1}'); do
    expect 0 "the range's edges render with $m" -- "$OMBRA" render "$dir/edges.scene" --method "$m" --time 1 --map 256 --out "$dir/z.ppm"
done

# bench and report: names checked before any work
expect 2 "compare --diff over a mask" -- "$OMBRA" compare "$dir/ref.pgm" "$dir/sm.pgm" --diff "$dir/./sm.pgm"
if [ "$(head -c 2 "$dir/sm.pgm")" = "P5" ]; then ok; else bad "compare --diff replaced a mask it read"; fi
expect 0 "bench on a scene under a long path" -- "$OMBRA" bench --scenes "$long/ok.scene" --runs 1 --methods ref --out "$dir/bench-long"
if [ "$(sed -n 2p "$dir/bench-long/bench.csv" | cut -d, -f1)" = "$long/ok.scene" ]; then ok; else bad "bench.csv cut the scene's name short"; fi
has "$dir/bench-long/ok.scene-time.svg" "<circle" "the long-named scene's chart has its points", a failed run writes nothing, the
# method's init is its own stage, and a scene file renders at its own size.
expect 2 "bench --methods foo" -- "$OMBRA" bench --scenes "$dir/ok.scene" --methods foo --out "$dir/bench-foo"
has "$dir/err" "unknown method 'foo'" "bench names the unknown method"
if [ -e "$dir/bench-foo/bench.csv" ]; then bad "bench --methods foo wrote a CSV"; else ok; fi
expect 2 "report --scenes nosuch.scene" -- "$OMBRA" report --scenes "$dir/nosuch.scene" --out "$dir/report-none"
has "$dir/err" "^ombra report: unknown scene" "report's usage error names report"
if [ -e "$dir/report-none/bench.csv" ] || [ -e "$dir/report-none/index.html" ] || grep -q wrote "$dir/out"; then bad "a failed report wrote files"; else ok; fi
cp "$dir/bench/bench.csv" "$dir/bench-old.csv"
expect 1 "bench on a malformed scene" -- "$OMBRA" bench --scenes "$dir/ok.scene,$dir/bad.scene" --runs 1 --methods izb --out "$dir/bench"
cmp -s "$dir/bench/bench.csv" "$dir/bench-old.csv" && ok || bad "a failed bench replaced the CSV"
has "$dir/bench/bench.csv" "^scene,method,setting,width,height,time_ms,init_ms," "bench.csv has an init column"
has "$dir/bench/bench.csv" ",stats$" "bench.csv ends with the methods' counters"
has "$dir/bench/bench.csv" ",threads,stats$" "bench.csv records the threads"
# frame_wall_ms times the whole frame call, time_ms sums its stages: never less (each to 0.001 ms)
if awk -F, 'NR == 1 {for (i = 1; i <= NF; i++) {if ($i == "time_ms") t = i; if ($i == "frame_wall_ms") w = i}
            if (!t || !w) exit 1; next} $w + 0.0015 < $t {exit 1}' "$dir/bench/bench.csv"; then ok
else bad "bench.csv's frame_wall_ms is missing or below the stage sum time_ms"; fi
has "$dir/bench/bench.csv" "bsp nodes=" "bench.csv carries izb's counters"
if awk -F, 'NR > 1 && ($4 != 64 || $5 != 48) {exit 1}' "$dir/bench/bench.csv"; then ok; else bad "bench ignored the scene's 64x48"; fi
if [ -s "$dir/bench/ok.scene-first.svg" ]; then ok; else bad "no first-frame (init + frame) chart"; fi
expect 0 "bench --scenes NAME@WxH" -- "$OMBRA" bench --scenes "default@32x24,$dir/ok.scene" --size 48x36 --runs 1 --methods izb --out "$dir/bench-at"
if awk -F, '$1 == "default" && ($4 != 32 || $5 != 24) {exit 1} $1 != "default" && NR > 1 && ($4 != 48 || $5 != 36) {exit 1}' "$dir/bench-at/bench.csv"; then ok; else bad "bench ignored a scene's @WxH"; fi
expect 2 "bench --scenes default@big" -- "$OMBRA" bench --scenes "default@big" --out "$dir/bench-at"
has "$dir/err" "@ takes WxH" "a bad @ size is a usage error"
expect 0 "render --method ref" -- "$OMBRA" render --size 16x12 --method ref --out "$dir/z.ppm"
has "$dir/out" "^time: total [0-9.]* ms (init [0-9.]*, eye" "the time line shows init"

# Frame hashes of every method on the default scene, for the cross-build comparison
# that `make test` runs (the same frames from every compiler and optimisation level).
hashes=$(dirname "$OMBRA")/frame-hashes.txt
: >"$hashes"
for m in $("$OMBRA" methods | awk 'NF == 0 {exit} {print $1}'); do
    expect 0 "render --method $m" -- "$OMBRA" render --size 160x120 --method "$m" --map 512 --out "$dir/m.ppm"
    echo "$m $(grep '^hash:' "$dir/out")" >>"$hashes"
    # the same frame on 1 and 3 threads, whole and through strips (engine/frame/frame.c)
    want=$(grep '^hash:' "$dir/out")
    for args in "--threads 1" "--threads 3" "--threads 3 --strip 50"; do
        expect 0 "render --method $m $args" -- "$OMBRA" render --size 160x120 --method "$m" --map 512 $args --out "$dir/m.ppm"
        [ "$(grep '^hash:' "$dir/out")" = "$want" ] && ok || bad "$m: $args changes the frame"
    done
done
expect 2 "render --threads 0" -- "$OMBRA" render --threads 0 --out "$dir/z.ppm"
has "$dir/err" "threads takes a thread count" "--threads 0 is a usage error"
expect 0 "render --threads 2" -- "$OMBRA" render --size 64x48 --threads 2 --out "$dir/z.ppm"
has "$dir/out" ", 2 thread(s)$" "render says how many threads the frame ran on"

# Things move: info lists objects and their shared meshes; --frames writes numbered
# files, frame k the same bits as --time T + k / F; a bad object line names its place.
cat >"$dir/move.scene" <<'EOF'
camera eye 0 6 9 target 0 0.5 0
plane size 12 12
box size 1 2 1 translate 0 1 0 name crate
copy crate translate 2 0 1
key object crate 0
key object crate 1 translate -2 0 0 rotate 0 90 0
EOF
expect 0 "info of objects" -- "$OMBRA" info "$dir/move.scene"
has "$dir/out" "objects 2 sharing 1 meshes (2 object keys)" "info counts objects and meshes"
has "$dir/out" "crate .*2 objects share it" "info says who shares a mesh"
expect 0 "render --frames" -- "$OMBRA" render "$dir/move.scene" --size 64x48 --frames 3 --fps 2 -q --out "$dir/f.ppm" --mask "$dir/f.pgm"
[ -s "$dir/f-0000.ppm" ] && [ -s "$dir/f-0002.ppm" ] && [ -s "$dir/f-0002.pgm" ] && ok || bad "--frames did not write numbered files"
expect 0 "render --time 1" -- "$OMBRA" render "$dir/move.scene" --size 64x48 --time 1 -q --out "$dir/t1.ppm"
cmp -s "$dir/f-0002.ppm" "$dir/t1.ppm" && ok || bad "frame 2 at 2 fps is not --time 1"
cmp -s "$dir/f-0000.ppm" "$dir/t1.ppm" && bad "the object did not move" || ok
expect 2 "--fps without --frames" -- "$OMBRA" render --fps 3
printf 'box name a\ncopy b\n' >"$dir/bad-copy.scene"
expect 1 "copy of an unknown object" -- "$OMBRA" info "$dir/bad-copy.scene"
has "$dir/err" "line 2, col 6: unknown object 'b'" "an unknown object is named with its place"

echo "cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
