#!/bin/sh
# report_check.sh — after `make run`: the report's SVG charts and its HTML page are
# well-formed XML (xmllint), and headless Chromium renders the page to a screenshot
# that is not blank. Run by .ci/run; skips a check whose tool is missing, saying so.
set -u
dir=${1:-out/report}
status=0
if [ ! -s "$dir/index.html" ]; then echo "report: FAIL $dir/index.html is missing"; exit 1; fi
if command -v xmllint >/dev/null 2>&1; then
    if xmllint --noout "$dir"/*.svg "$dir/index.html"; then
        echo "report: the charts and the page are well-formed"
    else
        echo "report: FAIL xmllint rejects the report"
        status=1
    fi
else
    echo "report: skip the XML check (no xmllint)"
fi
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -n "$browser" ] && command -v python3 >/dev/null 2>&1; then
    shot=$(mktemp -d)
    "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --user-data-dir="$shot/profile" --window-size=1280,2400 \
        --screenshot="$shot/page.png" "file://$(cd "$dir" && pwd)/index.html" >/dev/null 2>&1
    # Not blank: the inflated image data holds plenty of bytes other than 0 and 255
    # (a uniform page filters down to almost nothing else).
    if python3 - "$shot/page.png" <<'PY'
import sys, zlib, struct
data = open(sys.argv[1], 'rb').read()
assert data[:8] == b'\x89PNG\r\n\x1a\n'
pos, idat = 8, b''
while pos < len(data):
    n, = struct.unpack('>I', data[pos:pos + 4]); kind = data[pos + 4:pos + 8]
    if kind == b'IDAT': idat += data[pos + 8:pos + 8 + n]
    pos += 12 + n
raw = zlib.decompress(idat)
busy = sum(1 for b in raw if b not in (0, 255))
print("report: screenshot %d bytes of image data, %.1f%% busy" % (len(raw), 100.0 * busy / len(raw)))
sys.exit(0 if busy > len(raw) // 100 else 1)
PY
    then
        echo "report: Chromium renders the page"
    else
        echo "report: FAIL the screenshot of the page is blank or missing"
        status=1
    fi
    rm -rf "$shot"
else
    echo "report: skip the browser check (no chromium or python3)"
fi
exit $status
