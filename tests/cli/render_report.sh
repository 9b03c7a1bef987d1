#!/usr/bin/env bash
# Runs the demo, then renders its report in headless Chromium to a PNG and checks that
# the page loaded with its plots and without console errors. Skips (77) without Chromium.
set -euo pipefail
J="$1"
OUT="$2"
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROMIUM" ]; then
  echo "SKIP: chromium not installed (apt-get install chromium)"
  exit 77
fi
rm -rf "$OUT"
mkdir -p "$OUT"
"$J" demo --out "$OUT" > "$OUT/demo.txt"
REPORT="$OUT/report.html"
[ -s "$REPORT" ] || { echo "no report written"; exit 1; }
PLOTS=$(grep -c '<svg' "$REPORT")
[ "$PLOTS" -ge 3 ] || { echo "expected at least 3 inline plots, found $PLOTS"; exit 1; }
PROFILE=$(mktemp -d)
FLAGS=(--headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking --disable-component-update
       --disable-sync --disable-quic "--user-data-dir=$PROFILE")
"$CHROMIUM" "${FLAGS[@]}" --window-size=1100,3000 --screenshot="$OUT/report.png" "file://$REPORT" > "$OUT/chromium.log" 2>&1 || true
[ -s "$OUT/report.png" ] || { echo "chromium wrote no screenshot"; cat "$OUT/chromium.log"; exit 1; }
# Console errors: dump the DOM with logging on and look for page-originated errors.
"$CHROMIUM" "${FLAGS[@]}" --enable-logging=stderr --v=0 --dump-dom "file://$REPORT" > "$OUT/dom.html" 2> "$OUT/console.log" || true
grep -q "The paper's three collisions" "$OUT/dom.html" || { echo "page did not load"; exit 1; }
if grep -E "CONSOLE\(|Uncaught" "$OUT/console.log" | grep -qi error; then
  echo "console errors:"; grep -E "CONSOLE\(|Uncaught" "$OUT/console.log"; exit 1
fi
rm -rf "$PROFILE"
echo "report rendered: $OUT/report.png ($PLOTS plots)"
