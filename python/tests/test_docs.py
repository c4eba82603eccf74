"""The Python in the docs runs and says what the command says: the README's Table 4 snippet and the
first walk-through block of docs/python.md print the numbers of `ffsr-optimize`'s table for the
paper's 3-DOF scenario; docs/python.md's API reference is what python/tools/api_reference.py makes
from the package's docstrings."""

import re
import subprocess
import sys

import pytest

from conftest import REPO
from test_jobs import command


def python_blocks(path):
    return re.findall(r"```python\n(.*?)```", path.read_text(), re.S)


def command_rows():
    """The command's rows for the paper's 3-DOF scenario: configuration, M_ie (kg), F_max (kN)."""
    out = subprocess.run([command(), "--config", "robots/paper_3dof.toml", "--global=false"], cwd=REPO,
                         capture_output=True, text=True, check=True, timeout=600).stdout
    rows = {}
    for line in out.splitlines():
        for name in ("Without optimization", "With optimization"):
            if line.startswith(name):
                m = re.match(r".*\[(.*?)\]\s+([\d.]+)\s+([\d.]+)", line)
                rows[name] = ([float(x) for x in m.group(1).split(",")], m.group(2), m.group(3))
        if line.startswith("Reduction (optimization)"):
            rows["Reduction"] = re.findall(r"([\d.]+)%", line)
    return rows


def run_block(code):
    return subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True,
                          timeout=600).stdout


@pytest.mark.parametrize("doc", ["README.md", "docs/python.md"])
def test_table4_snippet_prints_the_commands_numbers(doc):
    code = python_blocks(REPO / doc)[0]
    assert "Scenario.load" in code
    rows = command_rows()
    out = run_block(code)
    for name in ("Without optimization", "With optimization"):
        line = next(x for x in out.splitlines() if x.startswith(name))
        angles = [float(x) for x in re.search(r"\[(.*?)\]", line).group(1).split()]
        assert angles == rows[name][0]
        assert rows[name][1] in line and rows[name][2] in line  # M_ie (kg) and F_max (kN), 3 decimals
    red = next(x for x in out.splitlines() if x.startswith("Reduction"))
    assert re.findall(r"([\d.]+) %", red) == rows["Reduction"][:2]


def test_api_reference_is_current():
    doc = (REPO / "docs" / "python.md").read_text()
    begin, end = "<!-- api-reference: begin -->", "<!-- api-reference: end -->"
    current = doc[doc.index(begin) + len(begin):doc.index(end)].strip()
    made = subprocess.run([sys.executable, str(REPO / "python" / "tools" / "api_reference.py")],
                          capture_output=True, text=True, check=True).stdout.strip()
    assert current == made, "docs/python.md: run python/tools/api_reference.py --write"
