"""Comparing the CSV tables a chapter executable writes with stored ones.

A column is *measured* (depends on the machine: wall times, rates, bandwidths) when its header ends
with a unit in brackets that contains a time: "time [s]", "rate [1/s]", "bandwidth [GB/s]",
"[ms]", "[us]", "[ns]", or with "[measured]" for a machine-dependent ratio ("fraction of triad
[measured]"). Measured columns are reported but never compared; every other column must
reproduce (numbers within a relative tolerance, text exactly). common/table.hpp states the same rule.
"""

import csv
import math
import re

MEASURED = re.compile(r"\[(s|ms|us|ns|measured|[^\]]*/\s*(s|ms|us|ns))\]\s*$")


def is_measured(header):
    return bool(MEASURED.search(header))


def read_csv(path):
    with open(path, newline="") as file:
        rows = list(csv.reader(file))
    if not rows:
        raise ValueError(f"{path} is empty")
    return rows[0], rows[1:]


def as_number(text):
    try:
        return float(text)
    except ValueError:
        return None


def close(expected, actual, rtol):
    if math.isnan(expected) or math.isnan(actual):
        return False
    return abs(actual - expected) <= rtol * max(abs(expected), abs(actual)) + 1e-300


def compare_tables(expected_header, expected_rows, actual_header, actual_rows, rtol, name):
    """A list of differences (empty when the tables agree on every non-measured column)."""
    if expected_header != actual_header:
        return [f"{name}: columns differ: expected {expected_header}, got {actual_header}"]
    if len(expected_rows) != len(actual_rows):
        return [f"{name}: expected {len(expected_rows)} rows, got {len(actual_rows)}"]
    problems = []
    for r, (want, got) in enumerate(zip(expected_rows, actual_rows)):
        for c, header in enumerate(expected_header):
            if is_measured(header):
                continue
            a, b = as_number(want[c]), as_number(got[c])
            if a is not None and b is not None:
                if not close(a, b, rtol):
                    problems.append(f"{name}, row {r + 1}, column '{header}': expected {want[c]}, "
                                    f"got {got[c]} (relative tolerance {rtol:g})")
            elif want[c] != got[c]:
                problems.append(f"{name}, row {r + 1}, column '{header}': expected '{want[c]}', "
                                f"got '{got[c]}'")
    return problems
