"""CaptureController from Python: step writes into the caller's arrays (the same memory, tick after
tick), the base velocity it writes is the zero-momentum one of the rates it writes (checked with crba
and base_velocity_from_momentum), a bad measurement is a fault and not an exception, a bad output
array is an InputError; driven by its own rates (RK4 on the joint angles and the base pose from the
rates) it brings the end-effector to the capture point."""

import numpy as np
import pytest

import ffsr
from conftest import ROBOTS


@pytest.fixture(scope="module")
def scenario():
    return ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), **{"global": False})


def test_step_writes_into_the_callers_arrays(scenario):
    ctrl = ffsr.CaptureController(scenario)
    n = ctrl.joints
    td, bv = np.zeros(n), np.zeros(6)
    td_address = td.__array_interface__["data"][0]
    base, theta, target = scenario.base, scenario.theta, scenario.target
    status = ctrl.step(0.0, base.position, base.orientation, theta, target.position, target.attitude,
                       target.velocity, target.angular_velocity, td, bv)
    assert status[0] in ("ok", "damped", "rate-limited") and status[1] == "none"
    assert td.__array_interface__["data"][0] == td_address and np.any(td != 0)
    model = scenario.model
    data = ffsr.Data(model)
    ffsr.crba(model, data, base, theta)
    expected = ffsr.base_velocity_from_momentum(model, data, td)
    assert np.max(np.abs(bv - expected)) < 1e-12 * max(1.0, np.max(np.abs(expected)))


def test_faults_and_bad_buffers(scenario):
    ctrl = ffsr.CaptureController(scenario)
    n = ctrl.joints
    td, bv = np.ones(n), np.ones(6)
    base, target = scenario.base, scenario.target
    theta = scenario.theta.copy()
    theta[1] = np.nan
    status = ctrl.step(1.0, base.position, base.orientation, theta, target.position, target.attitude,
                       target.velocity, target.angular_velocity, td, bv)
    assert status == ("fault", "joint angle", 1)
    assert np.all(td == 0) and np.all(bv == 0)
    with pytest.raises(ffsr.InputError, match="theta_dot_out must be an array of float64"):
        ctrl.step(1.0, base.position, base.orientation, scenario.theta, target.position, target.attitude,
                  target.velocity, target.angular_velocity, np.zeros(n, dtype=np.float32), bv)
    with pytest.raises(ffsr.InputError, match=r"base_velocity_out must have shape \(6,\)"):
        ctrl.step(1.0, base.position, base.orientation, scenario.theta, target.position, target.attitude,
                  target.velocity, target.angular_velocity, td, np.zeros(5))
    ro = np.zeros(n)
    ro.flags.writeable = False
    with pytest.raises(ffsr.InputError, match="theta_dot_out must be a writable array"):
        ctrl.step(1.0, base.position, base.orientation, scenario.theta, target.position, target.attitude,
                  target.velocity, target.angular_velocity, ro, bv)


def test_closed_loop_reaches_the_capture_point(scenario):
    """The exact target as the estimate, the state integrated from the controller's own rates (RK4,
    h = 0.1 s as the planner): the end-effector ends at the capture point of the plan's run."""
    ctrl = ffsr.CaptureController(scenario)
    model, data = scenario.model, ffsr.Data(scenario.model)
    n, T, h = ctrl.joints, ctrl.duration, 0.1
    target = scenario.target
    td, bv = np.zeros(n), np.zeros(6)

    def rates(t, pos, quat, theta):
        ctrl.step(min(t, T), pos, quat, theta, target.position, target.attitude, target.velocity,
                  target.angular_velocity, td, bv)
        return bv.copy(), td.copy()

    def advance(pos, quat, theta, v, dt):
        w = v[3:]
        angle = np.linalg.norm(w) * dt
        axis = w / np.linalg.norm(w) if angle > 0 else np.array([1.0, 0, 0])
        dq = np.concatenate([np.sin(angle / 2) * axis, [np.cos(angle / 2)]])
        x1, y1, z1, w1 = dq
        x2, y2, z2, w2 = quat
        q = np.array([w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                      w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2])
        return pos + v[:3] * dt, q / np.linalg.norm(q)

    pos, quat, theta = scenario.base.position, scenario.base.orientation, scenario.theta.copy()
    steps = int(round(T / h))
    for k in range(steps):
        t = k * h
        v1, d1 = rates(t, pos, quat, theta)
        p2, q2 = advance(pos, quat, theta, v1, h / 2)
        v2, d2 = rates(t + h / 2, p2, q2, theta + h / 2 * d1)
        p3, q3 = advance(pos, quat, theta, v2, h / 2)
        v3, d3 = rates(t + h / 2, p3, q3, theta + h / 2 * d2)
        p4, q4 = advance(pos, quat, theta, v3, h)
        v4, d4 = rates(t + h, p4, q4, theta + h * d3)
        v = (v1 + 2 * v2 + 2 * v3 + v4) / 6
        theta = theta + h / 6 * (d1 + 2 * d2 + 2 * d3 + d4)
        pos, quat = advance(pos, quat, theta, v, h)
    ffsr.forward_kinematics(model, data, ffsr.BasePose(pos, quat), theta)
    p_e = ffsr.frame_pose(model, data).p
    capture = ffsr.propagate_target(target, T).contact_point()
    assert np.linalg.norm((p_e - capture)[:2]) < 2e-3  # the planar robot's task: x and y, 1 mm tolerance
