#!/bin/sh
# report_check.sh — after `make run`: the report's SVG charts and its HTML page are
# well-formed XML (xmllint); the page's charts read as the report promises (every
# sweep point labelled, mismatch in percent, the Pareto front named, no script from
# elsewhere; table headers in words, numbers with separators; the stability strips
# and a flicker crop when stability.csv is there; the equal-memory chart when the page
# has that section; the small-machines section, naming make cross-test); and headless Chromium renders the page to a screenshot that is not
# blank, with every chart's points drawn and nothing wider than a 1280 px window.
# Run by .ci/run; skips a check whose tool is missing, saying so.
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
if command -v python3 >/dev/null 2>&1; then
    if python3 - "$dir/index.html" <<'PY'
import sys, xml.etree.ElementTree as ET
S = '{http://www.w3.org/2000/svg}'
page = ET.parse(sys.argv[1]).getroot()
bad = []
if any(True for _ in page.iter('{http://www.w3.org/1999/xhtml}script')):
    bad.append('the page carries a script')
for e in page.iter():
    for k in ('src', 'href', '{http://www.w3.org/1999/xlink}href'):
        if (e.get(k) or '').split(':')[0] in ('http', 'https', 'file', '//'):
            bad.append('the page loads %s from elsewhere' % e.get(k))
charts = list(page.iter(S + 'svg'))
sweeps = 0
for i, c in enumerate(charts):
    title = ''.join(next(c.iter(S + 'text')).itertext()) if list(c.iter(S + 'text')) else '?'
    cls = lambda k: [e for e in c.iter() if k in (e.get('class') or '').split()]
    points, labels = cls('point'), cls('label')
    if not points and not cls('cell'):
        bad.append('chart %r has no points' % title)
    if not cls('front'):
        continue
    sweeps += 1
    if len(labels) < len(points):
        bad.append('chart %r labels %d of its %d points' % (title, len(labels), len(points)))
    if not any(''.join(t.itertext()).endswith('%') for t in cls('tick')):
        bad.append('chart %r has no percent axis' % title)
    if not any('Pareto front' in ''.join(t.itertext()) for t in cls('front-name')):
        bad.append('chart %r does not name its Pareto front' % title)
if not sweeps:
    bad.append('no accuracy chart with a Pareto front')
import re
H = '{http://www.w3.org/1999/xhtml}'
for th in page.iter(H + 'th'):
    if '_' in ''.join(th.itertext()):
        bad.append('a table header reads as a CSV name: %r' % ''.join(th.itertext()))
for td in page.iter(H + 'td'):
    if re.fullmatch(r'-?\d{5,}', ''.join(td.itertext()).strip()):
        bad.append('a number without thousands separators: %s' % ''.join(td.itertext()))
        break
if not any(True for _ in page.iter(H + 'table')):
    bad.append('the page has no table')
memory = [h for h in page.iter(H + 'h2') if h.get('id') == 'memory']
if memory:
    eq = [c for c in charts if any('equal memory' in ''.join(t.itertext()) for t in c.iter(S + 'text'))]
    if not eq or not [e for e in eq[0].iter(S + 'circle') if 'point' in (e.get('class') or '')]:
        bad.append('the equal-memory section has no chart with points')
    elif not any(''.join(t.itertext()).endswith('%') for t in eq[0].iter(S + 'text') if t.get('class') == 'tick'):
        bad.append('the equal-memory chart has no percent axis')
body = list(page.find(H + 'body'))
at = [i for i, e in enumerate(body) if e.tag == H + 'h2' and e.get('id') == 'machines']
if not at:
    bad.append('the page has no small-machines section')
else:
    part = []
    for e in body[at[0] + 1:]:
        if e.tag == H + 'h2':
            break
        part.append(''.join(e.itertext()))
    if 'make cross-test' not in ' '.join(part) and not any(e.tag == H + 'div' for e in body[at[0] + 1:]):
        bad.append('the small-machines section has neither its tables nor the command that writes them')
import os
stab = os.path.join(os.path.dirname(sys.argv[1]), 'stability.csv')
if os.path.exists(stab) and 'frame_mismatch' in open(stab).readline():
    strips = [c for c in charts if 'multiple' in (c.get('class') or '')]
    if not strips:
        bad.append('stability.csv is there but the page has no stability strips')
    elif not any('flickers most' in ''.join(p.itertext()) for p in page.iter(H + 'p')):
        bad.append('the stability section shows no flicker crops')
for b in bad:
    print('report: FAIL ' + b)
print('report: %d charts, %d with a Pareto front' % (len(charts), sweeps))
sys.exit(1 if bad else 0)
PY
    then
        echo "report: the charts carry labels, percent axes and a named front; the tables read"
    else
        status=1
    fi
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
    # Layout, measured by a copy of the page with a script of the check's own (the page
    # itself has none): each chart's points drawn with a size, and nothing reaching past
    # the window unless a box of its own scrolls it.
    sed 's#</body>#<script>//<![CDATA[\
var out = [], W = document.documentElement.clientWidth;\
if (document.documentElement.scrollWidth > W) out.push("the page scrolls sideways: " + document.documentElement.scrollWidth + " px");\
document.querySelectorAll("svg").forEach(function (c, i) {\
  var n = 0; c.querySelectorAll(".point, .cell").forEach(function (p) { var b = p.getBoundingClientRect(); if (b.width > 0) n++; });\
  if (!n) out.push("chart " + i + " draws no points");\
});\
document.querySelectorAll("body *").forEach(function (e) {\
  for (var a = e.parentElement; a; a = a.parentElement) { var o = getComputedStyle(a).overflowX; if (o == "auto" || o == "scroll" || o == "hidden") return; }\
  var b = e.getBoundingClientRect(); if (b.right > W + 1) out.push(e.tagName + " reaches " + Math.round(b.right) + " px");\
});\
var r = document.createElement("pre"); r.id = "layout-check"; r.textContent = "LAY" + "OUT[" + out.slice(0, 10).join("; ") + "]"; document.body.appendChild(r);\
//]]></script></body>#' "$dir/index.html" > "$shot/check.html"
    "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --user-data-dir="$shot/profile" --window-size=1280,2400 \
        --dump-dom "file://$shot/check.html" 2>/dev/null > "$shot/dom.html"
    layout=$(grep -o 'LAYOUT\[[^]]*\]' "$shot/dom.html" | head -1)
    if [ "$layout" = "LAYOUT[]" ]; then
        echo "report: in a 1280 px window every chart draws its points and nothing is wider"
    elif [ -z "$layout" ]; then
        echo "report: FAIL Chromium did not run the layout check"
        status=1
    else
        echo "report: FAIL $layout"
        status=1
    fi
    rm -rf "$shot"
else
    echo "report: skip the browser check (no chromium or python3)"
fi
exit $status
