"""Comparing the CSV tables a chapter executable writes with stored ones.

A column is *measured* (depends on the machine: wall times, rates, bandwidths) when its header ends
with a unit in brackets that contains a time: "time [s]", "rate [1/s]", "bandwidth [GB/s]",
"[ms]", "[us]" or "[µs]", "[ns]", or with "[measured]" for a machine-dependent ratio ("fraction of triad
[measured]"). Measured columns are reported but never compared; every other column must
reproduce (numbers within a relative tolerance, text exactly). common/table.hpp states the same rule.

A number at ROUND-OFF level is held to a bound, never to its stored digits: when the stored value
has magnitude ≤ ROUNDOFF_LEVEL (1e-12), the new one passes when its magnitude is ≤ ROUNDOFF_BOUND
(1e-10). Residuals and errors of exact solvers, symmetry defects and the like sit at 1e-16…1e-12,
and their digits depend on which BLAS kernel the processor gets (OpenBLAS picks one at run time),
on the number of BLAS threads and on run-time SIMD dispatch (chapter 08's AVX2 kernel); their size
does not. Values above that level (a discretisation error, a CG error at its tolerance) are
reproducible and keep the relative tolerance, except in their digits below ROUNDOFF_LEVEL: two
values that differ by at most ROUNDOFF_LEVEL agree (a relative error of 6.1103e-9 that becomes
6.1101e-9 when a solve rounds differently is the same result).

A column whose header ends with "[round-off]" holds round-off amplified by a condition number
(e.g. "max deviation / max tip [round-off]": 1e-13…1e-10): each new value passes when it is at most
ROUNDOFF_GROWTH (100) times the stored one, or ≤ ROUNDOFF_BOUND.

A column whose header ends with "[±X]" (e.g. "final relative error [±1e-10]") holds values whose
digits below X are round-off of that computation (an error measured against a reference that is
itself exact only to round-off times a condition number): two values that differ by at most X agree.
The header says so to the reader as well.

A column whose header names iterations ("CG iterations per step") counts the steps of an iterative
solver until a residual test passes. The last test compares a round-off-affected residual with a
tolerance, so a different rounding can move a count by one: counts (and their averages) agree
within ITERATION_SLACK (1). A solver gone wrong misses by far more.

A number the docs quote in a sentence (check_docs.py, <!-- fem:value … -->) is read with
quoted_number and holds when the table's value, rounded to the digits the sentence shows, is it.
"""

import csv
import math
import re

# A number as prose writes it: 6e-3, 0.27, −2.2, 50 700 (thin or plain spaces between groups of
# three), 6·10⁻³, 6 × 10⁻³ or 10⁴.
PROSE_NUMBER = re.compile(r"(?P<mantissa>[-+]?\d{1,3}(?:[ \u2009\u202f]\d{3})+|[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?)?"
                          r"(?:\s*[·×]?\s*10(?P<power>[⁻]?[⁰¹²³⁴⁵⁶⁷⁸⁹]+))?")
SUPERSCRIPTS = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻", "0123456789-")
MEASURED = re.compile(r"\[(s|ms|us|µs|ns|measured|[^\]]*/\s*(s|ms|us|µs|ns))\]\s*$")
ROUNDOFF = re.compile(r"\[round-off\]\s*$")
ROUNDOFF_LEVEL = 1e-12
ROUNDOFF_BOUND = 1e-10
ROUNDOFF_GROWTH = 100.0
UNCERTAINTY = re.compile(r"\[±(?P<amount>[0-9.]+(?:e[-+]?[0-9]+)?)\]\s*$")
ITERATIONS = re.compile(r"\biterations\b", re.IGNORECASE)
ITERATION_SLACK = 1.0


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


def is_roundoff(header):
    return bool(ROUNDOFF.search(header))


def close(expected, actual, rtol, roundoff_column=False, uncertainty=0.0):
    """Within rtol of each other, or within the round-off rules above (uncertainty: a column's ±X)."""
    if math.isnan(expected) or math.isnan(actual):
        return False
    if roundoff_column:
        return abs(actual) <= max(ROUNDOFF_GROWTH * abs(expected), ROUNDOFF_BOUND)
    if abs(expected) <= ROUNDOFF_LEVEL:
        return abs(actual) <= ROUNDOFF_BOUND
    return abs(actual - expected) <= max(rtol * max(abs(expected), abs(actual)), ROUNDOFF_LEVEL, uncertainty)


def cells_differ(header, expected, actual, rtol):
    """None when a stored cell and a new one of the column `header` agree by the rules above (text
    cells: exactly), else the rule they break, for the message. Measured columns always agree."""
    if is_measured(header):
        return None
    a, b = as_number(expected), as_number(actual)
    if a is None or b is None:
        return None if expected == actual else "text must match"
    if ITERATIONS.search(header):
        return None if abs(a - b) <= ITERATION_SLACK and not math.isnan(a - b) else \
            f"iteration counts agree within {ITERATION_SLACK:g}"
    uncertainty = UNCERTAINTY.search(header)
    if close(a, b, rtol, is_roundoff(header), float(uncertainty["amount"]) if uncertainty else 0.0):
        return None
    if is_roundoff(header):
        return f"a round-off column may grow {ROUNDOFF_GROWTH:g}x"
    if abs(a) <= ROUNDOFF_LEVEL:
        return f"a round-off value must stay at most {ROUNDOFF_BOUND:g}"
    if uncertainty:
        return f"values agree within ±{uncertainty['amount']} or relative tolerance {rtol:g}"
    return f"relative tolerance {rtol:g}"


