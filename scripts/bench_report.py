#!/usr/bin/python3
"""Prints the medians of Google Benchmark JSON results, and the ratio peer / ours for every benchmark named
BM_<Subject>_<Impl>/<args> whose Impl is not 'Ardsim' but shares Subject and args with an 'Ardsim' one."""
import json
import re
import sys

NAME = re.compile(r"^BM_(?P<subject>[A-Za-z0-9]+)_(?P<impl>[A-Za-z0-9]+)(?P<args>/.*)?$")


def medians(paths):
    """The median rows, in the order the programs define them (family, then instance), not the order run:
    repetitions may be interleaved at random."""
    rows = []
    for path in paths:
        with open(path) as f:
            for b in json.load(f)["benchmarks"]:
                if b.get("aggregate_name") != "median":
                    continue
                counters = {k: v for k, v in b.items() if k not in {
                    "name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
                    "threads", "aggregate_name", "aggregate_unit", "iterations", "real_time", "cpu_time",
                    "time_unit", "repetition_index"}}
                scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
                order = (path, b["family_index"], b["per_family_instance_index"])
                rows.append((order, b["run_name"], b["real_time"] * scale, b["cpu_time"] * scale, counters))
    return [row[1:] for row in sorted(rows, key=lambda row: row[0])]


def main(paths):
    rows = medians(paths)
    print("%-52s %12s %12s  %s" % ("benchmark (median of repetitions)", "wall ms", "cpu ms", "counters"))
    for name, wall, cpu, counters in rows:
        text = " ".join("%s=%.4g" % (k, v) for k, v in sorted(counters.items()) if isinstance(v, (int, float)))
        print("%-52s %12.4g %12.4g  %s" % (name, wall, cpu, text))
    ours = {}
    for name, wall, _, _ in rows:
        m = NAME.match(name)
        if m and m.group("impl") == "Ardsim":
            ours[(m.group("subject"), m.group("args"))] = wall
    ratios = []
    for name, wall, _, _ in rows:
        m = NAME.match(name)
        if m and m.group("impl") != "Ardsim" and (m.group("subject"), m.group("args")) in ours:
            ratios.append((name, wall / ours[(m.group("subject"), m.group("args"))]))
    if ratios:
        print("\nratio peer / ours (median wall time; > 1 means ours is faster)")
        for name, ratio in ratios:
            print("  %-50s %8.2f" % (name, ratio))


if __name__ == "__main__":
    main(sys.argv[1:])
