"""The capture controller from Python (ffsr.CaptureController): driven by a classical RK4 written here in
numpy with the exact state, it lands where the planner's run of Scenario.run() lands; one tick's outputs
satisfy the identities of the rate law, checked with the package's own functions (zero momentum with
ffsr.momentum, the task rows of J_f with ffsr.generalized_jacobian, p_e with ffsr.frame_pose); and the
bad inputs: a wrong dtype, shape or layout of an array is an InputError naming it and nothing is
written, a bad value is the controller's fault status with zero rates."""

import numpy as np
import pytest

import ffsr
from conftest import ROBOTS


def quaternion_rate(q, w):
    """q_dot = 1/2 [0, w] (x) q, q as (x, y, z, w), w the inertial angular velocity."""
    x, y, z, s = q
    wx, wy, wz = w
    return 0.5 * np.array([wx * s + wy * z - wz * y,
                           wy * s + wz * x - wx * z,
                           wz * s + wx * y - wy * x,
                           -(wx * x + wy * y + wz * z)])


def drive(ctrl, position, quaternion, theta, steps):
    """Classical RK4 of (p_0, q_0, theta) over [0, T] in `steps` steps, the rates from ctrl.step; the
    quaternion renormalized after each step (the planner's integration of the capture run)."""
    n = ctrl.joints
    theta_dot, xb = np.zeros(n), np.zeros(6)
    statuses = set()

    def f(t, p, q, th):
        statuses.add(ctrl.step(t, p, q, th, theta_dot, xb))
        return xb[:3].copy(), quaternion_rate(q, xb[3:]), theta_dot.copy()

    p, q, th = (np.array(position, dtype=float), np.array(quaternion, dtype=float), np.array(theta, dtype=float))
    h = ctrl.duration / steps
    for k in range(steps):
        t = k * h
        k1 = f(t, p, q, th)
        k2 = f(t + h / 2, p + h / 2 * k1[0], q + h / 2 * k1[1], th + h / 2 * k1[2])
        k3 = f(t + h / 2, p + h / 2 * k2[0], q + h / 2 * k2[1], th + h / 2 * k2[2])
        k4 = f(t + h, p + h * k3[0], q + h * k3[1], th + h * k3[2])
        p = p + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        q = q + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        th = th + h / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
        q = q / np.linalg.norm(q)
    return p, q, th, statuses


@pytest.fixture(scope="module")
def paper_7dof():
    return ffsr.Scenario.load(str(ROBOTS / "paper_7dof_position.toml"), **{"global": False})


@pytest.mark.parametrize("name", ["paper_3dof", "paper_7dof_position", "paper_7dof_pose"])
def test_driven_controller_lands_where_the_planner_lands(name):
    sc = ffsr.Scenario.load(str(ROBOTS / f"{name}.toml"), **{"global": False})
    run = sc.run()
    planned = run.optimized
    assert planned is not None
    ctrl = ffsr.CaptureController(sc)
    assert ctrl.joints == sc.model.n and not ctrl.servo
    base = sc.base
    p, q, th, statuses = drive(ctrl, base.position, base.orientation, sc.theta, planned.steps)
    assert "fault" not in statuses
    # the same rate law and the same integration: equal to rounding (radians, metres)
    assert np.max(np.abs(th - planned.theta)) < 1e-12
    assert np.max(np.abs(p - planned.base.position)) < 1e-12
    assert np.max(np.abs(q - planned.base.orientation)) < 1e-12
    # and the paper's method lowered M_ie below the plain run's (Table 4's claim, by the plan itself)
    assert planned.M_ie < run.plain.M_ie


def test_servo_reaches_the_capture_point(paper_7dof):
    sc = paper_7dof
    goal = sc.run().optimized.theta
    ctrl = ffsr.CaptureController(sc, goal=goal)
    assert ctrl.servo and ctrl.gain == 0.0 and ctrl.max_joint_rate > 0
    steps = int(round(ctrl.duration / 0.1))
    p, q, th, statuses = drive(ctrl, sc.base.position, sc.base.orientation, sc.theta, steps)
    assert "fault" not in statuses
    data = ffsr.Data(sc.model)
    ffsr.forward_kinematics(sc.model, data, ffsr.BasePose(p, q), th)
    reached = ffsr.frame_pose(sc.model, data, None).p
    assert np.linalg.norm(reached - ctrl.capture_point) < 1e-3  # the scenario's tolerance


