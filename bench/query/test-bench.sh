#!/usr/bin/env bash
# CTest for tightbvh-bench: bad pose files fail with the file and line named; a written pose file
# reads back; JSON/CSV are written; every engine agrees with the reference except Bullet/ODE.
set -euo pipefail
bench=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
fail() { echo "test-bench: $*" >&2; exit 1; }
expect_error() {  # file, expected message fragment
  if "$bench" --poses-file "$1" --engines fcl-obb > out.txt 2> err.txt; then fail "$1 accepted"; fi
  grep -q -- "$2" err.txt || { cat err.txt; fail "$1: message lacks '$2'"; }
}
printf '# comment\n1 0 0 0 1 0 0 0 1 0 0 0\n1 0 0 0 1 0 0 0 1 0 0\n' > count.txt
expect_error count.txt "count.txt:3: expected 12 numbers"
printf '1 0 0 0 1 0 0 0 1 nan 0 0\n' > nan.txt
expect_error nan.txt "nan.txt:1: not finite"
printf '1 0 0 0 1 0 0 0 2 0 0 0\n' > scaled.txt
expect_error scaled.txt "scaled.txt:1: rotation is not orthonormal"
printf '1 0 0 0 1 0 0 0 -1 0 0 0\n' > mirror.txt
expect_error mirror.txt "mirror.txt:1: rotation has determinant -1"
printf '1 0 0 0 1 0 0 0 1 0 0 zero\n' > word.txt
expect_error word.txt "word.txt:1: not a number"
if "$bench" --engines no-such-engine > /dev/null 2>&1; then fail "unknown engine accepted"; fi

"$bench" --poses 6 --scenario near --write-poses near.txt --json a.json --csv a.csv --repetitions 1 > table.txt
[ "$(grep -vc '^#' near.txt)" = 6 ] || fail "expected 6 poses written"
grep -q '"engines"' a.json || fail "no engines in JSON"
"$bench" --poses-file near.txt --engines tightbvh-pca,fcl-obb,fcl-obbrss,fcl-export-pca --repetitions 1 > file.txt
# Our engines and FCL's must agree with the reference on every pose.
if grep -E '^(tightbvh|fcl)' file.txt | grep -q MISMATCH; then cat file.txt; fail "mismatch"; fi
# Distance mode on the gap scenario: our distances and FCL's agree with the reference.
"$bench" --modes distance --scenario gap,overlap --poses 4 --engines tightbvh-pca,fcl-obbrss,fcl-rss --repetitions 1 \
  > distance.txt
[ "$(grep -cE '^(tightbvh-pca|fcl-obbrss|fcl-rss) +distance' distance.txt)" = 6 ] || { cat distance.txt; fail "distance rows"; }
if grep -E '^(tightbvh|fcl)' distance.txt | grep -q MISMATCH; then cat distance.txt; fail "distance mismatch"; fi
# Margin mode: our pair sets equal the reference's exactly.
"$bench" --modes margin --scenario near --poses 3 --engines tightbvh-pca --repetitions 1 > margin.txt
grep -qE '^tightbvh-pca +margin .* ok$' margin.txt || { cat margin.txt; fail "margin"; }
# Trajectory scenario with the QueryCache engines: the same answers as the reference, and their
# speed-up over the cold engines is printed.
"$bench" --scenario trajectory --poses 12 --engines tightbvh-pca,tightbvh-auto,tightbvh-auto-qc --repetitions 1 \
  > trajectory.txt
[ "$(grep -cE '^tightbvh-auto-qc +(first_hit|all_pairs) .* ok$' trajectory.txt)" = 2 ] || { cat trajectory.txt; fail "trajectory"; }
grep -q 'QueryCache (front tracking, -qc' trajectory.txt || { cat trajectory.txt; fail "no QueryCache speed-up"; }
echo "test-bench: ok"
