#!/usr/bin/env python3
"""The cost model of a collide() query
(docs/design-notes/collide.md, "Where a query's time goes (the cost model)").

Reads the JSON of
  build/bin/tightbvh-collide-bench --benchmark_filter='BM_Traversal/fitter:6/.*/descend:0|BM_Replay' \
      --benchmark_format=json --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
(stdin or a file) and prints, per scenario and mode of the auto trees: the measured time of a query,
its box and triangle tests, the measured cost of one of each (replayed without the descent), and
what share of the query they explain; the rest is the descent itself (stack, descend decisions,
leaf bookkeeping, result).
"""
import json
import re
import sys

SCENARIOS = ["deep", "near", "separated"]


def main():
    data = json.load(open(sys.argv[1]) if len(sys.argv) > 1 else sys.stdin)
    rows = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name", "median") != "median":
            continue
        name = b.get("run_name", b["name"])
        m = re.match(r"BM_Traversal/fitter:6/scenario:(\d)/all_pairs:(\d)/descend:0", name)
        if m:
            r = rows.setdefault((int(m[1]), int(m[2])), {})
            r["query_us"] = 1e6 / b["queries_per_s"]
            r["box_tests"] = b["box_tests"]
            r["tri_tests"] = b["tri_tests"]
            continue
        m = re.match(r"BM_Replay(Box|Triangle)Tests/scenario:(\d)/all_pairs:(\d)", name)
        if m:
            r = rows.setdefault((int(m[2]), int(m[3])), {})
            r["box_ns" if m[1] == "Box" else "tri_ns"] = 1e9 / b["items_per_second"] if b.get("items_per_second") else 0.0
    print("| scenario | mode | query µs | box tests | ns/box test | triangle tests | ns/triangle test "
          "| box tests' share | triangle tests' share | descent overhead |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for (s, mode), r in sorted(rows.items()):
        if not {"query_us", "box_ns", "tri_ns"} <= r.keys():
            continue
        box_us = r["box_tests"] * r["box_ns"] / 1e3
        tri_us = r["tri_tests"] * r["tri_ns"] / 1e3
        q = r["query_us"]
        print(f"| {SCENARIOS[s]} | {'all_pairs' if mode else 'first_hit'} | {q:.1f} | {r['box_tests']:.0f} "
              f"| {r['box_ns']:.1f} | {r['tri_tests']:.0f} | {r['tri_ns']:.1f} | {100 * box_us / q:.0f}% "
              f"| {100 * tri_us / q:.0f}% | {100 * (1 - (box_us + tri_us) / q):.0f}% |")


if __name__ == "__main__":
    main()
