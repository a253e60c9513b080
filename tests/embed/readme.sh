#!/bin/sh
# readme.sh — the README's embedding example is tests/embed/render_once.c's, word for
# word: the README's first ```c block after "## Embedding" against the file's lines
# between "README: begin" and "README: end".
set -eu
cd "$(dirname "$0")/../.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
awk '/^## Embedding/ {s = 1} s && /^```c$/ {p = 1; next} p && /^```$/ {exit} p' README.md >"$tmp/readme"
sed -n '/README: begin/,/README: end/p' tests/embed/render_once.c | sed '1d;$d' >"$tmp/file"
if ! [ -s "$tmp/readme" ]; then echo "embed: FAIL — no \`\`\`c block under ## Embedding in README.md"; exit 1; fi
if ! cmp -s "$tmp/readme" "$tmp/file"; then
    echo "embed: FAIL — README.md's embedding example differs from tests/embed/render_once.c:"
    diff "$tmp/file" "$tmp/readme" || true
    exit 1
fi
echo "embed: the README's example is tests/embed/render_once.c's"
