"""The command's jobs as Python calls: Scenario.load(path, **overrides).run().to_dict() against the
--json that `ffsr-optimize --config FILE` writes for the same scenario, on the paper's three scenarios,
every number to 1e-12 (relative, absolute below 1) and every other value equal, but for the search's
wall-clock time.

The command is the one of the C++ build: $FFSR_OPTIMIZE, else build-ci/ or build/ of the repository;
the tests skip with a message when none is built."""

import csv
import io
import json
import math
import os
import pathlib
import subprocess

import numpy as np
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


def command_json(tmp_path, scenario, *flags, subcommand=None):
    out = tmp_path / "result.json"
    sub = [subcommand] if subcommand else []
    subprocess.run([command(), *sub, "--config", str(scenario), "--quiet", "--json", str(out), *flags], check=True,
                   timeout=900)
    return json.loads(out.read_text())


SCENARIOS = ["paper_3dof", "paper_7dof_position", "paper_7dof_pose"]


@pytest.mark.parametrize("name", SCENARIOS)
def test_run_equals_the_command(tmp_path, name):
    scenario = ROBOTS / f"{name}.toml"
    expected = command_json(tmp_path, scenario)
    result = ffsr.Scenario.load(str(scenario)).run()
    got = result.to_dict()
    assert differences(got, expected) == []
    # the typed result holds the same numbers
    assert result.optimized.M_ie == got["optimized"]["integrated_effective_mass"]


def test_run_series_equals_the_command_csv(tmp_path):
    """RunResult.series holds the columns of the command's --csv (the arrays the 3-D view draws), every
    number to 1e-12; each run's last sample is that run's capture configuration."""
    scenario = ROBOTS / "paper_3dof.toml"
    out = tmp_path / "series.csv"
    subprocess.run([command(), "--config", str(scenario), "--quiet", "--csv", str(out)], check=True, timeout=900)
    lines = list(csv.reader(io.StringIO(out.read_text())))
    header, rows = lines[0], lines[1:]
    result = ffsr.Scenario.load(str(scenario)).run()
    series = result.series
    assert list(series) == header
    for i, name in enumerate(header):
        column = series[name]
        assert len(column) == len(rows), name
        if name in ("run", "phase"):
            assert list(column) == [r[i] for r in rows], name
        else:
            assert isinstance(column, np.ndarray) and column.dtype == np.float64, name
            np.testing.assert_allclose(column, [float(r[i]) for r in rows], rtol=1e-12, atol=1e-12, err_msg=name)
    assert result.series_csv() == out.read_text()
    joints = [h for h in header if h.endswith("_deg")]
    runs = np.array(series["run"])
    for label, run in (("baseline", result.plain), ("optimized", result.optimized), ("global", result.global_run)):
        last = np.flatnonzero(runs == label)[-1]
        np.testing.assert_allclose([series[j][last] for j in joints], np.degrees(run.theta), rtol=0, atol=1e-9)
        assert series["t"][last] == pytest.approx(result.to_dict()["scene"]["capture_time"], rel=1e-12)


def test_run_with_post_capture_equals_the_command_and_the_detumble_job(tmp_path):
    """The main job of a scenario with Detumble keys: each run's post_capture is the command's, and the
    figures of Scenario.detumble(run='all') (a separate run), to the bit."""
    scenario = ROBOTS / "paper_7dof_detumble.toml"
    expected = command_json(tmp_path, scenario)
    result = ffsr.Scenario.load(str(scenario)).run()
    got = result.to_dict()
    assert differences(got, expected) == []
    assert sorted(result.post_capture) == ["baseline", "global", "optimized"]
    alone = {r.pop("run"): r for r in ffsr.Scenario.load(str(scenario)).detumble(run="all").to_dict()["runs"]}
    for name, figures in result.post_capture.items():
        assert got[name]["post_capture"] == alone[name]
        assert figures.time_to_rest == got[name]["post_capture"]["time_to_rest"]
        assert figures.peak_joint_torque == got[name]["post_capture"]["peak_joint_torque"]
        assert figures.at_rest and figures.ticks == got[name]["post_capture"]["ticks"]
    # without a Detumble key the runs stop at the impact
    plain = ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), **{"global": False}).run()
    assert plain.post_capture == {} and "post_capture" not in plain.to_dict()["baseline"]


def test_run_with_post_capture_error_names_the_key_and_the_run():
    scenario = ROBOTS / "paper_7dof_detumble.toml"
    with pytest.raises(ffsr.InputError, match=r"--detumble-horizon: .*not at rest after 0\.1 s.*baseline run"):
        ffsr.Scenario.load(str(scenario), detumble_horizon=0.1, **{"global": False}).run()


