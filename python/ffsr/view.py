"""The 3-D view of a capture: one self-contained HTML file that animates a run of the main job.

The page shows the bus, the links (their collision shapes where the scenario has shapes, else
segments between the joint origins with a marker at each joint), the target's shape tumbling (the
scenario's ``target-shape``, else a schematic cube of half side max(0.1 m, largest component of
r_tp), as in the command's figures), the end-effector's path (the approach in the run's colour, a
reconfiguration in orange), the contact point and normal on the target, the capture point, and a
time slider with play and pause. Every run of the result (plain, paper's method, global) can be
chosen; the page opens on the global run at the capture instant.

Forward kinematics is not redone here: the command's series holds the pose of every body at every
sample (``body<i>_*`` columns), the target's pose (``target_*``) and the phase, and its JSON result
holds the bodies' tree and shapes (``scene``). three.js (npm ``three``, MIT; the package's build
fetches it at the version pinned in python/three.sha256 into ``view_assets/three``) is written into
the page: the file opens offline, from disk, with no server and nothing fetched.

From the command's outputs::

    ffsr-optimize --config robots/paper_3dof.toml --json result.json --csv series.csv
    python -m ffsr.view result.json --csv series.csv -o capture.html

After the capture the page can go on with the post-capture runs (``ffsr-optimize detumble --run all``,
its ``--json`` and ``--csv``: ``--detumble`` and ``--detumble-csv``; from Python ``detumble=``): the
target carried by the gripper, the joints and the base following that series.

From Python: ``ffsr.view.capture(result, "capture.html", series)`` where ``result`` is the job's
result (an object with ``to_dict()``, or the dict of the command's ``--json``) and ``series`` the
time series (a path to the ``--csv`` file, its text, or a mapping of its columns; by default
``result.series``: an in-process run, ``ffsr.view.capture(ffsr.Scenario.load(path).run())``, carries
its own, ``RunResult.series``); it returns a :class:`CaptureView`, which Jupyter shows inline (the page in an
iframe), and writes the file when given a path. Bad input raises :class:`ViewInputError` naming
the file (or argument); nothing is written then. This module needs the Python standard library only.
"""

from __future__ import annotations

import argparse
import csv
import html
import io
import json
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

__all__ = ["ViewInputError", "CaptureView", "capture", "page", "page_data", "main"]

ASSETS = Path(__file__).resolve().parent / "view_assets"
THREE_FILES = ("three.module.min.js", "OrbitControls.js")  # written into view_assets/three by the build
RUNS = ("baseline", "optimized", "global")  # the result's keys and the series' run labels
RUN_LABELS = {"baseline": "Without optimization", "optimized": "With optimization", "global": "Global"}
POSE = ("x", "y", "z", "qw", "qx", "qy", "qz")
DEFAULT_FRAMES = 400


class ViewInputError(ValueError):
    """A result or a series the view cannot show; the message names the file or argument."""


# --- reading ------------------------------------------------------------------------------------------


def _read_text(path: Union[str, os.PathLike], what: str) -> str:
    try:
        with open(path, "r", encoding="utf-8") as f:
            return f.read()
    except FileNotFoundError:
        raise ViewInputError(f"{os.fspath(path)}: {what} not found") from None
    except IsADirectoryError:
        raise ViewInputError(f"{os.fspath(path)}: {what} is a directory") from None
    except UnicodeDecodeError:
        raise ViewInputError(f"{os.fspath(path)}: {what} is not text (UTF-8)") from None
    except OSError as e:
        raise ViewInputError(f"{os.fspath(path)}: cannot read the {what}: {e.strerror}") from None


def load_result(path: Union[str, os.PathLike]) -> Dict[str, Any]:
    """The main job's ``--json`` file as a dict (ViewInputError naming the file otherwise)."""
    text = _read_text(path, "result")
    try:
        return json.loads(text)
    except json.JSONDecodeError as e:
        raise ViewInputError(f"{os.fspath(path)}: not JSON ({e.msg} at line {e.lineno})") from None


