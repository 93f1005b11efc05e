#!/usr/bin/env bash
# Renders tightbvh-bench's HTML report in headless Chromium (Debian package `chromium`, installed
# by scripts/setup) and writes a screenshot to look at: check-report.sh REPORT_DIR [OUT.png]
# Offline by construction: the report has no external resources; networking is disabled here too.
# Each typical-pose picture (REPORT_DIR/pose-SCENARIO.svg, the same SVG as in the page) is rendered
# on its own too (REPORT_DIR/pose-SCENARIO.png) and must show drawn geometry: at least 5% colored
# pixels (tests/view/png_colored_pixels.py); any script error in Chromium's log fails the check.
set -euo pipefail
dir=$(cd "$1" && pwd)
out=${2:-$dir/screenshot.png}
here=$(cd "$(dirname "$0")" && pwd)
pixels="$here/../../tests/view/png_colored_pixels.py"
[ -f "$dir/index.html" ] || { echo "check-report: $dir/index.html missing" >&2; exit 1; }
if grep -Eq "(src|href)=['\"]?https?:" "$dir/index.html"; then
  echo "check-report: the report references the network" >&2
  exit 1
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
# shot URL PNG WIDTH,HEIGHT
shot() {
  timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-background-networking \
    --disable-component-update --disable-sync --no-first-run --enable-logging=stderr --v=0 \
    --user-data-dir="$profile" --screenshot="$2" --window-size="$3" "$1" > "$profile/log" 2>&1 \
    || { cat "$profile/log" >&2; return 1; }
  [ -s "$2" ] || { echo "check-report: no screenshot of $1 written" >&2; return 1; }
  if grep -E "Uncaught|SyntaxError|TypeError" "$profile/log" >&2; then
    echo "check-report: script errors in $1" >&2; return 1
  fi
}
shot "file://$dir/index.html" "$out" 1200,1600
echo "check-report: screenshot $out"
pictures=0
for svg in "$dir"/pose-*.svg; do
  [ -e "$svg" ] || continue
  grep -q "</svg>" "$svg" || { echo "check-report: $svg is incomplete" >&2; exit 1; }
  png=${svg%.svg}.png
  shot "file://$svg" "$png" 420,456
  /usr/bin/python3 "$pixels" "$png" 0.05 || { echo "check-report: $svg shows too little geometry" >&2; exit 1; }
  pictures=$((pictures + 1))
done
[ "$pictures" -gt 0 ] || { echo "check-report: no pose pictures (pose-*.svg) in $dir" >&2; exit 1; }
echo "check-report: $pictures pose pictures rendered"
