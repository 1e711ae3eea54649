"""Property-based fuzzing of every input kind at its validation boundary (hypothesis): structured
mutations (a field, a cell, a number or line of a UFF dataset) and byte-level ones of the bundled examples,
each input read as pcbdyn reads it. The property: the reader returns a result in which every number is
finite, or raises one of pcbdyn's input errors, in one line, naming the file; an input known to be
invalid (a quantity with a decimal comma, a bare unit, arithmetic or a non-finite number, a byte that is
not UTF-8, a measured frequency at or below 0, a mode asked beyond the limit, ...) must be refused. Inputs
per kind: PCBDYN_FUZZ_EXAMPLES (default 220: 27 kinds and the command runs make over 6,000 inputs); the
examples are derandomised, so a run repeats; the long run with fresh seeds is benchmarks/fuzz_long.py."""

import os

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzz_kinds import MESSAGE_NAME, kinds
from fuzz_mutate import Source
from fuzz_outcome import Tally, classify

EXAMPLES = int(os.environ.get("PCBDYN_FUZZ_EXAMPLES", 220))
NAMES = [k.name for k in kinds(None)]


@pytest.mark.parametrize("name", NAMES)
def test_every_input_is_read_or_refused_cleanly(name, tmp_path, record_property):
    kind = next(k for k in kinds(tmp_path) if k.name == name)
    tally = Tally()

    @settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(st.data())
    def fuzz(data):
        item, invalid = kind.one(Source(data=data), tmp_path)
        shown = MESSAGE_NAME.get(name, getattr(item, "name", None))
        out = classify(name, lambda: kind.read(item), shown, invalid)
        tally.add(out)
        assert not out.failed, f"{out.status}: {out.detail}"

    try:
        fuzz()
    finally:
        record_property("fuzz_counts", [[k, s, n] for (k, s), n in tally.counts.items()])
