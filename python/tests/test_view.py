"""The 3-D view of a capture (ffsr.view): the page in headless Chromium (a picture that is not blank,
the scene's objects, no console error) and the command's answers to bad input.

The inputs are written by the command (ffsr-optimize --json --csv) on the shipped scenarios: the
paper's 3-DOF robot (no shapes: links as segments, joint markers, the schematic target) and its
variant with shapes and a clearance (the links' capsules, the target's box, the bus).
"""

from __future__ import annotations

import csv
import html as htmllib
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from view_browser import ROOT, ffsr_optimize, grey_statistics, open_page, run_job

try:
    from ffsr import view
except ImportError:  # the package not installed: the module from the source tree (it needs no extension)
    sys.path.insert(0, str(ROOT / "python"))
    from ffsr import view

ROBOTS = ROOT / "robots"


@pytest.fixture(scope="module")
def paper_3dof(tmp_path_factory):
    """The main job on the paper's 3-DOF scenario: result.json, series.csv."""
    return run_job(tmp_path_factory.mktemp("paper_3dof"), "--config", str(ROBOTS / "paper_3dof.toml"))


@pytest.fixture(scope="module")
def shapes_3dof(tmp_path_factory):
    """The 3-DOF scenario with shapes (capsules, the target's box, the URDF's <collision> box as the bus), without
    the global row."""
    return run_job(tmp_path_factory.mktemp("shapes_3dof"), "--config", str(ROBOTS / "paper_3dof_clearance.toml"),
                   "--global", "false")


def cli(*args: str, cwd: Path = None) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(Path(view.__file__).resolve().parents[1]), env.get("PYTHONPATH", "")])
    return subprocess.run([sys.executable, "-m", "ffsr.view", *args], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=120)


def the_one_error_line(p: subprocess.CompletedProcess, names: str) -> str:
    assert p.returncode == 2, p.stderr
    assert p.stdout == ""
    lines = p.stderr.splitlines()
    assert len(lines) == 1, p.stderr
    assert lines[0].startswith("ffsr.view: error: "), lines[0]
    assert names in lines[0], lines[0]
    return lines[0]


# --- the page in the browser ------------------------------------------------------------------------------


def test_page_of_the_paper_3dof_run(paper_3dof, tmp_path):
    result, series = paper_3dof
    html = tmp_path / "capture.html"
    p = cli(str(result), "--csv", str(series), "-o", str(html))
    assert p.returncode == 0, p.stderr
    assert p.stdout == "" and p.stderr == ""
    text = html.read_text(encoding="utf-8")
    for remote in ("http://", "https://", "//cdn", "<script src", "<link"):  # nothing fetched
        assert remote not in text.replace("http://www.w3.org", ""), remote

    page = open_page(html, tmp_path / "capture.png")
    assert page.console == [], page.console
    s = page.summary()
    assert s["ready"] is True, s
    assert s["errors"] == []
    assert s["webgl"].startswith("WebGL")
    j = json.loads(result.read_text())
    bodies = j["scene"]["bodies"]
    # no shapes: a segment per joint-to-joint link and one to the end-effector, a marker per joint
    links = sum(1 for b in bodies[1:] if b["parent"] > 0) + 1
    roles = s["roles"]
    assert roles["bus"] == 1
    assert roles["link"] == links == 3
    assert roles["joint"] == len(bodies) - 1 == 3
    assert roles["target"] == 1 and s["target_kind"] == "box" and s["target_schematic"] is True
    assert roles["contact-normal"] == 1 and roles["contact-point"] == 1 and roles["capture-point"] == 1
    assert roles["path-approach"] == 1 and "path-reconfiguration" not in roles  # the paper's runs: approach only
    assert s["runs"] == ["baseline", "optimized", "global"] and s["run"] == "global"
    assert s["time"] == pytest.approx(j["scene"]["capture_time"])  # the page opens at the capture instant
    assert s["frames"] <= view.DEFAULT_FRAMES + 2

    variance, colours = grey_statistics(page.png)
    assert variance > 100, variance  # a blank or one-colour page is near 0
    assert colours > 200, colours
    # the 3-D canvas itself (left of the legend, right of the run panel, above the bar) is not blank
    variance, colours = grey_statistics(page.png, (330, 200, 1000, 700))
    assert variance > 30 and colours > 50, (variance, colours)