def test_one_tick_satisfies_the_rate_law(paper_7dof):
    """At a state off the plan (t = 40 s, the initial configuration moved): the base velocity gives zero
    momentum, the end-effector output is p_e, and the task rows of J_f map the joint rates to
    x_d_dot + k_p (x_d - p_e) (the null-space term adds nothing there), x_d_dot by central differences
    of the reference the controller writes."""
    sc = paper_7dof
    model, n = sc.model, sc.model.n
    ctrl = ffsr.CaptureController(sc)
    rng = np.random.default_rng(7)
    theta = sc.theta + rng.uniform(-0.05, 0.05, n)
    base = ffsr.BasePose(sc.base.position + np.array([0.01, -0.02, 0.005]), sc.base.orientation)
    t, dt = 40.0, 1e-3
    theta_dot, xb, ref, ee = np.zeros(n), np.zeros(6), np.zeros(3), np.zeros(3)
    status = ctrl.step(t, base.position, base.orientation, theta, theta_dot, xb, reference=ref, end_effector=ee)
    assert status == "ok" and ctrl.status == "ok" and ctrl.fault == "none" and ctrl.fault_index == -1
    assert ctrl.null_scale == 1.0 and ctrl.sigma_min > 0
    refs = []
    for s in (t - dt, t + dt):
        r = np.zeros(3)
        ctrl.step(s, base.position, base.orientation, theta, np.zeros(n), np.zeros(6), reference=r)
        refs.append(r)
    xd_dot = (refs[1] - refs[0]) / (2 * dt)

    data = ffsr.Data(model)
    ffsr.crba(model, data, base, theta)
    assert np.allclose(ee, ffsr.frame_pose(model, data, None).p, rtol=0, atol=1e-12)
    v = np.concatenate([xb, theta_dot])
    P = ffsr.momentum(model, data, v)
    assert np.linalg.norm(P) < 1e-10 * max(1.0, np.linalg.norm(data.H @ np.abs(v)))
    H = np.array(data.H)
    assert np.allclose(xb, -np.linalg.solve(H[:6, :6], H[:6, 6:] @ theta_dot), rtol=0, atol=1e-12)
    Jf = np.array(ffsr.generalized_jacobian(model, data, base, theta))
    rows = ctrl.task_rows
    assert rows == [0, 1, 2]
    task = (Jf @ theta_dot)[rows]
    wanted = xd_dot + ctrl.feedback * (ref - ee)
    assert np.max(np.abs(task - wanted)) < 1e-8 * max(1e-3, np.max(np.abs(wanted)))
    # the gradient policy moves the arm in the null space too: the rates are not the task's alone
    assert np.linalg.norm(theta_dot - np.linalg.pinv(Jf[rows]) @ wanted) > 1e-9


def test_update_target_moves_the_capture_point(paper_7dof):
    sc = paper_7dof
    ctrl = ffsr.CaptureController(sc)
    before = ctrl.capture_point.copy()
    est = ffsr.TargetEstimate.from_target(sc.target)
    assert ctrl.update_target(0.0, est) == "none"
    assert np.allclose(ctrl.capture_point, before, rtol=0, atol=1e-12)  # the same target: the same point
    moved = ffsr.TargetEstimate(est.position + np.array([0.03, -0.04, 0.0]), est.attitude, est.velocity,
                                est.angular_velocity)
    assert ctrl.update_target(0.0, moved) == "none"
    assert np.linalg.norm(ctrl.capture_point - before - np.array([0.03, -0.04, 0.0])) < 1e-9  # a translation
    assert ctrl.update_target(ctrl.duration, est) == "time"
    nan = ffsr.TargetEstimate(est.position, est.attitude, [0.0, float("nan"), 0.0], est.angular_velocity)
    assert ctrl.update_target(20.0, nan) == "target velocity"


