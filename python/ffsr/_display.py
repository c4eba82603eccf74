"""How the package's objects show themselves: a __repr__ with the figures a user looks for first, and
for the command's jobs a _repr_html_ with the command's table (Jupyter shows it under the cell). Set on
the classes of ffsr._ffsr when the package is imported."""

import html

from . import _ffsr


def _num(x, fmt=".6g"):
    return format(float(x), fmt)


def _vec(v, fmt=".6g"):
    return "[" + ", ".join(_num(x, fmt) for x in v) + "]"


def _deg(theta, decimals=2):
    """Radians as the command's degree list: [-2.48, 90.49, -86.17]."""
    return "[" + ", ".join(f"{x * 57.29577951308232:.{decimals}f}" for x in theta) + "]"


def _table(header, rows, caption=None):
    """An HTML table: header cells, then rows of cells (str), escaped."""
    cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f'<table class="ffsr">{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


# --- the model side --------------------------------------------------------------------------------

def _model(m):
    ee = m.frame_names[m.end_effector]
    return (f"Model({m.n} joints, {m.nb} bodies, end effector '{ee}', mass {m.total_mass:.1f} kg, "
            f"source '{m.source}')")


def _data(d):
    return f"Data({d.H.shape[0] - 6} joints, {len(d.rotations)} bodies)"


def _base_pose(b):
    return f"BasePose(position {_vec(b.position)} m, orientation (x, y, z, w) {_vec(b.orientation)})"


def _target(t):
    I = t.inertia
    diag = all(I[i, j] == 0 for i in range(3) for j in range(3) if i != j)
    inertia = ("diag(" + ", ".join(_num(I[i, i]) for i in range(3)) + ")") if diag else \
        "[" + "; ".join(_vec(row) for row in I) + "]"
    return (f"Target(mass {_num(t.mass)} kg, inertia {inertia} kg m^2,\n"
            f"       position {_vec(t.position)} m, attitude (x, y, z, w) {_vec(t.attitude)},\n"
            f"       velocity {_vec(t.velocity)} m/s, spin {_vec(t.angular_velocity)} rad/s,\n"
            f"       contact offset {_vec(t.contact_offset)} m, normal {_vec(t.normal)})")


def _contact_law(law):
    p = law.params
    return (f"ContactLaw('{law.name}', K {_num(p.K)} N/m^{_num(p.alpha)}, c_r {_num(p.c_r)}, "
            f"approach velocity {_num(law.approach_velocity)} m/s,\n"
            f"           f {_num(law.f)}, lambda {_num(law.lambda_)}, zeta {_num(law.zeta)}, "
            f"xi {law.xi:.3f} %)")


# --- the dynamics' and contact runs' results --------------------------------------------------------

def _force_peak(p):
    return (f"ForcePeak(force {_num(p.force)} N, deformation {_num(p.deformation)} m, "
            f"rate {_num(p.deformation_rate)} m/s)")


def _single_body(r):
    return (f"SingleBodyResult(F_max {r.f_max / 1e3:.3f} kN at t = {_num(r.t_at_f_max)} s, "
            f"delta_max {_num(r.delta_max)} m, duration {_num(r.contact_duration)} s, "
            f"restitution {r.restitution:.4f}, {r.num_steps} steps)")


def _multibody(r):
    return (f"MultibodyContactResult('{r.model}', M_ie {r.integrated_effective_mass:.3f} kg, "
            f"approach velocity {_num(r.approach_velocity)} m/s,\n"
            f"                       F_max {r.f_max / 1e3:.3f} kN at t = {_num(r.t_at_f_max)} s, "
            f"duration {_num(r.contact_duration)} s, restitution {r.restitution:.4f}, {r.steps} steps)")


def _base_disturbance(d):
    return (f"BaseDisturbance(M_ie {d.M_ie:.3f} kg, impulse {_num(d.impulse)} N s, "
            f"linear {_vec(d.linear)} m/s, angular rate {d.angular_rate * 57.29577951308232:.3e} deg/s)")