def test_page_with_shapes_at_a_chosen_time(shapes_3dof, tmp_path):
    result, series = shapes_3dof
    html = view.capture(json.loads(result.read_text()), tmp_path / "shapes.html", series, run="optimized")
    page = open_page(html.path, tmp_path / "shapes.png", fragment="#t=60")
    assert page.console == [], page.console
    s = page.summary()
    assert s["ready"] is True and s["errors"] == []
    j = json.loads(result.read_text())
    bodies = j["scene"]["bodies"]
    shapes = sum(len(b["shapes"]) for b in bodies[1:])
    assert shapes >= 3 and all(s_["kind"] == "capsule" for b in bodies[1:] for s_ in b["shapes"])
    assert s["shapes"] is True
    assert s["roles"]["link"] == shapes
    assert s["roles"]["bus"] == len(bodies[0]["shapes"]) == 1
    assert "joint" not in s["roles"]
    assert s["target_kind"] == "box" and s["target_schematic"] is False
    assert s["runs"] == ["baseline", "optimized"] and s["run"] == "optimized"
    assert s["time"] == pytest.approx(60.0)
    variance, colours = grey_statistics(page.png, (330, 200, 1000, 700))
    assert variance > 30 and colours > 50, (variance, colours)


# The host page of the inline view, as a notebook shows a cell's HTML output: the view's iframe, and a
# script that copies the summary the page inside the frame writes (same origin: srcdoc) into its own.
# the notebook's copy of the frame's summary polls every 50 ms of virtual time: 1200 polls before the
# budget ends, room for the frame's three.js to load on a machine busy with a build
NOTEBOOK_BUDGET_MS = 60000
NOTEBOOK = """<!doctype html><html><head><meta charset="utf-8"><title>notebook</title></head>
<body style="margin: 0; padding: 20px 40px"><div class="output">@@FRAME@@</div>
<pre id="ffsr-view-summary" hidden></pre>
<script>
const copy = () => {
  const doc = document.querySelector('iframe').contentDocument;
  const inner = doc && doc.getElementById('ffsr-view-summary');
  const outer = document.getElementById('ffsr-view-summary');
  if (inner && inner.textContent) outer.textContent = inner.textContent;
  else setTimeout(copy, 50);
};
copy();
</script></body></html>
"""


def test_inline_view_in_a_notebook(paper_3dof, tmp_path):
    """capture() without a path writes nothing and returns the view; its _repr_html_ (a cell's HTML
    output in Jupyter) is an iframe holding the whole page, the same text as the file written with a
    path; in Chromium the page inside the frame builds its scene with no console error and no fetch."""
    result, series = paper_3dof
    j = json.loads(result.read_text())
    shown = view.capture(j, series=series, frames=80, height=520)
    assert shown.path is None and list(tmp_path.iterdir()) == []
    with pytest.raises(TypeError, match="not written"):
        os.fspath(shown)
    assert "not written" in repr(shown)
    written = view.capture(j, tmp_path / "capture.html", series, frames=80)
    assert written.path == tmp_path / "capture.html" and os.fspath(written) == str(tmp_path / "capture.html")
    assert written.path.read_text(encoding="utf-8") == written.html == shown.html
    frame = shown._repr_html_()
    m = re.fullmatch(r'<iframe srcdoc="([^"]*)"([^>]*)></iframe>', frame, re.S)
    assert m, frame[:200]
    assert htmllib.unescape(m.group(1)) == shown.html
    assert "height: 520px" in m.group(2)
    with pytest.raises(view.ViewInputError, match="height"):
        view.capture(j, series=series, height=10)

    notebook = tmp_path / "notebook.html"
    notebook.write_text(NOTEBOOK.replace("@@FRAME@@", frame), encoding="utf-8")
    page = open_page(notebook, tmp_path / "notebook.png", budget_ms=NOTEBOOK_BUDGET_MS)
    assert page.console == [], page.console
    s = page.summary()
    assert s["ready"] is True and s["errors"] == [], s
    assert s["runs"] == ["baseline", "optimized", "global"] and s["run"] == "global"
    assert s["roles"]["bus"] == 1 and s["roles"]["link"] == 3 and s["roles"]["target"] == 1
    # the frame (40 px from the left, 20 px from the top, 520 px high) is drawn, the page below it is blank
    variance, colours = grey_statistics(page.png, (400, 150, 1000, 470))
    assert variance > 30 and colours > 50, (variance, colours)
    variance, _ = grey_statistics(page.png, (40, 600, 1240, 780))
    assert variance < 1, variance


