"""Objects that show themselves: repr() gives the figures a user looks for first, and the jobs' results
give the command's table as HTML (Jupyter's _repr_html_): a run result's rows are the rows
`ffsr-optimize` prints for the same scenario, cell by cell."""

import html.parser
import re
import subprocess

import numpy as np
import pytest

import ffsr
from conftest import REPO, ROBOTS
from test_jobs import command


class Cells(html.parser.HTMLParser):
    """The rows of an HTML table: lists of cell texts (header cells included)."""

    def __init__(self, text):
        super().__init__()
        self.rows, self._cell = [], None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell = ""

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self.rows[-1].append(self._cell)
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data


ROW = re.compile(r"^(Without optimization|With optimization|Global)\s+(\[.*?\]|failed \(below\))\s*(.*)$")
REDUCTION = re.compile(r"^(Reduction \((?:optimization|global)\))\s+(\S+)\s+(\S+)\s+(\S+)$")


def command_table(scenario):
    """The rows the command prints for a scenario: label, then its cells as printed."""
    out = subprocess.run([command(), "--config", str(scenario)], cwd=REPO, capture_output=True, text=True,
                         check=True, timeout=600).stdout
    rows = []
    for line in out.splitlines():
        if m := ROW.match(line):
            cells, _, skipped = m.group(3).partition("not applied:")  # the row's keys it does not take
            rows.append([m.group(1), m.group(2)] + cells.split() + ([skipped.strip()] if skipped else []))
        elif m := REDUCTION.match(line):
            rows.append([m.group(1), m.group(2), m.group(3), m.group(4)])
    return rows


@pytest.mark.parametrize("name", ["paper_3dof", "paper_7dof_position", "paper_7dof_detumble"])
def test_run_result_html_shows_the_commands_rows(name):
    scenario = ROBOTS / f"{name}.toml"
    expected = command_table(scenario)
    result = ffsr.Scenario.load(str(scenario)).run()
    rows = Cells(result._repr_html_()).rows
    header = ["", "Capture configuration (deg)", "M_ie (kg)", "F_max (kN)", "exact (kN)", "tracking (m)",
              "not applied"]
    if name == "paper_7dof_detumble":  # its Detumble keys add each run's post-capture figures
        header[-1:-1] = ["rest (s)", "torque (N m)", "joint", "force (N)", "moment (N m)", "attitude (deg)",
                         "wheels (N m s)"]
        assert all(len(r) == len(header) for r in rows)
        assert all(len(row) >= 13 for row in expected if row[0] in ("Without optimization", "Global"))
    assert rows[0] == header
    shown = [[c for c in r if c] for r in rows[1:]]  # the reductions leave the configuration cell empty
    assert len(expected) >= 4
    assert shown == expected
    text = repr(result)  # the same rows as text
    for row in expected:
        assert re.search(r"\s+".join(re.escape(c) for c in row), text), row


def test_model_data_target_base_pose_contact_law():
    model = ffsr.Model.from_urdf(str(ROBOTS / "paper_3dof.urdf"))
    ee = model.frame_names[model.end_effector]
    assert repr(model) == (f"Model(3 joints, 4 bodies, end effector '{ee}', mass {model.total_mass:.1f} kg, "
                           f"source '{model.source}')")
    assert repr(ffsr.Data(model)) == "Data(3 joints, 4 bodies)"
    t = repr(ffsr.Target())  # the paper's target
    for part in ("mass 200 kg", "inertia diag(100, 100, 100) kg m^2", "contact offset [-0.25, 0.15, 0] m",
                 "normal [1, 0, 0]", "attitude (x, y, z, w) [0, 0, 0, 1]"):
        assert part in t, part
    assert len(t.splitlines()) == 4
    assert repr(ffsr.BasePose(position=[1, 2, 3])) == \
        "BasePose(position [1, 2, 3] m, orientation (x, y, z, w) [0, 0, 0, 1])"
    law = ffsr.make_contact_law("hunt-crossley", ffsr.ContactParams(), 0.2)
    r = repr(law)
    assert r.startswith("ContactLaw('hunt-crossley', K 1e+09 N/m^1.5, c_r 0.9, approach velocity 0.2 m/s")
    assert f"xi {law.xi:.3f} %" in r and f"f {law.f:.6g}" in r