# --- the main job: the command's rows ------------------------------------------------------------------

RUN_HEADER = ["", "Capture configuration (deg)", "M_ie (kg)", "F_max (kN)", "exact (kN)", "tracking (m)",
              "not applied"]
# with the post-capture phase (a Detumble key given): after "tracking (m)"
POST_CAPTURE_HEADER = ["rest (s)", "torque (N m)", "joint", "force (N)", "moment (N m)", "attitude (deg)",
                       "wheels (N m s)"]


def run_header(r):
    """The header of the command's table for a run: with the post-capture columns when it has them."""
    return RUN_HEADER[:-1] + POST_CAPTURE_HEADER + RUN_HEADER[-1:] if r.post_capture else RUN_HEADER


def _post_capture_cells(post, result, key):
    """A run's post-capture cells as the command prints them: time to rest, peak joint torque and its
    joint, peak gripper force and moment, base attitude excursion (deg), peak wheel momentum (- without)."""
    if not post:
        return []
    x, d = post[key], result[key]["post_capture"]
    wheels = f"{x.peak_wheel_momentum:.3f}" if d["parameters"]["base_actuator"] == "reaction-wheels" else "-"
    return [f"{x.time_to_rest:.2f}", f"{x.peak_joint_torque:.2f}", d["peak_joint"],
            f"{x.peak_gripper_force:.2f}", f"{x.peak_gripper_moment:.2f}",
            f"{x.base_attitude_excursion * 57.29577951308232:.3f}", wheels]


def run_rows(r):
    """The rows of the command's table for a run: configuration, M_ie, F_max (closed form, exact),
    tracking error, the post-capture figures when the run has them, then the reductions against the
    plain run, formatted as the command prints them."""
    rows = []
    result = r.to_dict()
    post = r.post_capture
    blank = [""] * (len(POST_CAPTURE_HEADER) if post else 0)  # a failed or reduction row's post-capture cells
    for label, key, run, failure in (("Without optimization", "baseline", r.plain, r.plain_failure),
                                     ("With optimization", "optimized", r.optimized, r.optimized_failure),
                                     ("Global", "global", r.global_run, "")):
        if run is None and not failure:
            continue  # no global run
        # the keys the scenario gives that this row's run does not take, as the command's row ends
        skipped = ", ".join(result.get(key, {}).get("keys_not_applied", []))
        if run is None:
            rows.append([label, "failed (below)", "", "", "", ""] + blank + [skipped])
            continue
        rows.append([label, _deg(run.theta), f"{run.M_ie:.3f}", f"{run.f_max_closed_form / 1e3:.3f}",
                     f"{run.f_max_exact / 1e3:.3f}", f"{run.tracking_error:.2e}"]
                    + _post_capture_cells(post, result, key) + [skipped])

    def reduction(a, b):
        return f"{100.0 * (a - b) / a:.2f}%"

    for label, run in (("Reduction (optimization)", r.optimized), ("Reduction (global)", r.global_run)):
        if r.plain is not None and run is not None:
            p = r.plain
            rows.append([label, "", reduction(p.M_ie, run.M_ie),
                         reduction(p.f_max_closed_form, run.f_max_closed_form),
                         reduction(p.f_max_exact, run.f_max_exact), ""] + blank + [""])
    return rows


def _failures(r):
    return [f"failed: {f}" for f in (r.plain_failure, r.optimized_failure) if f]


def _run_result(r):
    rows, header = run_rows(r), run_header(r)
    widths = [max(len(row[i]) for row in rows + [header]) for i in range(len(header))]
    def line(row):  # labels and configurations left-aligned, numbers right-aligned, as the command
        return "  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(row, widths)))

    lines = [line(row).rstrip() for row in [header] + rows]
    return "RunResult(\n" + "\n".join("  " + x for x in lines + _failures(r)) + ")"


