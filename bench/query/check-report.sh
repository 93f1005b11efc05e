#!/usr/bin/env bash
# Renders tightbvh-bench's HTML report in headless Chromium (Debian package `chromium`, installed
# by scripts/setup) and writes a screenshot to look at: check-report.sh REPORT_DIR [OUT.png]
# Offline by construction: the report has no external resources; networking is disabled here too.
set -euo pipefail
dir=$(cd "$1" && pwd)
out=${2:-$dir/screenshot.png}
[ -f "$dir/index.html" ] || { echo "check-report: $dir/index.html missing" >&2; exit 1; }
if grep -Eq "(src|href)=['\"]?https?:" "$dir/index.html"; then
  echo "check-report: the report references the network" >&2
  exit 1
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
chromium --headless --no-sandbox --disable-gpu --disable-background-networking --disable-component-update \
  --disable-sync --no-first-run --user-data-dir="$profile" --screenshot="$out" --window-size=1200,1600 \
  "file://$dir/index.html" > "$profile/log" 2>&1 || { cat "$profile/log" >&2; exit 1; }
[ -s "$out" ] || { echo "check-report: no screenshot written" >&2; exit 1; }
echo "check-report: screenshot $out"