@pytest.mark.parametrize("name", SCENARIOS)
def test_inspect_equals_the_command(tmp_path, name):
    scenario = ROBOTS / f"{name}.toml"
    expected = command_json(tmp_path, scenario, subcommand="inspect")
    result = ffsr.Scenario.load(str(scenario)).inspect()
    got = result.to_dict()
    assert differences(got, expected) == []
    # the typed result holds the same numbers
    assert result.M_ie == got["integrated_effective_mass"]
    assert result.m_e == got["effective_mass"]
    assert result.J_f.tolist() == got["J_f"]
    assert result.H.shape == (6 + len(got["joint_names"]),) * 2


def test_inspect_override_equals_the_flag(tmp_path):
    scenario = ROBOTS / "paper_7dof_position.toml"
    expected = command_json(tmp_path, scenario, "--contact-joints", "locked", "--joints-deg",
                            "10,20,30,40,50,60,70", subcommand="inspect")
    got = ffsr.Scenario.load(str(scenario), contact_joints="locked", joints_deg=[10, 20, 30, 40, 50, 60, 70])
    assert differences(got.inspect().to_dict(), expected) == []


@pytest.mark.parametrize("name", SCENARIOS)
def test_contact_equals_the_command(tmp_path, name):
    scenario = ROBOTS / f"{name}.toml"
    expected = command_json(tmp_path, scenario, subcommand="contact")
    result = ffsr.Scenario.load(str(scenario)).contact()
    got = result.to_dict()
    assert differences(got, expected) == []
    assert result.rows[0].f_max_multibody == got["f_max_multibody"]
    assert result.rows[0].M_ie == got["integrated_effective_mass"]
    assert result.rows[0].series.shape == (0, 3)


def test_contact_every_law_and_joint_model(tmp_path):
    scenario = ROBOTS / "paper_3dof.toml"
    expected = command_json(tmp_path, scenario, "--model", "all", "--contact-joints", "all", subcommand="contact")
    result = ffsr.Scenario.load(str(scenario)).contact(model="all", contact_joints="all", series=True)
    got = result.to_dict()
    assert differences(got, expected) == []
    assert [r.model for r in result.rows] == [law["model"] for law in got["laws"]]
    assert all(r.series.shape[0] > 10 and r.series.shape[1] == 3 for r in result.rows)
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.contact: model: "):
        ffsr.Scenario.load(str(scenario)).contact(model="hertz-nonsense")


@pytest.mark.parametrize("name", SCENARIOS)
def test_closed_loop_equals_the_command(tmp_path, name):
    scenario = ROBOTS / f"{name}.toml"
    expected = command_json(tmp_path, scenario, subcommand="closed-loop")
    result = ffsr.Scenario.load(str(scenario)).closed_loop()
    got = result.to_dict()
    assert differences(got, expected) == []
    assert result.M_ie == got["closed_loop"]["integrated_effective_mass"]
    assert result.open_loop.M_ie == got["open_loop"]["integrated_effective_mass"]


def test_closed_loop_flags_equal_the_keywords(tmp_path):
    scenario = ROBOTS / "paper_3dof.toml"
    expected = command_json(tmp_path, scenario, "--position-noise", "0.002", "--attitude-noise-deg", "0.5",
                            "--spin-noise-deg", "0.1", "--noise-seed", "7", "--prediction-window", "3",
                            "--control-rate", "500", subcommand="closed-loop")
    result = ffsr.Scenario.load(str(scenario)).closed_loop(position_noise=0.002, attitude_noise_deg=0.5,
                                                           spin_noise_deg=0.1, noise_seed=7, prediction_window=3,
                                                           control_rate=500)
    assert differences(result.to_dict(), expected) == []
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.closed_loop: control_rate: must be positive and finite"):
        ffsr.Scenario.load(str(scenario)).closed_loop(control_rate=0.0)
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.closed_loop: plan: expected paper or global"):
        ffsr.Scenario.load(str(scenario)).closed_loop(plan="best")


def test_robust_equals_the_command(tmp_path):
    # the paper's scenarios have no [uncertainty] table: the 7-DOF position scenario with the table, its
    # plain and paper's-method configurations (global = false)
    scenario = ROBOTS / "paper_7dof_position_uncertain.toml"
    expected = command_json(tmp_path, scenario, "--global=false", "--samples", "200", "--threads", "2",
                            subcommand="robust")
    result = ffsr.Scenario.load(str(scenario), **{"global": False}).robust(samples=200, threads=2)
    got = result.to_dict()
    assert differences(got, expected) == []
    assert [c.name for c in result.configurations] == ["plain", "optimized"]
    assert result.configurations[1].p95 == got["configurations"][1]["summary"]["p95"]
    assert result.configurations[1].f_max.shape == (200,)


