#!/usr/bin/env python3
"""Reads Google Benchmark JSON (with --benchmark_repetitions and aggregates) and prints, per
case, the median times of an anchor and of volmorph and their ratio, as a Markdown table.

usage: ratios.py RESULT.json ANCHOR VOLMORPH [COUNTER ...]
The COUNTERs (default density_active) are printed for both, anchor first.
"""
import json
import sys


def medians(path):
    with open(path) as f:
        data = json.load(f)
    out = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        name, _, args = b["run_name"].partition("/")
        out[(name, args.replace("/real_time", ""))] = b
    return out


def main():
    path, anchor, ours = sys.argv[1:4]
    counters = sys.argv[4:] or ["density_active"]
    m = medians(path)
    print("| case | %s (ms) | %s (ms) | %s / %s | %s / %s | %s |" % (
        anchor, ours, ours, anchor, anchor, ours, ", ".join(counters)))
    print("|---|---:|---:|---:|---:|---|")
    for (name, args), b in sorted(m.items(), key=lambda kv: kv[0][1]):
        if name != anchor or (ours, args) not in m:
            continue
        o = m[(ours, args)]
        label = (b.get("label", "") + " " + args).strip()
        values = "; ".join("%g / %g" % (b.get(c, float("nan")), o.get(c, float("nan"))) for c in counters)
        print("| %s | %.1f | %.1f | %.3f | %.1f | %s |" % (
            label, b["real_time"], o["real_time"], o["real_time"] / b["real_time"],
            b["real_time"] / o["real_time"], values))


if __name__ == "__main__":
    main()