def test_bad_arrays_are_refused_naming_them_and_nothing_is_written(paper_7dof):
    sc = paper_7dof
    n = sc.model.n
    ctrl = ffsr.CaptureController(sc)
    p, q, th = sc.base.position, sc.base.orientation, sc.theta
    td, xb = np.full(n, 7.0), np.full(6, 7.0)

    def refused(match, **kw):
        args = dict(t=1.0, base_position=p, base_orientation=q, theta=th, theta_dot=td, base_velocity=xb)
        args.update(kw)
        with pytest.raises(ffsr.InputError, match=match):
            ctrl.step(**args)
        assert np.all(td == 7.0) and np.all(xb == 7.0)  # nothing written

    refused(r"CaptureController\.step: theta_dot must be an array of float64", theta_dot=np.zeros(n, np.float32))
    refused(r"theta_dot has shape \(8,\), expected \(7,\)", theta_dot=np.zeros(n + 1))
    refused(r"base_velocity has shape \(2, 3\), expected \(6,\)", base_velocity=np.zeros((2, 3)))
    refused(r"theta_dot must be C-contiguous", theta_dot=np.zeros(2 * n)[::2])
    ro = np.zeros(6)
    ro.flags.writeable = False
    refused(r"base_velocity is read-only", base_velocity=ro)
    refused(r"theta_dot must be a numpy array of float64 \(the caller's output\), got list", theta_dot=[0.0] * n)
    refused(r"reference has shape \(4,\), expected \(3,\)", reference=np.zeros(4))
    refused(r"theta has 6 entries, expected 7", theta=th[:6])
    refused(r"base_orientation has 3 entries, expected 4", base_orientation=q[:3])
    refused(r"theta cannot be read as an array of float64", theta=["a"] * n)
    with pytest.raises(ffsr.InputError, match=r"CaptureController: the servo goal has 5 joints, the robot 7"):
        ffsr.CaptureController(sc, goal=np.zeros(5))
    with pytest.raises(ffsr.InputError, match=r"CaptureController: prediction window must be in 1\.\.100000"):
        ffsr.CaptureController(sc, prediction_window=0)
    with pytest.raises(ffsr.InputError, match=r"gain is the servo's"):
        ffsr.CaptureController(sc, gain=0.5)


def test_bad_values_are_faults_with_zero_rates(paper_7dof):
    sc = paper_7dof
    n = sc.model.n
    ctrl = ffsr.CaptureController(sc)
    p, q = sc.base.position, sc.base.orientation
    td, xb = np.zeros(n), np.zeros(6)
    assert ctrl.step(1.0, p, q, sc.theta, td, xb) == "ok" and np.any(td != 0)

    def fault(field, index, t=1.0, pos=p, quat=q, theta=sc.theta, estimate=None):
        td[:] = 7.0
        xb[:] = 7.0
        assert ctrl.step(t, pos, quat, theta, td, xb, estimate=estimate) == "fault"
        assert (ctrl.fault, ctrl.fault_index) == (field, index)
        assert np.all(td == 0) and np.all(xb == 0)

    theta = sc.theta.copy()
    theta[3] = np.nan
    fault("joint angle", 3, theta=theta)
    fault("time", -1, t=ctrl.duration + 1.0)
    fault("time", -1, t=float("nan"))
    fault("base position", 1, pos=np.array([0.0, np.inf, 0.0]))
    fault("base quaternion norm", -1, quat=np.array([0.0, 0.0, 0.0, 1.1]))
    est = ffsr.TargetEstimate.from_target(sc.target)
    bad = ffsr.TargetEstimate(est.position, est.attitude, est.velocity, [0.0, 0.0, float("nan")])
    fault("target angular velocity", 2, estimate=bad)
    assert ctrl.step(1.0, p, q, sc.theta, td, xb, estimate=est) == "ok"


def test_the_docs_control_loop_captures():
    """docs/python.md's control loop (Euler steps of a robot that follows the command at 100 Hz) runs and
    ends at the capture point and near the planner's configuration (RK4 at 10 Hz of the same law)."""
    import re
    import subprocess
    import sys

    from conftest import REPO

    text = (REPO / "docs" / "python.md").read_text()
    section = text[text.index("## Capture controller"):text.index("## 3-D view")]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[0]
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True,
                         timeout=600).stdout
    assert "fault" not in out
    error = float(re.search(r"capture error ([\d.e+-]+) m", out).group(1))
    assert error < 1e-3  # the scenario's tolerance, 1 mm
    from_plan_deg = float(re.search(r"([\d.]+) deg from the plan's", out).group(1))
    assert from_plan_deg < 0.5


def test_the_controller_keeps_its_scenario_alive():
    import gc

    ctrl = ffsr.CaptureController(ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), **{"global": False}))
    gc.collect()  # the scenario (its robot model) has no other reference
    td, xb = np.zeros(3), np.zeros(6)
    assert ctrl.step(0.0, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], np.radians([0.0, 150.0, -100.0]), td, xb) == "ok"
    assert np.all(np.isfinite(td)) and np.all(np.isfinite(xb))