def test_robust_given_configuration_equals_the_command(tmp_path):
    scenario = ROBOTS / "paper_7dof_position_uncertain.toml"
    joints = [10, 80, 95, -85, 80, 95, 5]
    expected = command_json(tmp_path, scenario, "--capture-joints-deg", ",".join(map(str, joints)),
                            "--capture-base-position", "0.01,0,-0.02", "--force-model", "closed", "--samples", "300",
                            "--seed", "5", "--shard", "1/2", subcommand="robust")
    got = ffsr.Scenario.load(str(scenario)).robust(capture_joints_deg=joints, capture_base_position=[0.01, 0, -0.02],
                                                   force_model="closed", samples=300, seed=5, shard_k=1, shard_n=2)
    assert differences(got.to_dict(), expected) == []
    with pytest.raises(ffsr.InputError, match="no \\[uncertainty\\] table"):
        ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml")).robust()
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.robust: force_model: "):
        ffsr.Scenario.load(str(scenario)).robust(force_model="fast", capture_joints_deg=joints)


@pytest.mark.parametrize("name", SCENARIOS)
def test_pareto_equals_the_command(tmp_path, name):
    scenario = ROBOTS / f"{name}.toml"
    expected = command_json(tmp_path, scenario, "--levels", "6", "--starts", "4", subcommand="pareto")
    result = ffsr.Scenario.load(str(scenario)).pareto(levels=6, starts=4)
    got = result.to_dict()
    assert differences(got, expected) == []  # but the search's wall-clock time (seconds)
    assert result.knee.M_ie == got["knee"]["integrated_effective_mass"]
    assert len(result.front) == len(got["front"])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.pareto: levels: must be >= 1"):
        ffsr.Scenario.load(str(scenario)).pareto(levels=0)


def test_run_with_post_capture_constraints_equals_the_command(tmp_path):
    # the global search keeps the captures whose post-capture run, braking at 2 N m per joint, rests
    # within 1.5 s
    scenario = ROBOTS / "paper_3dof.toml"
    expected = command_json(tmp_path, scenario, "--global-starts", "2", "--joint-torque-limit", "2",
                            "--max-time-to-rest", "1.5")
    got = ffsr.Scenario.load(str(scenario), global_starts=2, joint_torque_limit=2,
                             max_time_to_rest=1.5).run().to_dict()
    assert differences(got, expected) == []
    assert 0 < got["global"]["post_capture_constraints"]["time_to_rest"] <= 1.5
    # the same capture's post-capture figures under the two names: the constraints' and the run's
    assert (got["global"]["post_capture_constraints"]["time_to_rest"] ==
            got["global"]["post_capture"]["time_to_rest"])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: max_peak_joint_torque: must be positive"):
        ffsr.Scenario.load(str(scenario), max_peak_joint_torque=-1)


def test_pareto_post_capture_axis_equals_the_command(tmp_path):
    # the 3-DOF robot with 20 N m joints: the front of M_ie against the time to rest
    scenario = ROBOTS / "paper_3dof.toml"
    flags = ("--levels", "3", "--starts", "2", "--global-starts", "2", "--axis", "time-to-rest",
             "--joint-torque-limit", "20")
    expected = command_json(tmp_path, scenario, *flags, subcommand="pareto")
    result = ffsr.Scenario.load(str(scenario), global_starts=2, joint_torque_limit=20).pareto(
        levels=3, starts=2, axis="time-to-rest")
    got = result.to_dict()
    assert differences(got, expected) == []
    assert result.axis == got["axis"] == "time-to-rest"
    front = got["post_capture"]["front"]
    assert [p["value"] for p in front] == [p["time_to_rest"] for p in front]
    assert all(a["integrated_effective_mass"] < b["integrated_effective_mass"] and a["value"] > b["value"]
               for a, b in zip(front, front[1:]))
    assert result.front_csv().splitlines()[0].startswith("index,M_ie_kg,time_to_rest_s,")
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.pareto: axis: expected"):
        ffsr.Scenario.load(str(scenario)).pareto(axis="torque")


def map_csv(path, header):
    """The rows of a map CSV as an array (one row per point); header: whether the file starts with one."""
    return np.loadtxt(path, delimiter=",", skiprows=1 if header else 0, ndmin=2)


