"""The README's Python API example runs as written, prints what its comments say and recovers the
thicker PGAs it simulates."""

import ast
import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_python_api_example_runs_and_recovers_the_parameter(tmp_path, capsys):
    block = re.search(r"## Python API.*?```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)
    code = block.replace('card = "examples/six_part_card/"', f'card = "{ROOT}/examples/six_part_card/"')
    here = os.getcwd()
    os.chdir(tmp_path)
    try:
        scope: dict = {}
        exec(compile(code, "README.md", "exec"), scope)
    finally:
        os.chdir(here)
    printed = capsys.readouterr().out
    promised = dict(re.findall(r'"(\w+)": ([-\d.e]+)\.\.\.', block))  # '# SI: {"t_PGA": 0.0041..., ...}'
    shown = next(ast.literal_eval(line) for line in printed.splitlines() if line.startswith("{'t_PGA'"))
    assert promised and all(repr(shown[k]).startswith(v) for k, v in promised.items()), (promised, shown)
    result = scope["result"]
    assert abs(result.values["t_PGA"] / 4.2e-3 - 1) < 0.05 and result.status == "converged"
    assert result.after[0]["max_freq_error_pct"] < result.before[0]["max_freq_error_pct"]
    assert "# The thesis' six-part test card" in (tmp_path / "board.updated.toml").read_text()


def test_the_api_and_the_command_line_stop_an_update_at_the_same_frequency_error():
    """The API stopped at 1 % (the snippet printed t_PGA 0.004333, not the 0.0042... it promised), the
    command line at 0.1 %."""
    from pcbdyn.commands.update import command
    from pcbdyn.problems.run import TOL_FREQ_PCT

    assert next(p.default for p in command.params if p.name == "tol_pct") == TOL_FREQ_PCT