def test_three_js_is_the_pinned_release_and_not_in_git():
    """The package holds three.js at the version python/three.sha256 pins (its build fetched it; the
    module's REVISION constant is the minor version); the repository holds none of its files."""
    pinned = (ROOT / "python" / "three.sha256").read_text().split()[1]
    version = re.fullmatch(r"three-(\d+)\.(\d+)\.(\d+)\.tgz", pinned)
    assert version, pinned
    module = (view.ASSETS / "three" / view.THREE_FILES[0]).read_text(encoding="utf-8")
    assert module.startswith("/**\n * @license\n * Copyright 2010-") and "Three.js Authors" in module[:200]
    assert f'const t="{version.group(2)}"' in module[:300]
    assert "OrbitControls" in (view.ASSETS / "three" / view.THREE_FILES[1]).read_text(encoding="utf-8")
    listed = subprocess.run(["git", "ls-files", "python/ffsr"], cwd=ROOT, capture_output=True, text=True)
    if listed.returncode != 0:
        pytest.skip("not a git checkout")
    assert [f for f in listed.stdout.split() if "three" in f.lower()] == []


# --- the series the command writes for the view: identities, not values pasted back ---------------------


def _rotate(q, v):
    """v turned by the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    t = [2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])]
    return [v[0] + w * t[0] + y * t[2] - z * t[1], v[1] + w * t[1] + z * t[0] - x * t[2],
            v[2] + w * t[2] + x * t[1] - y * t[0]]


def _pose(row, prefix):
    return ([float(row[f"{prefix}_{k}"]) for k in "xyz"], [float(row[f"{prefix}_q{k}"]) for k in "wxyz"])


@pytest.mark.parametrize("job", ["paper_3dof", "shapes_3dof"])
def test_series_poses_are_rigid_and_meet_the_capture(job, request):
    """Every quaternion is unit; each joint origin keeps its offset in its parent's frame (rigid
    links, against the URDF's offsets for the paper's robot: a = 0.6, b = 1.4, c = 1.6 m); the
    end-effector's body pose carries the end-effector point onto the planner's own end-effector
    column; at the last sample the target's pose puts the contact point on the result's capture point
    and turns u_n into the result's normal at T."""
    result, series = request.getfixturevalue(job)
    j = json.loads(result.read_text())
    scene = j["scene"]
    bodies = scene["bodies"]
    rows = list(csv.DictReader(io.StringIO(series.read_text())))
    assert {r["run"] for r in rows} == {r for r in ("baseline", "optimized", "global") if r in j}
    offsets = {1: [0.6, 0, 0], 2: [1.4, 0, 0], 3: [1.6, 0, 0]}  # robots/paper_3dof.urdf
    ee_body, ee_point = scene["end_effector_body"], scene["end_effector_point"]
    for row in rows[::37]:
        poses = [_pose(row, "base")] + [_pose(row, f"body{b}") for b in range(1, len(bodies))]
        for p, q in poses + [_pose(row, "target")]:
            assert sum(x * x for x in q) == pytest.approx(1.0, abs=1e-9)
        for b in range(1, len(bodies)):
            (p, _), (pp, qp) = poses[b], poses[bodies[b]["parent"]]
            conj = [qp[0], -qp[1], -qp[2], -qp[3]]
            local = _rotate(conj, [p[k] - pp[k] for k in range(3)])
            assert local == pytest.approx(offsets[b], abs=1e-9)
        p, q = poses[ee_body]
        ee = [a + b for a, b in zip(p, _rotate(q, ee_point))]
        assert ee == pytest.approx([float(row[f"ee_{k}"]) for k in "xyz"], abs=1e-9)
    for run in {r["run"] for r in rows}:
        last = [r for r in rows if r["run"] == run][-1]
        assert float(last["t"]) == pytest.approx(scene["capture_time"], abs=1e-9)
        p, q = _pose(last, "target")
        contact = [a + b for a, b in zip(p, _rotate(q, scene["contact_offset"]))]
        assert contact == pytest.approx(j["capture_point"], abs=1e-9)
        assert _rotate(q, scene["contact_normal_target_frame"]) == pytest.approx(scene["capture_normal"], abs=1e-9)
        assert last["phase"] == "approach"