@pytest.mark.parametrize("name", SCENARIOS)
def test_map_equals_the_command(tmp_path, name):
    scenario = ROBOTS / f"{name}.toml"
    csv = tmp_path / "map.csv"
    expected = command_json(tmp_path, scenario, "--vary", "1,2", "--step-deg", "40", "--csv", str(csv),
                            subcommand="map")
    result = ffsr.Scenario.load(str(scenario)).map([1, 2], step_deg=[40])
    assert differences(result.to_dict(), expected) == []
    # every point of the CSV, exactly: the command writes the shortest text that reads back the same double
    rows = map_csv(csv, header=True)
    assert result.angles_deg.shape == (81, 2) and rows.shape == (81, 4)
    assert np.array_equal(result.angles_deg, rows[:, :2])
    assert np.array_equal(result.M_ie, rows[:, 2])
    assert np.array_equal(result.f_max, rows[:, 3])
    assert (result.points, result.first, result.end) == (81, 0, 81)
    i = int(np.argmax(result.M_ie))
    assert result.M_ie[i] == expected["max"]["integrated_effective_mass"]
    assert list(result.angles_deg[i]) == expected["max"]["angles_deg"]


def test_map_shard_joint_model_and_threads(tmp_path):
    scenario = ROBOTS / "paper_7dof_position.toml"
    csv = tmp_path / "map.csv"
    flags = ("--vary", "2,4,6", "--range-deg", "-90,90", "--step-deg", "30", "--contact-joints", "locked")
    expected = command_json(tmp_path, scenario, *flags, "--shard", "1/3", "--csv", str(csv), subcommand="map")
    sc = ffsr.Scenario.load(str(scenario), contact_joints="locked")
    part = sc.map([2, 4, 6], range_deg=[-90, 90], step_deg=[30], shard_k=1, shard_n=3, threads=3)
    assert differences(part.to_dict(), expected) == []
    rows = map_csv(csv, header=False)  # shard 1 of 3: no header line
    assert np.array_equal(part.M_ie, rows[:, 3]) and np.array_equal(part.f_max, rows[:, 4])
    # the shard is its slice of the whole grid, whatever the threads
    whole = sc.map([2, 4, 6], range_deg=[-90, 90], step_deg=[30], threads=1)
    assert np.array_equal(whole.M_ie[part.first:part.end], part.M_ie)
    assert np.array_equal(whole.angles_deg[part.first:part.end], part.angles_deg)
    # locking the joints can only add inertia at the contact: M_ie at least the free joints' everywhere
    assert whole.to_dict()["contact_joints"] == "locked"
    free = ffsr.Scenario.load(str(scenario)).map([2, 4, 6], range_deg=[-90, 90], step_deg=[30])
    assert np.all(whole.M_ie >= free.M_ie * (1 - 1e-12)) and np.any(whole.M_ie > 1.01 * free.M_ie)


def test_map_bad_input():
    sc = ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"))
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.map: vary: joint 4 is not one of 1\.\.3"):
        sc.map([4])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.map: vary: joint 1 is given twice"):
        sc.map([1, 1])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.map: range_deg: the range of joint 1 is inverted"):
        sc.map([1], range_deg=[10, 5])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.map: range_deg: expected 2 numbers, got 3"):
        sc.map([1], range_deg=[1, 2, 3])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.map: step_deg: the step must be positive"):
        sc.map([1], step_deg=[float("nan")])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.map: max_points: the grid has 27000 points"):
        sc.map([1, 2, 3], step_deg=[12], max_points=100)
    with pytest.raises(ffsr.InputError, match="--shard: K must be less than N"):
        sc.map([1], shard_k=3, shard_n=3)


def test_override_equals_the_flag(tmp_path):
    scenario = ROBOTS / "paper_3dof.toml"
    expected = command_json(tmp_path, scenario, "--gain", "-0.02", "--global=false")
    # `global` is a Python keyword: passed through a dict
    got = ffsr.Scenario.load(str(scenario), gain=-0.02, **{"global": False}).run().to_dict()
    assert differences(got, expected) == []


def test_bad_scenario_input(tmp_path):
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: gian: not a scenario key$"):
        ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), gian=1.0)
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: duration: must be positive"):
        ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), duration=-1.0)
    bad = tmp_path / "bad.toml"
    bad.write_text("urdf = [\n")
    with pytest.raises(ffsr.InputError, match=f"scenario {bad}"):
        ffsr.Scenario.load(str(bad))