def _run_result_html(r):
    notes = "".join(f"<p>{html.escape(f)}</p>" for f in _failures(r))
    return _table(run_header(r), run_rows(r)) + notes


def _capture_result(c):
    return (f"CaptureResult(theta {_deg(c.theta)} deg, M_ie {c.M_ie:.3f} kg, "
            f"F_max {c.f_max_closed_form / 1e3:.3f} kN (exact {c.f_max_exact / 1e3:.3f} kN),\n"
            f"              tracking {c.tracking_error:.2e} m, "
            f"approach velocity {_num(c.approach_velocity)} m/s, {c.steps} steps)")


# --- the other jobs --------------------------------------------------------------------------------

def _inspect_rows(r):
    d = r.base_disturbance
    jump = f"{d.angular_rate * 57.29577951308232:.3e} deg/s" if d is not None else "none (not approaching)"
    return [["M_ie (Eq. 14)", f"{r.M_ie:.3f} kg"], ["m_e (Eq. 4)", f"{r.m_e:.3f} kg"],
            ["contact joints", r.contact_joints], ["contact normal u", _vec(r.direction, ".4f")],
            ["base angular rate jump", jump]]


def _inspect(r):
    return "InspectResult(" + ", ".join(f"{k} {v}" for k, v in _inspect_rows(r)) + ")"


CONTACT_HEADER = ["model", "M_ie (kg)", "delta_dot^- (m/s)", "F_max (kN)", "exact (kN)", "multibody (kN)",
                  "accuracy (%)", "xi (%)"]


def _contact_row_cells(w):
    return [w.model, f"{w.M_ie:.3f}", f"{w.approach_velocity:.4f}", f"{w.f_max_closed_form / 1e3:.3f}",
            f"{w.f_max_exact / 1e3:.3f}", f"{w.f_max_multibody / 1e3:.3f}", f"{w.model_accuracy:.2f}",
            f"{w.relative_error_xi:.2f}"]


def _contact_row(w):
    return "ContactRow(" + ", ".join(f"{h} {c}" for h, c in zip(CONTACT_HEADER, _contact_row_cells(w))) + ")"


def _contact_result(r):
    return "ContactResult(\n" + "\n".join("  " + _contact_row(w) for w in r.rows) + ")"


def _closed_loop_rows(r):
    o = r.open_loop
    return [["closed loop", _deg(r.theta), f"{r.M_ie:.3f}", f"{r.f_max_closed_form / 1e3:.3f}",
             f"{r.capture_error:.2e}"],
            ["open-loop plan", _deg(o.theta), f"{o.M_ie:.3f}", f"{o.f_max_closed_form / 1e3:.3f}",
             f"{o.tracking_error:.2e}"]]


CLOSED_LOOP_HEADER = ["", "Capture configuration (deg)", "M_ie (kg)", "F_max (kN)", "capture error (m)"]


def _closed_loop(r):
    c, o = _closed_loop_rows(r)
    return (f"ClosedLoopResult(plan '{r.plan}', {r.ticks} ticks, max torque {_num(r.max_torque)} N m,\n"
            f"  closed loop {c[1]} deg, M_ie {c[2]} kg, F_max {c[3]} kN, capture error {c[4]} m,\n"
            f"  open-loop   {o[1]} deg, M_ie {o[2]} kg, F_max {o[3]} kN)")


ROBUST_HEADER = ["configuration", "nominal (kN)", "mean (kN)", "p50 (kN)", "p95 (kN)", "p99 (kN)", "max (kN)"]


def _robust_cells(c):
    return [c.name] + [f"{x / 1e3:.3f}" for x in (c.nominal_f_max, c.mean, c.p50, c.p95, c.p99, c.max)]


def _robust_configuration(c):
    cells = zip(ROBUST_HEADER, _robust_cells(c))
    return "RobustConfiguration(" + ", ".join(f"{h} {x}" for h, x in cells) + ")"


def _robust(r):
    return (f"RobustResult({r.samples} samples, seed {r.seed},\n" +
            "\n".join("  " + _robust_configuration(c) for c in r.configurations) + ")")