# --- the page's data -------------------------------------------------------------------------------------


def test_data_follow_the_series(paper_3dof):
    """The frames are samples of the series: first, last, evenly spread; the poses as written."""
    result, series = paper_3dof
    rows = list(csv.DictReader(io.StringIO(series.read_text())))
    d = view.page_data(json.loads(result.read_text()), series, frames=50)
    g = next(r for r in d["runs"] if r["name"] == "global")
    samples = [r for r in rows if r["run"] == "global"]
    assert len(g["t"]) == 50
    assert g["t"][0] == float(samples[0]["t"]) and g["t"][-1] == float(samples[-1]["t"])
    nb = len(d["bodies"])
    assert len(g["bodies"]) == 7 * (nb - 1) * 50 and len(g["base"]) == len(g["target"]) == 7 * 50
    last = samples[-1]
    assert g["bodies"][-7:-4] == pytest.approx([float(last[f"body{nb - 1}_{k}"]) for k in "xyz"], abs=1e-5)
    assert g["target"][-4:] == pytest.approx([float(last[f"target_q{k}"]) for k in "wxyz"], abs=1e-6)
    assert g["approach_begin"] == 0


def test_capture_from_a_result_object_with_its_series(paper_3dof, tmp_path):
    """capture() takes an object with to_dict() and a series attribute (the Python job's result)."""
    result, series = paper_3dof

    class Result:
        def to_dict(self):
            return json.loads(result.read_text())

        def series(self):
            return series.read_text()

    out = view.capture(Result(), tmp_path / "object.html")
    assert out.path == tmp_path / "object.html"
    assert out.path.read_text(encoding="utf-8").startswith("<!doctype html>")
    columns = {}
    for row in csv.DictReader(io.StringIO(series.read_text())):
        for k, v in row.items():
            columns.setdefault(k, []).append(v)
    view.capture(json.loads(result.read_text()), tmp_path / "columns.html", columns, frames=20)
    assert (tmp_path / "columns.html").stat().st_size > 600_000  # three.js is in the file


def test_page_of_an_in_process_run(paper_3dof, tmp_path):
    """ffsr.view.capture(Scenario.run()): the run's series comes with its result (RunResult.series), no
    file of the command; the page draws the three runs as the one made from the command's files."""
    ffsr = pytest.importorskip("ffsr")
    if not hasattr(ffsr, "Scenario"):
        pytest.skip("the extension ffsr._ffsr is not built")
    result = ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml")).run()
    html = tmp_path / "in_process.html"
    assert view.capture(result, html).path == html
    page = open_page(html, tmp_path / "in_process.png")
    assert page.console == [], page.console
    s = page.summary()
    assert s["ready"] is True and s["errors"] == [], s
    assert s["runs"] == ["baseline", "optimized", "global"] and s["run"] == "global"
    assert s["time"] == pytest.approx(result.to_dict()["scene"]["capture_time"])
    variance, colours = grey_statistics(page.png, (330, 200, 1000, 700))
    assert variance > 30 and colours > 50, (variance, colours)
    # the frames are the command's: the same samples of the same series
    command_result, command_series = paper_3dof
    mine = view.page_data(result, result.series, frames=50)
    theirs = view.page_data(json.loads(command_result.read_text()), command_series, frames=50)
    assert [r["name"] for r in mine["runs"]] == [r["name"] for r in theirs["runs"]]
    for a, b in zip(mine["runs"], theirs["runs"]):
        for key in ("t", "base", "bodies", "target", "ee"):
            assert a[key] == b[key], (a["name"], key)


# --- bad input: one line naming the file, exit 2, nothing written --------------------------------------


