#!/usr/bin/env bash
# CTest bench_report_render: a small tightbvh-bench run with --report, checked as a person sees it
# (check-report.sh: headless Chromium, no network, the pose pictures show geometry), and a
# picture with nothing drawn must fail that check. test-report.sh BENCH OUT_DIR
set -euo pipefail
bench=$1 out=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$out"
mkdir -p "$out"
"$bench" --poses 4 --repetitions 1 --budget 0.05 --engines tightbvh-pca,fcl-obb --scenario overlap,near \
  --report "$out/report" > "$out/table.txt"
for scenario in overlap near; do
  [ -f "$out/report/pose-$scenario.svg" ] || { echo "test-report: no picture of $scenario" >&2; exit 1; }
  grep -q "fill='#e0202a'" "$out/report/pose-$scenario.svg" || { echo "test-report: $scenario: no contacts group" >&2; exit 1; }
done
bash "$here/check-report.sh" "$out/report"
# The check itself: a report whose picture is blank must fail.
mkdir -p "$out/blank"
cp "$out/report/index.html" "$out/blank/"
echo "<svg xmlns='http://www.w3.org/2000/svg' width='420' height='456'><text x='4' y='20'>nothing</text></svg>" \
  > "$out/blank/pose-overlap.svg"
if bash "$here/check-report.sh" "$out/blank" > /dev/null 2>&1; then
  echo "test-report: a blank pose picture passed check-report" >&2; exit 1
fi
echo "test-report: ok"
