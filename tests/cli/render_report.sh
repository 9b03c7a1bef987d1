#!/usr/bin/env bash
# The demo's report as a reader gets it (issue 29 item 4). Runs scripts/demo.sh on this
# build folder (the script a fresh machine runs: has_target, the cycle-benchmark ELF, the
# demo) or, given only J and OUT, `J demo`; then:
#  - the "Firmware cost" section is measured when the build has the ELF's target (the fresh
#    machine's report said "Not measured: cycle benchmark ELF not built"), else says why not;
#  - every plot was drawn (no "plot not drawn": gnuplot missing);
#  - headless Chromium renders the page without console errors (a PNG beside the report);
#  - the plots' layout as Chromium lays them out (tests/cli/plot_layout.sh): no text over
#    another, nothing cut off, no line out of its frame; and the same check fails on a
#    hand-written plot with those faults (tests/cli/data/plot_layout_faulty.html), so it
#    cannot pass by finding nothing;
#  - a reader can read values off every plot and zoom into it (plot_layout.sh --interaction,
#    tests/cli/plot_interaction_check.js): a hover shows x and y as the axes give them, a drag
#    zooms the x axis, a double-click brings the whole range back.
# usage: render_report.sh J OUT [SOURCE_DIR BUILD_DIR MCU_TARGET_EXISTS(0|1)]
# Skips (77) without Chromium.
set -euo pipefail
J="$1"
OUT="$2"
SRC="${3:-}" BUILD="${4:-}" MCU="${5:-}"
HERE=$(cd "$(dirname "$0")" && pwd)
fail() { echo "FAIL: $*" >&2; exit 1; }
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROMIUM" ]; then
  echo "SKIP: chromium not installed (apt-get install chromium)"
  exit 77
fi
rm -rf "$OUT"
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
if [ -n "$SRC" ]; then
  JG_DEMO_BUILD="$BUILD" bash "$SRC/scripts/demo.sh" "$OUT" > "$OUT/demo.txt" 2> "$OUT/demo.err" ||
    { cat "$OUT/demo.err"; fail "scripts/demo.sh failed"; }
else
  "$J" demo --out "$OUT" > "$OUT/demo.txt"
fi
REPORT="$OUT/report.html"
[ -s "$REPORT" ] || fail "no report written"
PLOTS=$(grep -c '<svg' "$REPORT")
[ "$PLOTS" -ge 3 ] || fail "expected at least 3 inline plots, found $PLOTS"
if grep -q 'plot not drawn' "$REPORT"; then fail "plots not drawn: $(grep -o 'plot not drawn[^<]*' "$REPORT" | head -1); $(grep -m1 'report plots not drawn' "$OUT"/demo.* || true)"; fi

# The firmware cost: measured exactly when this build has the benchmark ELF's target.
COST=$(sed -n '/<h2>Firmware cost/,/<h2>\|Generated in/p' "$REPORT")
[ -n "$COST" ] || fail "the report has no Firmware cost section"
if [ "$MCU" = 1 ]; then
  grep -q 'Not measured' <<<"$COST" && fail "Firmware cost not measured although the build has jg_mcu_cortex_m4: $(grep -o 'Not measured[^<]*' <<<"$COST")"
  grep -Eq '<td>float</td><td>[0-9]+</td>' <<<"$COST" || fail "Firmware cost section without the float estimator's instruction count"
  echo "firmware cost measured: $(grep -o '<td>float</td><td>[0-9]*' <<<"$COST" | sed 's/<[^>]*>/ /g' | xargs) instructions per estimator cycle"
elif [ "$MCU" = 0 ]; then
  grep -q 'Not measured: ' <<<"$COST" || fail "Firmware cost claims figures but this build has no jg_mcu_cortex_m4"
fi

PROFILE=$(mktemp -d)
trap 'rm -rf "$PROFILE"' EXIT
FLAGS=(--headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking --disable-component-update
       --disable-sync --disable-quic "--user-data-dir=$PROFILE")
"$CHROMIUM" "${FLAGS[@]}" --window-size=1100,3000 --screenshot="$OUT/report.png" "file://$REPORT" > "$OUT/chromium.log" 2>&1 || true
[ -s "$OUT/report.png" ] || { cat "$OUT/chromium.log"; fail "chromium wrote no screenshot"; }
# Console errors: dump the DOM with logging on and look for page-originated errors.
"$CHROMIUM" "${FLAGS[@]}" --enable-logging=stderr --v=0 --dump-dom "file://$REPORT" > "$OUT/dom.html" 2> "$OUT/console.log" || true
grep -q "The paper's three collisions" "$OUT/dom.html" || fail "page did not load"
if grep -E "CONSOLE\(|Uncaught" "$OUT/console.log" | grep -qi error; then
  grep -E "CONSOLE\(|Uncaught" "$OUT/console.log"; fail "console errors"
fi

# The layout check must catch each fault of the hand-written plots before it is believed.
set +e
bash "$HERE/plot_layout.sh" "$HERE/data/plot_layout_faulty.html" "$OUT/faulty" > "$OUT/faulty.txt"
rc=$?
set -e
[ "$rc" = 1 ] || { cat "$OUT/faulty.txt"; fail "the layout check passed a plot with known faults (exit $rc)"; }
for fault in 'overlaps' 'cut off' 'runs out of the plot frame' 'crosses the plot frame'; do
  grep -q "$fault" "$OUT/faulty.txt" || { cat "$OUT/faulty.txt"; fail "the layout check missed a fault: '$fault'"; }
done
bash "$HERE/plot_layout.sh" --interaction "$REPORT" "$OUT/layout" > "$OUT/layout.txt" ||
  { cat "$OUT/layout.txt"; fail "the report's plots are not laid out cleanly or cannot be hovered and zoomed"; }
grep '^PLOT-LAYOUT: \|^PLOT-INTERACTION: ' "$OUT/layout.txt"
echo "report rendered: $OUT/report.png ($PLOTS plots)"