def test_results_of_the_algorithms_and_the_jobs():
    sc = ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), **{"global": False})
    run = sc.run()
    degrees = ", ".join(f"{np.degrees(x):.2f}" for x in run.plain.theta)
    assert repr(run.plain).startswith(f"CaptureResult(theta [{degrees}] deg, M_ie {run.plain.M_ie:.3f} kg")
    law = ffsr.make_contact_law("hunt-crossley", ffsr.ContactParams(), 0.2)
    peak = law.exact_peak(10.0)
    assert repr(peak).startswith(f"ForcePeak(force {peak.force:.6g} N")
    single = ffsr.simulate_single_body(law, 10.0)
    assert f"F_max {single.f_max / 1e3:.3f} kN" in repr(single)
    inspect = sc.inspect()
    cells = dict(Cells(inspect._repr_html_()).rows[1:])
    assert cells["M_ie (Eq. 14)"] == f"{inspect.M_ie:.3f} kg" and cells["contact joints"] == "free"
    assert f"M_ie (Eq. 14) {inspect.M_ie:.3f} kg" in repr(inspect)
    assert repr(inspect.base_disturbance).startswith(f"BaseDisturbance(M_ie {inspect.M_ie:.3f} kg")
    contact = sc.contact(model="all")
    rows = Cells(contact._repr_html_()).rows
    assert [r[0] for r in rows[1:]] == [w.model for w in contact.rows] == ffsr.contact_law_names()
    assert all(r[5] == f"{w.f_max_multibody / 1e3:.3f}" for r, w in zip(rows[1:], contact.rows))
    assert repr(contact).count("ContactRow(") == len(contact.rows)
    grid = sc.map(vary=[2, 3], range_deg=[0, 90], step_deg=[30])
    assert Cells(grid._repr_html_()).rows[0] == ["angles (deg)", "M_ie (kg)", "F_max (kN)"]
    i = int(np.argmin(grid.M_ie))
    assert f"M_ie {grid.M_ie[i]:.3f} kg" in repr(grid) and f"{grid.points} grid points" in repr(grid)


def test_closed_loop_robust_and_pareto_tables():
    sc = ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), **{"global": False})
    loop = sc.closed_loop()
    rows = Cells(loop._repr_html_()).rows
    assert rows[1][:3] == ["closed loop", "[" + ", ".join(f"{np.degrees(x):.2f}" for x in loop.theta) + "]",
                           f"{loop.M_ie:.3f}"]
    assert rows[2][2] == f"{loop.open_loop.M_ie:.3f}" and f"plan '{loop.plan}'" in repr(loop)
    uncertain = ffsr.Scenario.load(str(ROBOTS / "paper_7dof_position_uncertain.toml"), **{"global": False})
    robust = uncertain.robust(force_model="closed", samples=8)
    rows = Cells(robust._repr_html_()).rows
    assert [r[0] for r in rows[1:]] == [c.name for c in robust.configurations]
    assert all(r[-1] == f"{c.max / 1e3:.3f}" and r[3] == f"{c.p50 / 1e3:.3f}"
               for r, c in zip(rows[1:], robust.configurations))
    assert repr(robust).startswith(f"RobustResult(8 samples, seed {robust.seed},")


def test_pareto_table():
    result = ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml")).pareto(levels=4, starts=2)
    rows = Cells(result._repr_html_()).rows
    assert len(rows) == len(result.front) + 1
    assert [r[1] for r in rows[1:]] == [f"{p.M_ie:.3f}" for p in result.front]
    assert sum("(knee)" in r[0] for r in rows) == 1
    assert f"knee ParetoPoint(M_ie {result.knee.M_ie:.3f} kg" in repr(result)
