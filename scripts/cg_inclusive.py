#!/usr/bin/env python3
"""Inclusive instruction counts per function from a callgrind output file
written with --compress-strings=no --compress-pos=no (scripts/profile.sh).

    cg_inclusive.py FILE PATTERN...

Prints, for each PATTERN (a substring of the function name), the summed
inclusive cost of the functions whose name contains it (calls among
matching functions are counted once: only calls from outside the set add).
"""
import sys
from collections import defaultdict


def parse(path):
    """self[fn], calls[(caller, callee)] = inclusive cost of those calls."""
    self_cost = defaultdict(int)
    calls = defaultdict(int)
    fn = None
    callee = None
    after_calls = False
    with open(path) as f:
        for line in f:
            if line.startswith("fn="):
                fn = line[3:].strip()
            elif line.startswith("cfn="):
                callee = line[4:].strip()
            elif line.startswith("calls="):
                after_calls = True
            elif line[:1].isdigit() or line[:1] in "+-*":
                parts = line.split()
                cost = int(parts[1]) if len(parts) > 1 else 0
                if after_calls:
                    calls[(fn, callee)] += cost
                    after_calls = False
                elif fn is not None:
                    self_cost[fn] += cost
    return self_cost, calls


def inclusive(self_cost, calls, match):
    inside = {f for f in self_cost if match(f)} | {
        f for (a, b) in calls for f in (a, b) if match(f)
    }
    total = sum(self_cost[f] for f in inside)
    total += sum(c for (a, b), c in calls.items() if a in inside and b not in inside)
    return total


def main():
    path, patterns = sys.argv[1], sys.argv[2:]
    self_cost, calls = parse(path)
    for p in patterns:
        print(f"{inclusive(self_cost, calls, lambda f: p in f)}\t{p}")


if __name__ == "__main__":
    main()
