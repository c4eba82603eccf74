"""The command's jobs as Python calls: Scenario.load(path, **overrides).run().to_dict() against the
--json that `ffsr-optimize --config FILE` writes for the same scenario, on the paper's three scenarios,
every number to 1e-12 (relative, absolute below 1) and every other value equal, but for the search's
wall-clock time.

The command is the one of the C++ build: $FFSR_OPTIMIZE, else build-ci/ or build/ of the repository;
the tests skip with a message when none is built."""

import json
import math
import os
import pathlib
import subprocess

import pytest

import ffsr
from conftest import REPO, ROBOTS


def command():
    candidates = [os.environ.get("FFSR_OPTIMIZE", "")] + [str(REPO / d / "src/cli/ffsr-optimize")
                                                          for d in ("build-ci", "build")]
    for c in candidates:
        if c and pathlib.Path(c).is_file():
            return c
    pytest.skip("no ffsr-optimize built (set FFSR_OPTIMIZE, or build build-ci/ or build/)")


# wall-clock times (global.search.seconds): the one key of the result that is not a result
UNCOMPARED = {"seconds"}


def differences(a, b, path="$"):
    """Where two JSON values differ: numbers beyond 1e-12, anything else not equal."""
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or a is None:
        return [] if a == b else [f"{path}: {a!r} != {b!r}"]
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if math.isnan(a) and math.isnan(b):
            return []
        return [] if abs(a - b) <= 1e-12 * max(1.0, abs(a), abs(b)) else [f"{path}: {a!r} != {b!r}"]
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{path}: keys {sorted(set(a) ^ set(b))} in one only"] if set(a) != set(b) else []
        for k in sorted((set(a) & set(b)) - UNCOMPARED):
            out += differences(a[k], b[k], f"{path}.{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} != {len(b)} entries"]
        out = []
        for i, (x, y) in enumerate(zip(a, b)):
            out += differences(x, y, f"{path}[{i}]")
        return out
    return [f"{path}: {type(a).__name__} != {type(b).__name__}"]


def command_json(tmp_path, scenario, *flags):
    out = tmp_path / "result.json"
    subprocess.run([command(), "--config", str(scenario), "--quiet", "--json", str(out), *flags], check=True,
                   timeout=900)
    return json.loads(out.read_text())


@pytest.mark.parametrize("name", ["paper_3dof", "paper_7dof_position", "paper_7dof_pose"])
def test_run_equals_the_command(tmp_path, name):
    scenario = ROBOTS / f"{name}.toml"
    expected = command_json(tmp_path, scenario)
    result = ffsr.Scenario.load(str(scenario)).run()
    got = result.to_dict()
    assert differences(got, expected) == []
    # the typed result holds the same numbers
    assert result.optimized.M_ie == got["optimized"]["integrated_effective_mass"]


def test_override_equals_the_flag(tmp_path):
    scenario = ROBOTS / "paper_3dof.toml"
    expected = command_json(tmp_path, scenario, "--gain", "-0.02", "--global=false")
    # `global` is a Python keyword: passed through a dict
    got = ffsr.Scenario.load(str(scenario), gain=-0.02, **{"global": False}).run().to_dict()
    assert differences(got, expected) == []


def test_bad_scenario_input(tmp_path):
    with pytest.raises(ffsr.InputError, match="--gian: not a scenario key"):
        ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), gian=1.0)
    with pytest.raises(ffsr.InputError, match="--duration"):
        ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), duration=-1.0)
    bad = tmp_path / "bad.toml"
    bad.write_text("urdf = [\n")
    with pytest.raises(ffsr.InputError, match=f"scenario {bad}"):
        ffsr.Scenario.load(str(bad))
