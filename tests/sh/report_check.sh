#!/bin/sh
# report_check.sh — after `make run`: the report's SVG charts and its HTML page are
# well-formed XML (xmllint); the page's charts read as the report promises (every
# sweep point labelled or listed as unlabelled, no two labels' boxes overlapping as
# their positions, sizes and lengths place them, mismatch in percent, the Pareto front
# named, no script from elsewhere; table headers in words, numbers with separators;
# the summary first, before any chart, every cell of it a link to a chart or table of
# the page; every section with data (a chart, a table or a picture, no "not there yet"
# line); the stability strips, each case's description and forced settings, its
# animation and a flicker crop when stability.csv is there; an equal-memory chart per
# scene when the page has that section; the small-machines section's tables, measured
# or from the firmware README with its commit); and headless Chromium renders the page
# to a screenshot that is not blank, opens it in under 2 s, draws every chart's points,
# lays out no two texts of a chart over each other and nothing wider than a 1280 px
# window.
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
    notes = [t for t in cls('label-note')][1:]
    if len(labels) + len(notes) < len(points):
        bad.append('chart %r labels %d of its %d points (and lists %d)' % (title, len(labels), len(points), len(notes)))
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
    if len(eq) < 2:
        bad.append('the equal-memory section has %d charts, not one per scene' % len(eq))
    for c in eq:
        if not [e for e in c.iter() if 'point' in (e.get('class') or '').split()]:
            bad.append('an equal-memory chart has no points')
        elif not any(''.join(t.itertext()).endswith('%') for t in c.iter(S + 'text') if t.get('class') == 'tick'):
            bad.append('an equal-memory chart has no percent axis')
# Labels: no two boxes overlap, a box from the text's x, baseline y, font size and
# length (0.6 em a character: DejaVu Sans, the widest of the usual sans-serifs, averages
# less on digits and lower case; the browser check below measures the real glyphs).
for c in charts:
    title = ''.join(next(c.iter(S + 'text')).itertext()) if list(c.iter(S + 'text')) else '?'
    boxes = []
    for t in c.iter(S + 'text'):
        if 'label' not in (t.get('class') or '').split():
            continue
        x, y, fs, s = float(t.get('x')), float(t.get('y')), float(t.get('font-size') or 10), ''.join(t.itertext())
        boxes.append((x, y - 0.8 * fs, x + 0.6 * fs * len(s), y + 0.2 * fs, s))
    for i in range(len(boxes)):
        for j in range(i):
            a, b = boxes[i], boxes[j]
            if a[0] < b[2] - 0.5 and b[0] < a[2] - 0.5 and a[1] < b[3] - 0.5 and b[1] < a[3] - 0.5:
                bad.append('chart %r: labels %r and %r overlap' % (title, a[4], b[4]))
# The summary: first, before any chart; each of its cells a link to a chart or a table.
ids = {e.get('id'): e for e in page.iter() if e.get('id')}
summary = ids.get('summary')
order = list(page.iter())
if summary is None:
    bad.append('the page has no summary (id="summary")')
else:
    if charts and order.index(charts[0]) < order.index(summary):
        bad.append('a chart comes before the summary')
    cells = [td for td in summary.iter(H + 'td')]
    if not cells:
        bad.append('the summary has no table cells')
    for td in cells:
        links = [a for a in td.iter(H + 'a') if (a.get('href') or '').startswith('#')]
        target = ids.get(links[0].get('href')[1:]) if links else None
        if target is None:
            bad.append('a summary cell links nowhere: %r' % ''.join(td.itertext())[:60])
            break
        if not (target.tag in (S + 'svg', H + 'table') or any(True for _ in target.iter(S + 'svg'))
                or any(True for _ in target.iter(H + 'table'))):
            bad.append('a summary cell links to %s, which holds no chart or table' % links[0].get('href'))
            break
# Every section has data: a chart, a table or a picture, and no line saying a file is
# not there yet.
body = list(page.find(H + 'body'))
heads = [i for i, e in enumerate(body) if e.tag == H + 'h2'] + [i for i, e in enumerate(body) if e.get('id') == 'summary']
for i in sorted(heads):
    e = body[i]
    name = ''.join((e if e.tag == H + 'h2' else e.find(H + 'h2')).itertext())
    part = [e] if e.tag != H + 'h2' else []
    for x in body[i + 1:]:
        if x.tag == H + 'h2' or x.get('id') == 'summary':
            break
        part.append(x)
    has = any(True for x in part for y in x.iter() if y.tag in (S + 'svg', H + 'table', H + 'img'))
    if not has:
        bad.append('the section %r has no chart, table or picture' % name)
    for x in part:
        for y in x.iter():
            if 'missing' in (y.get('class') or '').split() and y.tag == H + 'p':
                bad.append('the section %r says: %s' % (name, ''.join(y.itertext())[:100]))
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
    text = ' '.join(part)
    tables = [t for e in body[at[0] + 1:at[0] + 1 + len(part)] for t in e.iter(H + 'table')]
    if not tables:
        bad.append('the small-machines section has no table')
    if 'make cross-test' not in text:
        bad.append('the small-machines section does not name make cross-test')
    if ids.get('machines-doc') is not None and 'commit' not in text:
        bad.append('the small-machines section shows the README\'s tables without their commit')
