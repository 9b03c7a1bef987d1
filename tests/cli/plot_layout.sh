#!/usr/bin/env bash
# plot_layout.sh HTML OUT_DIR: loads HTML in headless Chromium with tests/cli/plot_layout_check.js
# injected, prints its verdict and fault lines; exit 0 when every plot is laid out cleanly
# (no overlapping texts, nothing cut off, no line out of its frame), 1 when not, 77 without
# Chromium. With --interaction, tests/cli/plot_interaction_check.js runs after it on the
# same page (hover readout, drag zoom, double-click reset: issue 29) and must pass too.
# Used by render_report.sh; runs on any report, e.g. an old one:
#   bash tests/cli/plot_layout.sh --interaction old/report.html /tmp/check
set -euo pipefail
CHECKS=(plot_layout_check.js)
if [ "${1:-}" = --interaction ]; then CHECKS+=(plot_interaction_check.js); shift; fi
if [ $# -ne 2 ]; then echo "usage: $0 [--interaction] HTML OUT_DIR" >&2; exit 2; fi
HTML=$1 OUT=$2
HERE=$(cd "$(dirname "$0")" && pwd)
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
[ -n "$CHROMIUM" ] || { echo "SKIP: chromium not installed"; exit 77; }
[ -s "$HTML" ] || { echo "plot_layout.sh: '$HTML' is missing or empty" >&2; exit 1; }
mkdir -p "$OUT"
PAGE="$OUT/$(basename "$HTML" .html).checked.html"
# The checks run after the page's own content (its scripts too), in order: before </body>,
# or at the end without one.
/usr/bin/python3 - "$HTML" "$PAGE" "${CHECKS[@]/#/$HERE/}" <<'PY'
import sys
page = open(sys.argv[1], encoding="utf-8").read()
script = "".join("<script>\n" + open(f, encoding="utf-8").read() + "\n</script>\n" for f in sys.argv[3:])
at = page.rfind("</body>")
page = page[:at] + script + page[at:] if at >= 0 else page + script
open(sys.argv[2], "w", encoding="utf-8").write(page)
PY
PROFILE=$(mktemp -d)
trap 'rm -rf "$PROFILE"' EXIT
"$CHROMIUM" --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking --disable-component-update \
  --disable-sync --disable-quic "--user-data-dir=$PROFILE" --window-size=1100,3000 --dump-dom "file://$(realpath "$PAGE")" \
  > "$OUT/layout_dom.html" 2> "$OUT/layout_chromium.log" || true
verdict() {  # the last PRE of that id: the scripts themselves name the element
  /usr/bin/python3 - "$OUT/layout_dom.html" "$1" <<'PY'
import html, re, sys
found = re.findall(r'<pre id="' + sys.argv[2] + r'">(.*?)</pre>', open(sys.argv[1], encoding="utf-8").read(), re.S)
print(html.unescape(found[-1]) if found else "")
PY
}
VERDICT=$(verdict plot-layout-verdict)
[ -n "$VERDICT" ] || { echo "plot_layout.sh: no verdict in the page (the check did not run); $OUT/layout_chromium.log"; exit 1; }
echo "$VERDICT"
if [ ${#CHECKS[@]} = 2 ]; then
  INTERACTION=$(verdict plot-interaction-verdict)
  [ -n "$INTERACTION" ] || { echo "plot_layout.sh: no interaction verdict (the check did not run); $OUT/layout_chromium.log"; exit 1; }
  echo "$INTERACTION"
  grep -q '^PLOT-INTERACTION: ok' <<<"$INTERACTION" || exit 1
fi
grep -q '^PLOT-LAYOUT: ok' <<<"$VERDICT"
