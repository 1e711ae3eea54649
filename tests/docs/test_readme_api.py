"""The README's Python API example runs as written and recovers the thicker PGAs it simulates."""

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
    result = scope["result"]
    assert abs(result.values["t_PGA"] / 4.2e-3 - 1) < 0.05 and result.status == "converged"
    assert result.after[0]["max_freq_error_pct"] < result.before[0]["max_freq_error_pct"]
    assert "# The thesis' six-part test card" in (tmp_path / "board.updated.toml").read_text()