def quoted_number(text):
    """(value, significant digits) of a number as the docs write it, or None if it is not one.
    The digits are those the text shows: 6·10⁻³ has 1, 0.0595 has 3, 2.20 has 3, 300 has 1."""
    text = text.strip().replace("−", "-")
    m = PROSE_NUMBER.fullmatch(text)
    if not text or not m or not (m["mantissa"] or m["power"]):
        return None
    mantissa = re.sub(r"[ \u2009\u202f]", "", m["mantissa"] or "1")
    value = float(mantissa) * (10.0 ** int(m["power"].translate(SUPERSCRIPTS)) if m["power"] else 1.0)
    digits = re.sub(r"e.*$", "", mantissa.lstrip("+-")).replace(".", "").lstrip("0")
    if "." not in mantissa:
        digits = digits.rstrip("0")
    return value, max(len(digits), 1)


def rounded(value, digits):
    """value rounded to that many significant digits."""
    if value == 0 or not math.isfinite(value):
        return value
    return round(value, digits - 1 - math.floor(math.log10(abs(value))))


def compare_tables(expected_header, expected_rows, actual_header, actual_rows, rtol, name):
    """A list of differences (empty when the tables agree on every non-measured column)."""
    if expected_header != actual_header:
        return [f"{name}: columns differ: expected {expected_header}, got {actual_header}"]
    if len(expected_rows) != len(actual_rows):
        return [f"{name}: expected {len(expected_rows)} rows, got {len(actual_rows)}"]
    problems = []
    for r, (want, got) in enumerate(zip(expected_rows, actual_rows)):
        for c, header in enumerate(expected_header):
            rule = cells_differ(header, want[c], got[c], rtol)
            if rule:
                problems.append(f"{name}, row {r + 1}, column '{header}': expected '{want[c]}', "
                                f"got '{got[c]}' ({rule})")
    return problems


def self_test():
    """The rules above on examples (ctest: csv_compare_rules)."""
    assert close(1.0, 1.0 + 1e-7, 1e-6) and not close(1.0, 1.01, 1e-6)
    assert close(6.7e-15, 6.9e-15, 1e-6) and close(8e-16, 9e-11, 1e-6)   # round-off: bounded
    assert not close(8e-16, 2e-10, 1e-6)                                   # grew past the bound
    assert close(3e-11, 9e-11, 1e-6, True) and close(3e-11, 2.9e-9, 1e-6, True)  # [round-off] column
    assert not close(3e-11, 4e-9, 1e-6, True) and close(1e-14, 5e-11, 1e-6, True)
    assert not close(5.8e-10, 5.9e-10, 1e-6)                               # above round-off: digits
    assert close(6.1103777e-9, 6.1101246e-9, 1e-6) and not close(6.1e-9, 6.2e-9, 1e-6)  # below 1e-12 apart
    assert not close(float("nan"), 1e-15, 1e-6) and not close(1e-15, float("nan"), 1e-6)
    assert is_measured("time [s]") and is_measured("rate [1/s]") and not is_measured("residual")
    assert is_measured("median time per query [µs]") and is_measured("time per query [us]")
    header = ["x", "error", "time [s]"]
    assert compare_tables(header, [["1", "1e-15", "3"]], header, [["1", "4e-14", "9"]], 1e-6, "t") == []
    assert len(compare_tables(header, [["1", "1e-15", "3"]], header, [["2", "4e-10", "9"]], 1e-6, "t")) == 2
    header = ["CG iterations per step"]
    assert compare_tables(header, [["20.25"]], header, [["20.75"]], 1e-6, "t") == []
    assert len(compare_tables(header, [["20.25"]], header, [["23"]], 1e-6, "t")) == 1
    header = ["final relative error [±1e-10]"]
    assert compare_tables(header, [["1.650e-11"]], header, [["1.831e-11"]], 1e-6, "t") == []
    assert compare_tables(header, [["3.610e-09"]], header, [["3.65e-09"]], 1e-6, "t") == []
    assert len(compare_tables(header, [["3.610e-09"]], header, [["3.8e-09"]], 1e-6, "t")) == 1
    assert len(compare_tables(["a"], [["yes"]], ["a"], [["no"]], 1e-6, "t")) == 1
    assert len(compare_tables(["CG iterations"], [["nan"]], ["CG iterations"], [["nan"]], 1e-6, "t")) == 1
    header = ["deviation [round-off]"]
    assert compare_tables(header, [["2e-11"]], header, [["7e-11"]], 1e-6, "t") == []
    assert quoted_number("6·10⁻³") == (0.006, 1) and quoted_number("6 × 10⁻³") == (0.006, 1)
    assert quoted_number("10⁴") == (1e4, 1) and quoted_number("2.20") == (2.2, 3)
    assert quoted_number("50 700") == (50700.0, 3) and quoted_number("300") == (300.0, 1)
    assert quoted_number("−0.0595") == (-0.0595, 3) and quoted_number("1.2e-03") == (0.0012, 2)
    assert quoted_number("a few") is None and quoted_number("") is None
    assert rounded(5.954e-3, 1) == 0.006 and rounded(294.1, 1) == 300.0 and rounded(2.196, 2) == 2.2
    print("csv_compare: rules hold")


if __name__ == "__main__":
    self_test()
