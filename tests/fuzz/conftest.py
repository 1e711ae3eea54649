"""The fuzz tests report how many inputs of each kind they generated and what came of them: each test
records its counts as a user property (so they reach the controller under pytest-xdist too), and the
table is printed at the end of the run."""

import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

_COUNTS = Counter()


def pytest_runtest_logreport(report):
    if report.when != "call":
        return
    for key, value in report.user_properties:
        if key == "fuzz_counts":
            for kind, status, n in value:
                _COUNTS[kind, status] += n


def pytest_terminal_summary(terminalreporter):
    if not _COUNTS:
        return
    from fuzz_outcome import Tally

    tally = Tally()
    tally.counts = _COUNTS
    terminalreporter.write_sep("-", "fuzzed inputs by kind (tests/fuzz)")
    terminalreporter.write_line(tally.table())