PARETO_HEADER = ["point", "M_ie (kg)", "base rate jump (deg/s)", "configuration (deg)"]


def _pareto_rows(r):
    knee = r.knee
    rows = []
    for i, p in enumerate(r.front):
        label = f"{i}" + (" (knee)" if p.M_ie == knee.M_ie and p.base_rate == knee.base_rate else "")
        rows.append([label, f"{p.M_ie:.3f}", f"{p.base_rate * 57.29577951308232:.3e}", _deg(p.theta)])
    return rows


def _pareto_point(p):
    return (f"ParetoPoint(M_ie {p.M_ie:.3f} kg, base rate jump {p.base_rate * 57.29577951308232:.3e} deg/s, "
            f"theta {_deg(p.theta)} deg)")


def _pareto(r):
    return (f"ParetoResult({len(r.front)} points, hypervolume {r.hypervolume_normalized:.4f},\n"
            f"  knee {_pareto_point(r.knee)})")


def _map_summary(r):
    if len(r.M_ie) == 0:
        return f"{r.points} grid points, shard [{r.first}, {r.end}): no point"
    i, j = int(r.M_ie.argmin()), int(r.M_ie.argmax())
    return (f"{r.points} grid points, shard [{r.first}, {r.end}); "
            f"M_ie {r.M_ie[i]:.3f} kg at {_vec(r.angles_deg[i], '.2f')} deg to {r.M_ie[j]:.3f} kg at "
            f"{_vec(r.angles_deg[j], '.2f')} deg")


def _map(r):
    return f"MapResult({_map_summary(r)})"


def _map_html(r):
    rows = [[_vec(a, ".2f"), f"{m:.3f}", f"{f / 1e3:.3f}"] for a, m, f in zip(r.angles_deg, r.M_ie, r.f_max)]
    shown = rows if len(rows) <= 20 else rows[:10] + [["...", "...", "..."]] + rows[-10:]
    return _table(["angles (deg)", "M_ie (kg)", "F_max (kN)"], shown, _map_summary(r))


REPRS = {
    "Model": _model, "Data": _data, "BasePose": _base_pose, "Target": _target, "ContactLaw": _contact_law,
    "ForcePeak": _force_peak, "SingleBodyResult": _single_body, "MultibodyContactResult": _multibody,
    "BaseDisturbance": _base_disturbance, "CaptureResult": _capture_result, "RunResult": _run_result,
    "InspectResult": _inspect, "ContactRow": _contact_row, "ContactResult": _contact_result,
    "ClosedLoopResult": _closed_loop, "RobustConfiguration": _robust_configuration, "RobustResult": _robust,
    "ParetoPoint": _pareto_point, "ParetoResult": _pareto, "MapResult": _map,
}

HTML = {
    "RunResult": _run_result_html,
    "InspectResult": lambda r: _table(["", "value"], _inspect_rows(r)),
    "ContactResult": lambda r: _table(CONTACT_HEADER, [_contact_row_cells(w) for w in r.rows]),
    "ClosedLoopResult": lambda r: _table(CLOSED_LOOP_HEADER, _closed_loop_rows(r),
                                         f"plan '{r.plan}', {r.ticks} ticks, "
                                         f"max torque {_num(r.max_torque)} N m"),
    "RobustResult": lambda r: _table(ROBUST_HEADER, [_robust_cells(c) for c in r.configurations],
                                     f"{r.samples} samples, seed {r.seed}"),
    "ParetoResult": lambda r: _table(PARETO_HEADER, _pareto_rows(r),
                                     f"hypervolume (normalized) {r.hypervolume_normalized:.4f}"),
    "MapResult": _map_html,
}


def install():
    for name, fn in REPRS.items():
        setattr(getattr(_ffsr, name), "__repr__", fn)
    for name, fn in HTML.items():
        setattr(getattr(_ffsr, name), "_repr_html_", fn)
