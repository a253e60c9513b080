#!/bin/sh
# readme.sh — the README's embedding examples are tests/embed/render_once.c's and
# render_sized.c's, word for word: the README's first and second ```c blocks after
# "## Embedding" against each file's lines between "README: begin" and "README: end".
set -eu
cd "$(dirname "$0")/../.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
n=0
for f in tests/embed/render_once.c tests/embed/render_sized.c; do
    n=$((n + 1))
    awk -v want="$n" '/^## Embedding/ {s = 1} /^## / && !/^## Embedding/ {s = 0}
        s && /^```c$/ {k++; p = (k == want); next} p && /^```$/ {exit} p' README.md >"$tmp/readme"
    sed -n '/README: begin/,/README: end/p' "$f" | sed '1d;$d' >"$tmp/file"
    if ! [ -s "$tmp/readme" ]; then echo "embed: FAIL — no \`\`\`c block number $n under ## Embedding in README.md"; exit 1; fi
    if ! cmp -s "$tmp/readme" "$tmp/file"; then
        echo "embed: FAIL — README.md's embedding example $n differs from $f:"
        diff "$tmp/file" "$tmp/readme" || true
        exit 1
    fi
done
echo "embed: the README's examples are tests/embed/render_once.c's and render_sized.c's"
