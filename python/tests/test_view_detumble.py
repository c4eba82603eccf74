"""The 3-D view going on after the capture (ffsr.view with the post-capture runs of ffsr-optimize
detumble --run all): the target carried by the gripper checked against ffsr's own forward kinematics of
the series' configuration composed with the grasp's attachment, the page in headless Chromium without a
console error (as a file and inline), and the answers to bad input.

The inputs are the command's on the paper's 3-DOF scenario (its URDF gives no effort: the joints' torque
limit is a flag).
"""

from __future__ import annotations

import csv
import io
import json
import re
import subprocess
import sys

import numpy as np
import pytest

from view_browser import ROOT, ffsr_optimize, grey_statistics, open_page, run_job

try:
    from ffsr import view
except ImportError:  # the package not installed: the module from the source tree (it needs no extension)
    sys.path.insert(0, str(ROOT / "python"))
    from ffsr import view

SCENARIO = ROOT / "robots" / "paper_3dof.toml"
DETUMBLE_FLAGS = ("--joint-torque-limit", "50", "--detumble-dwell", "1")  # a short hold: every sample a frame


@pytest.fixture(scope="module")
def captured(tmp_path_factory):
    """The main job and the post-capture runs of its three captures: (result, series, detumble, its series)."""
    folder = tmp_path_factory.mktemp("detumble_3dof")
    result, series = run_job(folder, "--config", str(SCENARIO))
    post, post_series = folder / "detumble.json", folder / "detumble.csv"
    cmd = [ffsr_optimize(), "detumble", "--config", str(SCENARIO), "--run", "all", *DETUMBLE_FLAGS, "--quiet",
           "--json", str(post), "--csv", str(post_series)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return result, series, post, post_series


def quat_matrix(q):
    """The rotation matrix of the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


class Kinematics:
    """The target's pose from a post-capture sample by ffsr's forward kinematics: the gripper frame's pose
    at the sample's base pose and joint angles, composed with the grasp's attachment of its run."""

    def __init__(self, post_json):
        pytest.importorskip("ffsr._ffsr", reason="the compiled module (scripts/install-python.sh)")
        import ffsr
        self.ffsr = ffsr
        self.model = ffsr.Model.from_urdf(str(ROOT / "robots" / "paper_3dof.urdf"), end_effector="ee")
        self.data = ffsr.Data(self.model)
        self.attachment = {r["run"]: r["grasp"]["attachment"] for r in post_json["runs"]}

    def target(self, run, row):
        angles = sorted((k for k in row if re.fullmatch(r"theta_\d+", k)), key=lambda k: int(k[6:]))
        theta = [float(row[k]) for k in angles]
        q = [float(row[f"base_q{k}"]) for k in "wxyz"]
        base = self.ffsr.BasePose(position=[float(row[f"base_{k}"]) for k in "xyz"], orientation=q[1:] + q[:1])
        self.ffsr.forward_kinematics(self.model, self.data, base, theta)
        a = self.attachment[run]
        frame = self.ffsr.frame_pose(self.model, self.data, a["frame"])
        R_f, p_f = np.asarray(frame.R), np.asarray(frame.p)
        return p_f + R_f @ np.asarray(a["position"]), R_f @ quat_matrix(a["quaternion_wxyz"])


def rows_of(path, run):
    return [r for r in csv.DictReader(io.StringIO(path.read_text())) if r["run"] == run]


def test_the_target_rides_on_the_gripper_in_the_page(captured, tmp_path):
    """In the page's data, every post-capture frame's target pose equals the gripper frame's pose at the
    series' configuration composed with the grasp's attachment (forward kinematics here, not the
    command's target columns); in Chromium, the target drawn at three instants after the capture is
    that pose, the page has no console error and draws the path after the capture."""
    result, series, post, post_series = captured
    j, d = json.loads(result.read_text()), json.loads(post.read_text())
    kin = Kinematics(d)
    data = view.page_data(j, series, detumble=d, detumble_series=post_series, frames=60)
    T = j["scene"]["capture_time"]
    for run in data["runs"]:
        samples = rows_of(post_series, run["name"])
        by_time = {round(T + float(r["t"]), 6): r for r in samples}
        c = run["capture_index"]
        assert run["t"][c] == pytest.approx(T) and len(run["t"]) - c - 1 == 59  # 60 samples, the first is T
        post_run = d["runs"][[r["run"] for r in d["runs"]].index(run["name"])]
        # the series ends after the hold at rest (detumble-dwell)
        assert run["t"][-1] == pytest.approx(T + post_run["time_to_rest"] + post_run["parameters"]["dwell"])
        for k in range(c + 1, len(run["t"])):
            p, R = kin.target(run["name"], by_time[run["t"][k]])
            pose = run["target"][7 * k:7 * k + 7]
            assert pose[:3] == pytest.approx(list(p), abs=2e-5)
            assert np.abs(quat_matrix(pose[3:]) - R).max() < 1e-5
    # the target at the capture instant (the main job's, propagated) and just after it (held): no jump
    g = next(r for r in data["runs"] if r["name"] == "global")
    c = g["capture_index"]
    assert g["target"][7 * (c + 1):7 * (c + 1) + 3] == pytest.approx(g["target"][7 * c:7 * c + 3], abs=2e-3)

    html = view.capture(j, tmp_path / "after.html", series, detumble=d, detumble_series=post_series).path
    samples = rows_of(post_series, "global")
    full = view.page_data(j, series, detumble=d, detumble_series=post_series)
    times = next(r for r in full["runs"] if r["name"] == "global")["t"]
    for k in (1, len(samples) // 2, len(samples) - 1):  # frames of the page (all samples: fewer than 400)
        t = times[next(r for r in full["runs"] if r["name"] == "global")["capture_index"] + k]
        page = open_page(html, tmp_path / f"after{k}.png", fragment=f"#run=global&t={t!r}")
        assert page.console == [], page.console
        s = page.summary()
        assert s["ready"] is True and s["errors"] == [], s
        assert s["time"] == pytest.approx(t) and s["phase"] == "after the capture"
        assert s["capture_time"] == pytest.approx(T) and s["end_time"] > T
        assert s["post_capture"] == ["baseline", "optimized", "global"]
        assert s["roles"]["path-detumble"] == 1 and s["roles"]["target"] == 1
        p, R = kin.target("global", samples[k])
        assert s["target_pose"][:3] == pytest.approx(list(p), abs=2e-5)
        assert np.abs(quat_matrix(s["target_pose"][3:]) - R).max() < 1e-5
    variance, colours = grey_statistics(tmp_path / f"after{len(samples) - 1}.png", (330, 200, 1000, 700))
    assert variance > 30 and colours > 50, (variance, colours)


def test_the_page_opens_at_the_capture_and_inline(captured, tmp_path):
    """Without a time in its address the page opens at the capture instant (badge 'capture'); its
    inline form (a notebook's iframe) draws with no console error."""
    from test_view import NOTEBOOK, NOTEBOOK_BUDGET_MS

    result, series, post, post_series = captured
    j = json.loads(result.read_text())
    shown = view.capture(j, series=series, detumble=json.loads(post.read_text()), detumble_series=post_series,
                         frames=80)
    notebook = tmp_path / "notebook.html"
    notebook.write_text(NOTEBOOK.replace("@@FRAME@@", shown._repr_html_()), encoding="utf-8")
    page = open_page(notebook, tmp_path / "notebook.png", budget_ms=NOTEBOOK_BUDGET_MS)
    assert page.console == [], page.console
    s = page.summary()
    assert s["ready"] is True and s["errors"] == [], s
    assert s["time"] == pytest.approx(j["scene"]["capture_time"]) and s["phase"] == "capture"
    assert s["path_points"]["path-detumble"] >= 2


def test_the_command_line(captured, tmp_path):
    """python -m ffsr.view --detumble --detumble-csv writes the page; one of the two alone is refused."""
    result, series, post, post_series = captured
    out = tmp_path / "after.html"
    base = [sys.executable, "-m", "ffsr.view", str(result), "--csv", str(series), "-o", str(out)]
    env = {"PYTHONPATH": str(__import__("pathlib").Path(view.__file__).resolve().parents[1])}
    p = subprocess.run(base + ["--detumble", str(post), "--detumble-csv", str(post_series)], capture_output=True,
                       text=True, env=env, timeout=120)
    assert p.returncode == 0 and p.stderr == "", p.stderr
    text = out.read_text(encoding="utf-8")
    data = json.loads(re.search(r'id="ffsr-view-data">(.*?)</script>', text, re.S).group(1))
    assert all(r["capture_index"] < len(r["t"]) - 1 for r in data["runs"])
    out.unlink()
    p = subprocess.run(base + ["--detumble", str(post)], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "--detumble-csv" in p.stderr, p.stderr
    assert not out.exists()


def test_bad_post_capture_input(captured, tmp_path):
    result, series, post, post_series = captured
    j, d = json.loads(result.read_text()), json.loads(post.read_text())
    # a post-capture run from the scenario's configuration continues no capture
    single = tmp_path / "single.json"
    p = subprocess.run([ffsr_optimize(), "detumble", "--config", str(SCENARIO), *DETUMBLE_FLAGS, "--quiet", "--json",
                        str(single)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    with pytest.raises(view.ViewInputError, match="detumble: a post-capture run from the scenario's configuration"):
        view.page_data(j, series, detumble=json.loads(single.read_text()), detumble_series=post_series)
    # the series missing, or given alone
    with pytest.raises(view.ViewInputError, match="detumble series: missing"):
        view.page_data(j, series, detumble=d)
    with pytest.raises(view.ViewInputError, match="given without the post-capture result"):
        view.page_data(j, series, detumble_series=post_series)
    # the post-capture run of another capture: its start moved
    lines = post_series.read_text().splitlines()
    header = lines[0].split(",")
    fields = lines[1].split(",")
    fields[header.index("theta_1")] = str(float(fields[header.index("theta_1")]) + 0.01)
    moved = tmp_path / "moved.csv"
    moved.write_text("\n".join([lines[0], ",".join(fields)] + lines[2:]) + "\n")
    with pytest.raises(view.ViewInputError, match="the post-capture run of another capture"):
        view.page_data(j, series, detumble=d, detumble_series=moved)
    # a series written before the poses were added (no theta_k, base, target, body columns)
    old = tmp_path / "old.csv"
    keep = [i for i, h in enumerate(header) if not re.match(r"(theta_\d|base_|target_|body\d)", h)]
    old.write_text("\n".join(",".join(line.split(",")[i] for i in keep) for line in lines) + "\n")
    with pytest.raises(view.ViewInputError, match="column.s. missing"):
        view.page_data(j, series, detumble=d, detumble_series=old)
    # the result of two runs beside the series of three
    two = dict(d, runs=d["runs"][:2])
    with pytest.raises(view.ViewInputError, match=r"detumble series: its runs \(baseline, global, optimized\)"):
        view.page_data(j, series, detumble=two, detumble_series=post_series)


def test_the_python_job_result_continues_the_view(captured, tmp_path):
    """capture(..., detumble=Scenario.detumble(run="all")) takes the series from its series_csv(): the
    page's data equal those of the command's two files."""
    pytest.importorskip("ffsr._ffsr", reason="the compiled module (scripts/install-python.sh)")
    import ffsr

    result, series, post, post_series = captured
    urdf = ROOT / "robots" / "paper_3dof.urdf"
    scenario = tmp_path / "paper_3dof_detumble.toml"
    scenario.write_text(SCENARIO.read_text().replace('urdf = "paper_3dof.urdf"', f'urdf = "{urdf}"')
                        + "\njoint-torque-limit = 50\ndetumble-dwell = 1\n")  # the flags of DETUMBLE_FLAGS
    job = ffsr.Scenario.load(str(scenario)).detumble(run="all")
    j = json.loads(result.read_text())
    from_object = view.page_data(j, series, detumble=job, frames=100)
    from_files = view.page_data(j, series, detumble=str(post), detumble_series=post_series, frames=100)
    assert from_object == from_files
    assert view.capture(j, tmp_path / "job.html", series, detumble=job, frames=100).path.is_file()