def test_a_missing_file(paper_3dof, tmp_path):
    result, series = paper_3dof
    out = tmp_path / "out.html"
    the_one_error_line(cli(str(tmp_path / "nope.json"), "--csv", str(series), "-o", str(out)), "nope.json")
    the_one_error_line(cli(str(result), "--csv", str(tmp_path / "nope.csv"), "-o", str(out)), "nope.csv")
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_a_json_of_another_command(paper_3dof, tmp_path):
    _, series = paper_3dof
    inspect = tmp_path / "inspect.json"
    p = subprocess.run([ffsr_optimize(), "inspect", "--urdf", str(ROBOTS / "paper_3dof.urdf"), "--joints-deg",
                        "0,90,-90", "--json"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    inspect.write_text(p.stdout)
    out = tmp_path / "out.html"
    line = the_one_error_line(cli(str(inspect), "--csv", str(series), "-o", str(out)), str(inspect))
    assert "not the --json of the main job" in line
    not_json = tmp_path / "series-as-result.json"
    not_json.write_text(series.read_text())
    the_one_error_line(cli(str(not_json), "--csv", str(series), "-o", str(out)), str(not_json))
    assert not out.exists()


def test_a_csv_of_another_run(paper_3dof, tmp_path):
    result, series = paper_3dof
    # the same robot and runs, another gain: the optimized run ends elsewhere
    other_result, other_series = run_job(tmp_path, "--config", str(ROBOTS / "paper_3dof.toml"), "--gain", "-0.02")
    out = tmp_path / "out.html"
    line = the_one_error_line(cli(str(result), "--csv", str(other_series), "-o", str(out)), str(other_series))
    assert "the series of another run" in line
    # another robot
    robot7 = tmp_path / "7dof"
    robot7.mkdir()
    _, series7 = run_job(robot7, "--config", str(ROBOTS / "paper_7dof_position.toml"), "--global", "false")
    line = the_one_error_line(cli(str(result), "--csv", str(series7), "-o", str(out)), str(series7))
    assert "another robot" in line
    # a CSV of another command (closed-loop's, map's): not a series of the main job
    other = tmp_path / "map.csv"
    other.write_text("theta1_deg,theta2_deg,M_ie\n0,0,1.5\n")
    the_one_error_line(cli(str(result), "--csv", str(other), "-o", str(out)), str(other))
    # a damaged series: a value that is not a number
    text = series.read_text().splitlines()
    fields = text[5].split(",")
    fields[3] = "nan"
    text[5] = ",".join(fields)
    damaged = tmp_path / "damaged.csv"
    damaged.write_text("\n".join(text) + "\n")
    line = the_one_error_line(cli(str(result), "--csv", str(damaged), "-o", str(out)), str(damaged))
    assert "line 6" in line
    assert not out.exists()


def test_an_earlier_page_survives_a_failing_run(paper_3dof, tmp_path):
    result, series = paper_3dof
    out = tmp_path / "capture.html"
    out.write_text("earlier page")
    the_one_error_line(cli(str(result), "--csv", str(tmp_path / "missing.csv"), "-o", str(out)), "missing.csv")
    assert out.read_text() == "earlier page"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["capture.html"]  # no temporary file left
    the_one_error_line(cli(str(result), "--csv", str(series), "-o", str(tmp_path / "no" / "such" / "dir.html")),
                       "dir.html")
    the_one_error_line(cli(str(result), "--csv", str(series), "-o", str(out), "--run", "elsewhere"), "--run")
    the_one_error_line(cli(str(result), "--csv", str(series), "-o", str(out), "--frames", "1"), "--frames")
    assert out.read_text() == "earlier page"


def test_the_python_call_on_bad_input(paper_3dof, tmp_path):
    result, series = paper_3dof
    j = json.loads(result.read_text())
    with pytest.raises(view.ViewInputError, match="series: missing"):
        view.capture(j, tmp_path / "a.html")
    with pytest.raises(view.ViewInputError, match="run: 'nothing'"):
        view.capture(j, tmp_path / "a.html", series, run="nothing")
    with pytest.raises(view.ViewInputError, match="result: not the --json of the main job"):
        view.capture({"H": [[1.0]]}, tmp_path / "a.html", series)
    assert list(tmp_path.iterdir()) == []
