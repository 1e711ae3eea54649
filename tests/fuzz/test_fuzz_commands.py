"""A small sample of mutated inputs run end to end through build, correlate and update on a small plate
(tests/fuzz/fuzz_commands.py): each run ends with results whose numbers are all finite, or with one clean
``error:`` line naming the file; never a crash, a hang or a NaN. The mutations are drawn from fixed seeds
(random.Random), so most inputs get through the readers to the mesh and the solve; the readers are fuzzed
at length in test_fuzz_readers.py, and the long end-to-end run is benchmarks/fuzz_long.py."""

import random

import pytest

from fuzz_commands import CASES, simulated_test
from fuzz_mutate import Source
from fuzz_outcome import Tally

RUNS = {"build": 12, "correlate": 10, "update": 4}


@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    folder = tmp_path_factory.mktemp("seeds")
    simulated_test(folder)
    return folder


@pytest.mark.parametrize("command", sorted(RUNS))
def test_mutated_inputs_through_the_command(command, seeds, tmp_path, record_property):
    tally = Tally()
    for seed in range(RUNS[command]):
        tally.add(CASES[command](Source(rng=random.Random(seed)), seeds, tmp_path))
    record_property("fuzz_counts", [[k, s, n] for (k, s), n in tally.counts.items()])
    failures = {k: v for k, v in tally.examples.items()}
    assert not failures, failures
