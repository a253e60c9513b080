#!/bin/sh
# links.sh — every relative link in the project's Markdown files reaches a file, and
# every #anchor a heading of the file it names (GitHub's anchors: the heading in lower
# case, punctuation dropped, spaces as hyphens, "-1", "-2" after repeats) or an id="..."
# in it. Links in fenced code blocks and in `code spans` are not links. Fails naming
# the file, line and link. Usage: sh tests/sh/links.sh (from anywhere).
set -u
cd "$(dirname "$0")/../.." || exit 1
export LC_ALL=C
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
files=$(git ls-files '*.md' 2>/dev/null || find . -name '*.md' -not -path './build/*' -not -path './out/*' | sed 's|^\./||')

# anchors FILE: the file's anchors, one a line
anchors() {
    awk '/^```/ {code = !code; next}
         code {next}
         /^#+ / {
             h = $0; sub(/^#+ +/, "", h); sub(/ +#* *$/, "", h)
             h = tolower(h); gsub(/[^a-z0-9 _-]/, "", h); gsub(/ /, "-", h)
             n = seen[h]++; print (n ? h "-" n : h)
         }
         { s = $0; while (match(s, /id="[^"]*"/)) { print substr(s, RSTART + 4, RLENGTH - 5); s = substr(s, RSTART + RLENGTH) } }' "$1"
}

bad=0
for f in $files; do
    d=$(dirname "$f")
    # FILE:LINE TARGET for each link outside code
    awk '/^```/ {code = !code; next}
         code {next}
         { s = $0; gsub(/`[^`]*`/, "", s)
           while (match(s, /\]\([^) ]*\)/)) {
               print FNR " " substr(s, RSTART + 2, RLENGTH - 3); s = substr(s, RSTART + RLENGTH)
           } }' "$f" >"$tmp/links"
    while read -r line target; do
        case $target in
            *://* | mailto:*) continue ;;
        esac
        path=${target%%#*}
        anchor=
        case $target in *'#'*) anchor=${target#*#} ;; esac
        if [ -z "$path" ]; then to=$f; else to=$d/$path; fi
        if ! [ -e "$to" ]; then
            echo "links: FAIL $f:$line: '$target': no file $to"
            bad=$((bad + 1))
            continue
        fi
        if [ -n "$anchor" ]; then
            case $to in
                *.md) ;;
                *) continue ;;   # an anchor in a non-Markdown file is not checked
            esac
            if ! anchors "$to" | grep -qx -- "$anchor"; then
                echo "links: FAIL $f:$line: '$target': $to has no heading whose anchor is #$anchor"
                bad=$((bad + 1))
            fi
        fi
    done <"$tmp/links"
done
if [ "$bad" -gt 0 ]; then
    echo "links: $bad dead link(s): fix the path, or the anchor to a heading's (lower case, punctuation dropped, spaces as hyphens)"
    exit 1
fi
echo "links: every relative link and anchor in $(echo "$files" | wc -w) Markdown files resolves"