def _result_dict(result: Any) -> Dict[str, Any]:
    if hasattr(result, "to_dict"):
        result = result.to_dict()
    if not isinstance(result, Mapping):
        raise ViewInputError(f"result: expected the main job's result (to_dict()) or its JSON dict, got "
                             f"{type(result).__name__}")
    return dict(result)


def _series_table(series: Any, name: str) -> Tuple[List[str], List[List[Any]]]:
    """The series as a header and rows: from a CSV file, CSV text or a mapping of columns."""
    if isinstance(series, (str, os.PathLike)) and not (isinstance(series, str) and "\n" in series):
        text = _read_text(series, "series")
    elif isinstance(series, str):
        text = series
    elif isinstance(series, bytes):
        text = series.decode("utf-8")
    elif hasattr(series, "keys") and hasattr(series, "__getitem__"):  # a mapping of columns (dict, DataFrame)
        header = [str(k) for k in series.keys()]
        columns = [list(series[k]) for k in series.keys()]
        lengths = {len(c) for c in columns}
        if len(lengths) > 1:
            raise ViewInputError(f"{name}: the columns have different lengths ({sorted(lengths)})")
        return header, [list(r) for r in zip(*columns)]
    else:
        raise ViewInputError(f"{name}: expected the CSV of the main job's --csv (a path or its text) or a "
                             f"mapping of its columns, got {type(series).__name__}")
    if not text.strip():
        raise ViewInputError(f"{name}: empty, not a time series of ffsr-optimize --csv")
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], rows[1:]


# --- checking the result and the series together ----------------------------------------------------


def _runs_of(result: Dict[str, Any], name: str) -> List[str]:
    """The runs the result holds (without an error), checking that it is the main job's result."""
    held = [r for r in RUNS if isinstance(result.get(r), Mapping)]
    if not held or "scenario" not in result:
        keys = ", ".join(sorted(result)[:6]) or "none"
        raise ViewInputError(f"{name}: not the --json of the main job of ffsr-optimize (no baseline, optimized "
                             f"or global run; its keys: {keys})")
    if "scene" not in result:
        raise ViewInputError(f"{name}: no 'scene' key: written by an ffsr-optimize older than the 3-D view "
                             f"(version {result.get('version', '?')}); run it again")
    runs = [r for r in held if "error" not in result[r]]
    if not runs:
        raise ViewInputError(f"{name}: every run of the result failed; nothing to show")
    return runs


def _number(text: Any, where: str) -> float:
    try:
        x = float(text)
    except (TypeError, ValueError):
        raise ViewInputError(f"{where}: '{text}' is not a number") from None
    if not math.isfinite(x):
        raise ViewInputError(f"{where}: {text} is not finite")
    return x


def _close(a: float, b: float, rtol: float = 1e-9, atol: float = 1e-7) -> bool:
    return abs(a - b) <= atol + rtol * max(abs(a), abs(b))


class _Series:
    """The columns of one run of the series (numbers), and its phases."""

    def __init__(self) -> None:
        self.rows: List[List[float]] = []
        self.phases: List[str] = []