import os
stab = os.path.join(os.path.dirname(sys.argv[1]), 'stability.csv')
if os.path.exists(stab) and 'frame_mismatch' in open(stab).readline():
    strips = [c for c in charts if 'multiple' in (c.get('class') or '')]
    if not strips:
        bad.append('stability.csv is there but the page has no stability strips')
    elif not any('flickers most' in ''.join(p.itertext()) for p in page.iter(H + 'p')):
        bad.append('the stability section shows no flicker crops')
    cases = sorted(set(l.split(',')[0] for l in open(stab).readlines()[1:] if l.strip()))
    for case in cases:
        h = ids.get('case-' + case)
        if h is None:
            bad.append('stability case %s has no heading' % case)
            continue
        after = body[body.index(h) + 1:] if h in body else []
        about = after[0] if after else None
        if about is None or 'Forced settings' not in ''.join(about.itertext()):
            bad.append('stability case %s shows no description and forced settings' % case)
    anims = [f for f in page.iter(H + 'figure') if 'anim' in (f.get('class') or '')]
    if len(anims) < len(cases):
        bad.append('%d stability animations for %d cases' % (len(anims), len(cases)))
    for f in anims:
        src = next(f.iter(H + 'img')).get('src') or ''
        import base64
        png = base64.b64decode(src.split(',', 1)[1])
        if b'acTL' not in png[:100]:
            bad.append('a stability animation is no APNG')
            break
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
window.addEventListener("load", function () {\
var out = [], W = document.documentElement.clientWidth, t = performance.now();\
if (t > 2000) out.push("the page takes " + Math.round(t) + " ms to open");\
if (document.documentElement.scrollWidth > W) out.push("the page scrolls sideways: " + document.documentElement.scrollWidth + " px");\
document.querySelectorAll("svg").forEach(function (c, i) {\
  var n = 0; c.querySelectorAll(".point, .cell").forEach(function (p) { var b = p.getBoundingClientRect(); if (b.width > 0) n++; });\
  if (!n) out.push("chart " + i + " draws no points");\
  var ts = [].slice.call(c.querySelectorAll("text")).map(function (e) { return [e.getBoundingClientRect(), e.firstChild ? e.firstChild.textContent : ""]; });\
  for (var a = 0; a < ts.length; a++) for (var b = 0; b < a; b++) {\
    var p = ts[a][0], q = ts[b][0];\
    var w = Math.min(p.right, q.right) - Math.max(p.left, q.left), h = Math.min(p.bottom, q.bottom) - Math.max(p.top, q.top);\
    if (Math.min(w, h, p.width, q.width) > 1)\
      out.push("chart " + i + ": " + JSON.stringify(ts[a][1]) + " over " + JSON.stringify(ts[b][1]));\
  }\
});\
document.querySelectorAll("body *").forEach(function (e) {\
  for (var a = e.parentElement; a; a = a.parentElement) { var o = getComputedStyle(a).overflowX; if (o == "auto" || o == "scroll" || o == "hidden") return; }\
  var b = e.getBoundingClientRect(); if (b.right > W + 1) out.push(e.tagName + " reaches " + Math.round(b.right) + " px");\
});\
var r = document.createElement("pre"); r.id = "layout-check"; r.textContent = "LAY" + "OUT[" + out.slice(0, 10).join("; ") + "]" + " OPEN[" + Math.round(t) + "]"; document.body.appendChild(r);\
});\
//]]></script></body>#' "$dir/index.html" > "$shot/check.html"
    "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --user-data-dir="$shot/profile" --window-size=1280,2400 \
        --dump-dom "file://$shot/check.html" 2>/dev/null > "$shot/dom.html"
    layout=$(grep -o 'LAYOUT\[[^]]*\]' "$shot/dom.html" | head -1)
    opened=$(grep -o 'OPEN\[[0-9]*\]' "$shot/dom.html" | head -1 | tr -dc 0-9)
    if [ "$layout" = "LAYOUT[]" ]; then
        echo "report: Chromium opens the page in ${opened} ms (under 2 s); in a 1280 px window every chart draws its points, no two of a chart's texts overlap, nothing is wider"
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