def _check_series(result: Dict[str, Any], runs: List[str], header: List[str], rows: List[List[Any]],
                  result_name: str, name: str) -> Tuple[Dict[str, int], Dict[str, _Series]]:
    scenario = result["scenario"]
    scene = result["scene"]
    joints = [f"{j}_deg" for j in scenario.get("joint_names", [])]
    nb = len(scene.get("bodies", []))
    expected = (["run", "t"] + joints + [f"base_{k}" for k in POSE] + ["ee_x", "ee_y", "ee_z", "M_ie", "F_max_estimate"]
                + [f"target_{k}" for k in POSE] + [f"body{b}_{k}" for b in range(1, nb) for k in POSE] + ["phase"])
    col = {h: i for i, h in enumerate(header)}
    missing = [h for h in expected if h not in col]
    if "run" not in col or "phase" not in col or "t" not in col:
        raise ViewInputError(f"{name}: not a time series of ffsr-optimize --csv (no run, t or phase column)")
    csv_joints = [h for h in header if h.endswith("_deg")]
    if csv_joints != joints:
        raise ViewInputError(f"{name}: its joints ({', '.join(csv_joints)}) are not those of {result_name} "
                             f"({', '.join(joints)}): the series of another robot")
    if missing:
        shown = ", ".join(missing[:4]) + (", ..." if len(missing) > 4 else "")
        raise ViewInputError(f"{name}: {len(missing)} column(s) missing ({shown}): not the series of "
                             f"{result_name}'s run, or written by an older ffsr-optimize")
    numeric = [i for i, h in enumerate(header) if h not in ("run", "phase")]
    series: Dict[str, _Series] = {}
    for line, row in enumerate(rows, start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise ViewInputError(f"{name}: line {line} has {len(row)} fields, the header {len(header)}")
        label, phase = row[col["run"]], row[col["phase"]]
        if label not in RUNS:
            raise ViewInputError(f"{name}: line {line}: unknown run '{label}' (baseline, optimized, global)")
        if phase not in ("reconfiguration", "approach"):
            raise ViewInputError(f"{name}: line {line}: unknown phase '{phase}' (reconfiguration, approach)")
        s = series.setdefault(label, _Series())
        values = [0.0] * len(header)
        for i in numeric:
            values[i] = _number(row[i], f"{name}: line {line}, column {header[i]}")
        if s.rows and values[col["t"]] < s.rows[-1][col["t"]]:
            raise ViewInputError(f"{name}: line {line}: time goes back in the {label} run")
        if s.phases and s.phases[-1] == "approach" and phase == "reconfiguration":
            raise ViewInputError(f"{name}: line {line}: a reconfiguration after the approach in the {label} run")
        s.rows.append(values)
        s.phases.append(phase)
    if sorted(series) != sorted(runs):
        raise ViewInputError(f"{name}: its runs ({', '.join(sorted(series)) or 'none'}) are not those of "
                             f"{result_name} ({', '.join(sorted(runs))}): the series of another run")
    capture_time = _number(scene.get("capture_time"), f"{result_name}: scene.capture_time")
    for r in runs:
        last = series[r].rows[-1]
        q = result[r].get("capture_configuration_deg", [])
        got = [last[col[j]] for j in joints]
        base = [last[col[f"base_{k}"]] for k in "xyz"]
        if (len(q) != len(got) or not all(_close(a, b) for a, b in zip(got, q))
                or not all(_close(a, b, atol=1e-9) for a, b in zip(base, result[r].get("base_position", [])))
                or not _close(last[col["t"]], capture_time)):
            shown = ", ".join(f"{x:.4f}" for x in got)
            want = ", ".join(f"{x:.4f}" for x in q)
            raise ViewInputError(f"{name}: its {r} run ends at [{shown}] deg, t = {last[col['t']]:g} s; "
                                 f"{result_name}'s capture configuration is [{want}] deg at t = "
                                 f"{capture_time:g} s: the series of another run")
    return col, series


# --- after the capture: the post-capture runs of ffsr-optimize detumble --run --------------------------


def _detumble_dict(detumble: Any, name: str) -> Dict[str, Any]:
    if isinstance(detumble, (str, os.PathLike)):
        d = load_result(detumble)
    else:
        d = detumble.to_dict() if hasattr(detumble, "to_dict") else detumble
    if not isinstance(d, Mapping):
        raise ViewInputError(f"{name}: expected the result of ffsr-optimize detumble --run (to_dict(), its JSON "
                             f"dict or its file), got {type(d).__name__}")
    if "runs" not in d:
        if "grasp" in d and "at_rest" in d:
            raise ViewInputError(f"{name}: a post-capture run from the scenario's configuration does not continue "
                                 f"a capture of the main job: run ffsr-optimize detumble --run all (or plain, "
                                 f"optimized, global)")
        keys = ", ".join(sorted(d)[:6]) or "none"
        raise ViewInputError(f"{name}: not the --json of ffsr-optimize detumble --run (its keys: {keys})")
    for r in d["runs"]:
        if not isinstance(r, Mapping) or "run" not in r or "attachment" not in r.get("grasp", {}):
            raise ViewInputError(f"{name}: a run without 'run' or 'grasp.attachment': written by an "
                                 f"ffsr-optimize older than the post-capture view; run it again")
    return dict(d)


def _detumble_table(header: List[str], rows: List[List[Any]], joints: int, bodies: int,
                    name: str) -> Tuple[Dict[str, int], Dict[str, List[List[float]]]]:
    """The post-capture series' columns by name and its numbers by run (checked)."""
    expected = (["run", "t", "joint_rate", "gripper_force"] + [f"theta_{k}" for k in range(1, joints + 1)]
                + [f"{p}_{k}" for p in ["base", "target"] + [f"body{b}" for b in range(1, bodies)] for k in POSE])
    col = {h: i for i, h in enumerate(header)}
    missing = [h for h in expected if h not in col]
    if missing:
        shown = ", ".join(missing[:4]) + (", ..." if len(missing) > 4 else "")
        raise ViewInputError(f"{name}: {len(missing)} column(s) missing ({shown}): not the --csv of ffsr-optimize "
                             f"detumble --run of this robot, or written by an older ffsr-optimize")
    if f"theta_{joints + 1}" in col:
        raise ViewInputError(f"{name}: more joints than the main job's {joints}: the series of another robot")
    table: Dict[str, List[List[float]]] = {}
    for line, row in enumerate(rows, start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise ViewInputError(f"{name}: line {line} has {len(row)} fields, the header {len(header)}")
        values = [0.0] * len(header)
        for h in expected[1:]:
            values[col[h]] = _number(row[col[h]], f"{name}: line {line}, column {h}")
        rows_of = table.setdefault(row[col["run"]], [])
        if rows_of and values[col["t"]] < rows_of[-1][col["t"]]:
            raise ViewInputError(f"{name}: line {line}: time goes back in the {row[col['run']]} run")
        rows_of.append(values)
    return col, table


def _detumble_runs(res: Dict[str, Any], runs: List[str], table: Dict[str, _Series], col: Dict[str, int],
                   detumble: Any, series: Any, result_name: str, name: str,
                   series_name: str) -> Dict[str, Dict[str, Any]]:
    """Each post-capture run by the main job's run it continues, checked to start where that run ends."""
    d = _detumble_dict(detumble, name)
    if series is None:
        series = getattr(detumble, "series_csv", None)
        series = series() if callable(series) else series
    if series is None:
        raise ViewInputError(f"{series_name}: missing: the view needs the post-capture series "
                             f"(ffsr-optimize detumble --run all --csv)")
    joints = res["scenario"].get("joint_names", [])
    header, rows = _series_table(series, series_name)
    dcol, dtable = _detumble_table(header, rows, len(joints), len(res["scene"]["bodies"]), series_name)
    if sorted(dtable) != sorted(r["run"] for r in d["runs"]):
        raise ViewInputError(f"{series_name}: its runs ({', '.join(sorted(dtable)) or 'none'}) are not those of "
                             f"{name} ({', '.join(sorted(r['run'] for r in d['runs']))})")
    out: Dict[str, Dict[str, Any]] = {}
    for r in d["runs"]:
        label = r["run"]
        if label not in runs:
            raise ViewInputError(f"{name}: its {label} run is not a run of {result_name} ({', '.join(runs)})")
        last, first = table[label].rows[-1], dtable[label][0]
        capture = [last[col[f"{j}_deg"]] for j in joints]
        start = [math.degrees(first[dcol[f"theta_{k}"]]) for k in range(1, len(joints) + 1)]
        stated = list(r.get("joints_deg", []))
        same = (len(stated) == len(capture) and all(_close(a, b, atol=1e-6) for a, b in zip(capture, stated))
                and all(_close(a, b, atol=1e-6) for a, b in zip(capture, start))
                and all(_close(last[col[f"base_{k}"]], first[dcol[f"base_{k}"]], atol=1e-6) for k in "xyz")
                and first[dcol["t"]] == 0)
        if not same:
            shown = ", ".join(f"{x:.4f}" for x in start)
            want = ", ".join(f"{x:.4f}" for x in capture)
            raise ViewInputError(f"{series_name}: its {label} run starts at [{shown}] deg; {result_name}'s {label} "
                                 f"run captures at [{want}] deg: the post-capture run of another capture")
        out[label] = {"rows": dtable[label], "col": dcol, "time_to_rest": r.get("time_to_rest")}
    return out


def _rotate(q: Sequence[float], v: Sequence[float]) -> List[float]:
    """v turned by the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    t = [2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])]
    return [v[0] + w * t[0] + y * t[2] - z * t[1], v[1] + w * t[1] + z * t[0] - x * t[2],
            v[2] + w * t[2] + x * t[1] - y * t[0]]


def _append_post_capture(d: Dict[str, Any], post: Dict[str, Any], scene: Dict[str, Any], frames: int) -> None:
    """Appends the post-capture frames to a run's frames: times from the capture instant on, the poses of
    the series, the end-effector from its body's pose, the gripper's force and the largest joint rate."""
    rows, col = post["rows"], post["col"]
    T = d["t"][-1]
    nb = len(scene["bodies"])
    ee_body, ee_point = scene["end_effector_body"], scene["end_effector_point"]
    n = len(d["t"])
    d["grip"] = [0.0] * n
    d["jrate"] = [0.0] * n
    for k in _frames(len(rows), [], frames)[1:]:  # the first sample is the capture instant itself
        row = rows[k]
        d["t"].append(round(T + row[col["t"]], 6))
        for prefix, out in [("base", d["base"])] + [(f"body{b}", d["bodies"]) for b in range(1, nb)] + [
                ("target", d["target"])]:
            out.extend(round(row[col[f"{prefix}_{c}"]], 5) for c in POSE[:3])
            out.extend(round(row[col[f"{prefix}_{c}"]], 6) for c in POSE[3:])
        prefix = "base" if ee_body == 0 else f"body{ee_body}"
        p = [row[col[f"{prefix}_{c}"]] for c in "xyz"]
        q = [row[col[f"{prefix}_q{c}"]] for c in "wxyz"]
        d["ee"].extend(round(a + b, 5) for a, b in zip(p, _rotate(q, ee_point)))
        d["mie"].append(d["mie"][d["capture_index"]])
        d["fmax"].append(d["fmax"][d["capture_index"]])
        d["grip"].append(round(row[col["gripper_force"]], 4))
        d["jrate"].append(round(math.degrees(row[col["joint_rate"]]), 5))
    d["time_to_rest"] = post["time_to_rest"]


# --- the page's data ------------------------------------------------------------------------------------


def _frames(n: int, keep: Sequence[int], frames: int) -> List[int]:
    """About `frames` sample indices evenly spread over n, with 0, n - 1 and `keep`."""
    if n <= frames:
        return list(range(n))
    idx = {round(i * (n - 1) / (frames - 1)) for i in range(frames)}
    idx.update(k for k in keep if 0 <= k < n)
    return sorted(idx)


def _schematic_target(result: Dict[str, Any]) -> Dict[str, Any]:
    """The figures' schematic target: a cube of half side max(0.1 m, largest |r_tp| component)."""
    h = max([0.1] + [abs(x) for x in result["scene"]["contact_offset"]])
    return {"kind": "box", "size": [2 * h] * 3, "position": [0, 0, 0], "quaternion_wxyz": [1, 0, 0, 0],
            "schematic": True}


def page_data(result: Any, series: Any = None, *, run: Optional[str] = None, frames: int = DEFAULT_FRAMES,
              result_name: str = "result", series_name: str = "series", detumble: Any = None,
              detumble_series: Any = None, detumble_name: str = "detumble",
              detumble_series_name: str = "detumble series") -> Dict[str, Any]:
    """The data the page animates (checked): every run's frames, the bodies and shapes, the capture, and
    with `detumble` (the post-capture runs, ffsr-optimize detumble --run) the frames after it."""
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 2:
        raise ViewInputError(f"frames: must be an integer >= 2, got {frames!r}")
    res = _result_dict(result)
    runs = _runs_of(res, result_name)
    if run is not None and run not in runs:
        raise ViewInputError(f"run: '{run}' is not a run of {result_name} ({', '.join(runs)})")
    if series is None:
        raise ViewInputError(f"{series_name}: missing: the view needs the time series (ffsr-optimize --csv)")
    header, rows = _series_table(series, series_name)
    col, table = _check_series(res, runs, header, rows, result_name, series_name)
    scene = res["scene"]
    nb = len(scene["bodies"])

    def cols(prefix: str) -> List[int]:
        return [col[f"{prefix}_{k}"] for k in POSE]

    base_cols, target_cols = cols("base"), cols("target")
    body_cols = [cols(f"body{b}") for b in range(1, nb)]
    ee_cols = [col["ee_x"], col["ee_y"], col["ee_z"]]

    def pose(row: List[float], c: List[int], out: List[float]) -> None:
        out.extend(round(row[i], 5) for i in c[:3])
        out.extend(round(row[i], 6) for i in c[3:])

    out_runs = []
    for r in runs:
        s = table[r]
        n = len(s.rows)
        split = next((k for k, p in enumerate(s.phases) if p == "approach"), n)
        idx = _frames(n, [split - 1, split], frames)
        d: Dict[str, Any] = {"name": r, "label": RUN_LABELS[r], "t": [], "base": [], "bodies": [], "target": [],
                             "ee": [], "mie": [], "fmax": []}
        for k in idx:
            row = s.rows[k]
            d["t"].append(round(row[col["t"]], 6))
            pose(row, base_cols, d["base"])
            for c in body_cols:
                pose(row, c, d["bodies"])
            pose(row, target_cols, d["target"])
            d["ee"].extend(round(row[i], 5) for i in ee_cols)
            d["mie"].append(round(row[col["M_ie"]], 6))
            d["fmax"].append(round(row[col["F_max_estimate"]], 3))
        d["approach_begin"] = idx.index(split) if split < n else 0
        for key in ("integrated_effective_mass", "f_max_closed_form", "f_max_exact"):
            d[key] = res[r].get(key)
        d["reconfigured"] = bool(res[r].get("reconfigured", False))
        d["capture_index"] = len(d["t"]) - 1
        out_runs.append(d)
    if detumble is not None:
        post = _detumble_runs(res, runs, table, col, detumble, detumble_series, result_name, detumble_name,
                              detumble_series_name)
        for d in out_runs:
            if d["name"] in post:
                _append_post_capture(d, post[d["name"]], scene, frames)
    elif detumble_series is not None:
        raise ViewInputError(f"{detumble_series_name}: given without the post-capture result (detumble)")
    target_shape = scene.get("target_shape") or _schematic_target(res)
    source = str(res["scenario"].get("source", ""))
    return {
        "source": source,
        "version": str(res.get("version", "")),
        "joint_names": list(res["scenario"].get("joint_names", [])),
        "bodies": scene["bodies"],
        "end_effector_body": scene["end_effector_body"],
        "end_effector_point": scene["end_effector_point"],
        "target_shape": target_shape,
        "contact_offset": scene["contact_offset"],
        "contact_normal_target_frame": scene["contact_normal_target_frame"],
        "capture_time": scene["capture_time"],
        "capture_point": res.get("capture_point"),
        "capture_normal": scene["capture_normal"],
        "runs": out_runs,
        "initial_run": run or runs[-1],
    }


# --- the page -------------------------------------------------------------------------------------------


def _asset(name: str) -> str:
    path = ASSETS / name
    if name.startswith("three/") and not path.is_file():
        raise RuntimeError(f"ffsr.view: {path} is missing: three.js is not in this copy of the package "
                           f"(its build fetches it from the npm registry; install the package: "
                           f"scripts/install-python.sh or pip install ./python)")
    return path.read_text(encoding="utf-8")


def _raw_script(text: str, what: str) -> str:
    """Text that goes inside a <script> element as it is: it must not close or comment the element."""
    lowered = text.lower()
    if "</script" in lowered or "<!--" in lowered:
        raise RuntimeError(f"ffsr.view: {what} holds '</script' or '<!--' and cannot be embedded")
    return text


def page(data: Dict[str, Any]) -> str:
    """The HTML page of page_data()'s data: three.js, the viewer and the data in one file."""
    name = os.path.splitext(os.path.basename(data["source"]))[0] or "capture"
    joints = len(data["joint_names"])
    T = data["capture_time"]
    subtitle = (f"{joints} joints · capture at T = {T:g} s · ffsr-optimize {data['version']}"
                if data["version"] else f"{joints} joints · capture at T = {T:g} s")
    blob = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")
    out = _asset("page.html")
    for key, value in (
        ("@@FFSR_VERSION@@", html.escape(data["version"])),
        ("@@FFSR_TITLE@@", html.escape(f"Capture: {name}")),
        ("@@FFSR_HEADING@@", html.escape(f"Capture: {name}")),
        ("@@FFSR_SUBTITLE@@", html.escape(subtitle)),
        ("@@FFSR_DATA@@", blob),
        ("@@FFSR_THREE@@", _raw_script(_asset(f"three/{THREE_FILES[0]}"), THREE_FILES[0])),
        ("@@FFSR_ORBIT@@", _raw_script(_asset(f"three/{THREE_FILES[1]}"), THREE_FILES[1])),
        ("@@FFSR_VIEWER@@", _raw_script(_asset("viewer.js"), "viewer.js")),
    ):
        out = out.replace(key, value, 1)
    return out


def _write_atomically(path: Union[str, os.PathLike], text: str) -> Path:
    """Writes `text` to a temporary file beside `path`, then renames it into place (all or nothing)."""
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    try:
        mode = target.stat().st_mode & 0o7777 if target.exists() else None
    except OSError:
        mode = None
    if mode is None:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=".ffsr-view-", suffix=".tmp", dir=folder)
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(tmp, mode)
        os.replace(tmp, target)
        tmp = None
    except OSError as e:
        raise ViewInputError(f"{os.fspath(path)}: cannot write the page: {e.strerror}") from None
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
    return target


class CaptureView:
    """The 3-D view of a capture: the page (``html``, one self-contained HTML text) and the file it was
    written to (``path``, None when not written). In Jupyter it shows itself inline: ``_repr_html_`` is
    an iframe whose ``srcdoc`` is the whole page (three.js included), so it needs no server, no file
    and no network, and a notebook's saved output still holds it."""

    def __init__(self, html_text: str, path: Optional[Path] = None, height: int = 600) -> None:
        self.html = html_text
        self.path = path
        self.height = height

    def save(self, path: Union[str, os.PathLike]) -> Path:
        """Writes the page to `path` (all or nothing) and returns it; ``self.path`` becomes it."""
        self.path = _write_atomically(path, self.html)
        return self.path

    def _repr_html_(self) -> str:
        return (f'<iframe srcdoc="{html.escape(self.html, quote=True)}" title="ffsr.view" '
                f'style="width: 100%; height: {self.height}px; border: 1px solid #d5d9de; '
                f'border-radius: 4px"></iframe>')

    def __fspath__(self) -> str:
        if self.path is None:
            raise TypeError("CaptureView: the page was not written to a file "
                            "(capture(..., path) or save(path))")
        return os.fspath(self.path)

    def __repr__(self) -> str:
        where = f"'{self.path}'" if self.path is not None else "not written"
        return f"CaptureView({where}, {len(self.html.encode('utf-8')) / 1e6:.2f} MB)"


def capture(result: Any, path: Optional[Union[str, os.PathLike]] = None, series: Any = None, *,
            run: Optional[str] = None, frames: int = DEFAULT_FRAMES, height: int = 600, detumble: Any = None,
            detumble_series: Any = None) -> CaptureView:
    """The 3-D view of a capture (a CaptureView, shown inline in Jupyter), written to `path` if given.

    path: the HTML file to write (one self-contained file); None: nothing is written.
    result: the main job's result (an object with ``to_dict()``, or the dict of ``ffsr-optimize --json``).
    series: its time series: a path to the ``--csv`` file, the CSV text, or a mapping of its columns;
        None: ``result.series`` (called when it is a method; ``Scenario.run()``'s RunResult has it).
    run: the run the page opens on (baseline, optimized, global; default: the last the result holds).
    frames: at most this many samples per run go into the page (evenly spread; the first, the last
        and the phase boundary always).
    height: the inline frame's height in Jupyter, in CSS pixels.
    detumble: the post-capture runs that continue the captures (``Scenario.detumble(run="all")``, or the
        dict or the file of ``ffsr-optimize detumble --run all --json``): after the capture instant the page goes on
        with the target carried by the gripper, the joints and the base following that series. Each of its
        runs must start at its main job's run's capture configuration and base position.
    detumble_series: its series: a path to ``detumble --csv``, the text, or a mapping of its columns;
        None: ``detumble.series_csv()``.
    Raises ViewInputError (a ValueError) naming the argument on bad input; nothing is written then.
    """
    if isinstance(height, bool) or not isinstance(height, int) or height < 100:
        raise ViewInputError(f"height: must be an integer >= 100 (pixels), got {height!r}")
    if series is None:
        series = getattr(result, "series", None)
        if callable(series):
            series = series()
    data = page_data(result, series, run=run, frames=frames, detumble=detumble, detumble_series=detumble_series)
    view = CaptureView(page(data), height=height)
    if path is not None:
        view.save(path)
    return view


# --- python -m ffsr.view ----------------------------------------------------------------------------------


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, exit 2 (as ffsr-optimize)
        self.exit(2, f"ffsr.view: error: {message}\n")


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = _Parser(prog="python -m ffsr.view",
                description="Write the 3-D view of a capture (one HTML file) from ffsr-optimize's --json and --csv.")
    p.add_argument("result", help="the main job's result (ffsr-optimize --json FILE)")
    p.add_argument("--csv", required=True, metavar="SERIES", help="its time series (ffsr-optimize --csv FILE)")
    p.add_argument("-o", "--output", required=True, metavar="HTML", help="the page to write ('-': standard output)")
    p.add_argument("--run", choices=RUNS, help="the run the page opens on (default: global, else the last held)")
    p.add_argument("--frames", type=int, default=DEFAULT_FRAMES,
                   help=f"at most this many samples per run in the page (default {DEFAULT_FRAMES})")
    p.add_argument("--detumble", metavar="RESULT",
                   help="the post-capture runs that continue the captures (ffsr-optimize detumble --run all --json)")
    p.add_argument("--detumble-csv", metavar="SERIES", help="their series (ffsr-optimize detumble --run all --csv)")
    a = p.parse_args(argv)
    try:
        if a.frames < 2:
            raise ViewInputError(f"--frames: must be >= 2, got {a.frames}")
        if (a.detumble is None) != (a.detumble_csv is None):
            raise ViewInputError("--detumble and --detumble-csv: give both (the post-capture result and its series)")
        result = load_result(a.result)
        if not isinstance(result, dict):
            raise ViewInputError(f"{a.result}: not the --json of the main job of ffsr-optimize (not a JSON object)")
        post = load_result(a.detumble) if a.detumble else None
        try:
            data = page_data(result, a.csv, run=a.run, frames=a.frames, result_name=a.result, series_name=a.csv,
                             detumble=post, detumble_series=a.detumble_csv, detumble_name=a.detumble or "detumble",
                             detumble_series_name=a.detumble_csv or "detumble series")
        except ViewInputError as e:
            msg = str(e)
            if msg.startswith("run: "):
                msg = "--run: " + msg[len("run: "):]
            raise ViewInputError(msg) from None
        text = page(data)
        if a.output == "-":
            sys.stdout.write(text)
            sys.stdout.flush()
        else:
            _write_atomically(a.output, text)
    except ViewInputError as e:
        print(f"ffsr.view: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
