"""The grasp of ffsr against an independent computation with Pinocchio (`pin`): the robot's URDF with a
free-flyer base plus the target as a second free-flyer, the 6-D lock's Jacobian from Pinocchio's frame
Jacobians (the gripper frame minus a frame of the target at the same point), and the plastic impulse
from the KKT system [M J^T; J 0][v+; -p] = [M v-; 0] solved with numpy. The velocities after the lock
agree to 1e-9 on both paper robots, from random states and from the end of the Hertz contact run. Also
the post-capture run and the controller through Python."""

import subprocess

import numpy as np
import pytest

import ffsr

pin = pytest.importorskip("pinocchio", reason="Pinocchio's Python package `pin` is a test requirement")

from conftest import ROBOTS  # noqa: E402
from test_jobs import command, command_json, differences  # noqa: E402
from test_pinocchio import quat_to_rot  # noqa: E402


def random_target(rng, point):
    a = rng.uniform(5, 60, 3)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    inertia = Q @ np.diag([a[1] + a[2], a[0] + a[2], a[0] + a[1]]) @ Q.T
    quat = rng.normal(size=4)
    return ffsr.Target(mass=180.0, inertia=inertia, position=point + rng.uniform(-0.4, 0.4, 3),
                       attitude=quat / np.linalg.norm(quat), velocity=rng.uniform(-0.05, 0.05, 3),
                       angular_velocity=rng.uniform(-0.1, 0.1, 3))


def set_joint_angles(pm, fm, theta, q):
    """Writes ffsr's joint angles into Pinocchio's q (by joint name; a continuous joint as cos, sin);
    returns (ffsr coordinate, Pinocchio velocity index) per joint."""
    out = []
    for b in fm.bodies[1:]:
        j = pm.joints[pm.getJointId(b.joint.name)]
        if j.nq == 2:
            q[j.idx_q:j.idx_q + 2] = [np.cos(theta[b.coord]), np.sin(theta[b.coord])]
        else:
            q[j.idx_q] = theta[b.coord]
        out.append((b.coord, j.idx_v))
    return out


def pinocchio_grasp(path, fm, base, theta, v, target, ee_name):
    """v+ of robot and target (ffsr's coordinates: robot [v0, w0, theta_dot], target [v_c, w]) and the
    impulse on the gripper, by Pinocchio."""
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    tj = pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "target_free_flyer")
    inertia = pin.Inertia(target.mass, np.zeros(3), np.asarray(target.inertia))
    pm.appendBodyToJoint(tj, inertia, pin.SE3.Identity())
    pd = pm.createData()
    R0 = quat_to_rot(base.orientation)
    Rt = quat_to_rot(target.attitude)
    q = np.zeros(pm.nq)
    q[:3] = base.position
    q[3:7] = base.orientation
    n = fm.n
    T = np.zeros((pm.nv, fm.nv + 6))  # Pinocchio's v = T [ffsr v; target twist]
    T[0:3, 0:3] = R0.T
    T[3:6, 3:6] = R0.T
    for coord, iv in set_joint_angles(pm, fm, theta, q):
        T[iv, 6 + coord] = 1.0
    jt = pm.joints[tj]
    q[jt.idx_q:jt.idx_q + 3] = target.position
    q[jt.idx_q + 3:jt.idx_q + 7] = target.attitude
    T[jt.idx_v:jt.idx_v + 3, fm.nv:fm.nv + 3] = Rt.T
    T[jt.idx_v + 3:jt.idx_v + 6, fm.nv + 3:fm.nv + 6] = Rt.T
    pin.forwardKinematics(pm, pd, q)
    pin.updateFramePlacements(pm, pd)
    ee = pm.getFrameId(ee_name)
    p = pd.oMf[ee].translation
    # a frame of the target at the contact point (its placement in the target's centre-of-mass frame)
    grip = pm.addFrame(pin.Frame("target_grip", tj, 0, pin.SE3(np.eye(3), Rt.T @ (p - target.position)),
                                 pin.FrameType.OP_FRAME))
    pd = pm.createData()
    pin.crba(pm, pd, q)
    M = np.triu(pd.M) + np.triu(pd.M, 1).T
    pin.computeJointJacobians(pm, pd, q)
    pin.updateFramePlacements(pm, pd)
    assert np.allclose(pd.oMf[grip].translation, p, atol=1e-12)
    Jg = pin.getFrameJacobian(pm, pd, ee, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    Jt = pin.getFrameJacobian(pm, pd, grip, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    J = Jg - Jt
    vminus = T @ np.concatenate([v, target.velocity, Rt @ target.angular_velocity])
    K = np.block([[M, J.T], [J, np.zeros((6, 6))]])
    sol = np.linalg.solve(K, np.concatenate([M @ vminus, np.zeros(6)]))
    vplus = sol[:pm.nv]
    back = np.linalg.lstsq(T, vplus, rcond=None)[0]  # T has full column rank (square, invertible blocks)
    return back[:fm.nv], back[fm.nv:], -sol[pm.nv:]


@pytest.mark.parametrize("urdf", ["paper_3dof.urdf", "paper_7dof.urdf"])
def test_grasp_against_pinocchio(urdf):
    path = ROBOTS / urdf
    fm = ffsr.Model.from_urdf(str(path), end_effector="ee")
    data = ffsr.Data(fm)
    rng = np.random.default_rng(48)
    for _ in range(4):
        quat = rng.normal(size=4)
        base = ffsr.BasePose(rng.uniform(-1, 1, 3), quat / np.linalg.norm(quat))
        theta = rng.uniform(-1.5, 1.5, fm.n)
        v = rng.uniform(-0.3, 0.3, fm.nv)
        ffsr.forward_kinematics(fm, data, base, theta)
        point = ffsr.frame_pose(fm, data, fm.end_effector).p
        target = random_target(rng, point)
        g = ffsr.grasp(fm, data, base, theta, v, None, target)
        v_ref, tw_ref, p_ref = pinocchio_grasp(path, fm, base, theta, v, target, "ee")
        scale = max(1.0, np.max(np.abs(v_ref)))
        assert np.max(np.abs(g.v_after - v_ref)) / scale < 1e-9
        assert np.max(np.abs(g.target_after - tw_ref)) / max(1.0, np.max(np.abs(tw_ref))) < 1e-9
        assert np.max(np.abs(g.impulse - p_ref)) / max(1.0, np.max(np.abs(p_ref))) < 1e-9
        assert np.linalg.norm(g.impulse) > 1e-3
        d = g.to_dict()
        assert np.array_equal(d["v_after"], g.v_after)


@pytest.mark.parametrize("name", ["paper_3dof", "paper_7dof_position"])
def test_grasp_after_contact_against_pinocchio(name):
    """The lock from the state the Hertz contact run ends in (its separation) against Pinocchio's KKT
    system at that state; the contact's and the lock's impulses add up to the approach lock's (to first
    order in the contact's duration, docs/detumble.md)."""
    sc = ffsr.Scenario.load(str(ROBOTS / f"{name}.toml"))
    urdf = ROBOTS / ("paper_3dof.urdf" if name == "paper_3dof" else "paper_7dof.urdf")
    fm = ffsr.Model.from_urdf(str(urdf), end_effector="ee")
    r = ffsr.grasp_after_contact(fm, None, sc.base, sc.theta, sc.target, 0.2)
    e = r.contact.end
    assert r.contact.contact_duration > 0 and r.contact.separation_velocity < 0
    assert np.array_equal(r.grasp.v_before, e.v)
    v_ref, tw_ref, p_ref = pinocchio_grasp(urdf, fm, e.base, e.theta, e.v, e.target, "ee")
    assert np.max(np.abs(r.grasp.v_after - v_ref)) / max(1.0, np.max(np.abs(v_ref))) < 1e-9
    assert np.max(np.abs(r.grasp.target_after - tw_ref)) / max(1.0, np.max(np.abs(tw_ref))) < 1e-9
    assert np.max(np.abs(r.grasp.impulse - p_ref)) / max(1.0, np.max(np.abs(p_ref))) < 1e-9
    a = ffsr.grasp_at_capture(fm, None, sc.base, sc.theta, sc.target, 0.2)
    total = r.grasp.impulse.copy()
    total[:3] += r.contact_impulse
    assert np.linalg.norm(total - a.impulse) < 1e-3 * np.linalg.norm(a.impulse)


def grasped_7dof():
    """The 7-DOF robot at the detumble scenario's configuration, the grasp at the end of the approach of
    its target (1, -0.5, 2 deg/s) and the stack: (model, theta, target, base, grasp, stack)."""
    fm = ffsr.Model.from_urdf(str(ROBOTS / "paper_7dof.urdf"), end_effector="ee")
    theta = np.radians([0, 90, 90, -90, 90, 90, 0])
    target = ffsr.Target(angular_velocity=np.radians([1, -0.5, 2]), contact_offset=[-0.25, 0.15, 0.1])
    base = ffsr.BasePose()
    g = ffsr.grasp_at_capture(fm, None, base, theta, target, 0.2)
    stack = ffsr.attach_body(fm, "ee", g.body.mass, g.body.inertia, g.body.pose)
    return fm, theta, target, base, g, stack


def test_detumble_run_and_controller():
    fm, theta, target, base, g, stack = grasped_7dof()
    limits = [60, 60, 60, 40, 20, 20, 20]
    r = ffsr.run_detumble(stack, "ee", g.body, base, theta, g.v_after, limits, horizon=60.0)
    assert r.at_rest and r.momentum_drift < 1e-8
    assert np.all(np.abs(r.series_tau) <= np.asarray(limits) * (1 + 1e-12))
    c = ffsr.DetumbleController(stack, "ee", g.body, limits)
    cmd = c.step(stack, base, theta, g.v_after)
    assert cmd["status"] in ("braking", "saturated") and np.all(np.abs(cmd["tau"]) <= np.asarray(limits) * (1 + 1e-12))
    assert 0 < cmd["decay"] <= c.decay_cap and not cmd["passive"]
    with pytest.raises(ffsr.InputError, match="angular momentum is conserved"):
        ffsr.DetumbleController(stack, "ee", g.body, limits, stop_stack_spin=True)
    # an AttachedBody of one's own: the same stack and the same run as the grasp's body
    own = ffsr.AttachedBody(g.body.mass, g.body.inertia, g.body.pose)
    r2 = ffsr.run_detumble(stack, "ee", own, base, theta, g.v_after, limits, horizon=60.0)
    assert r2.time_to_rest == r.time_to_rest and np.array_equal(r2.series_tau, r.series_tau)
    with pytest.raises(ffsr.InputError, match="mass must be positive"):
        ffsr.AttachedBody(-1.0, np.eye(3))


def test_detumble_law_against_pinocchio_forward_dynamics():
    """The command makes every joint rate decay at the rate it reports: Pinocchio's ABA of the stack (the
    URDF plus the target as a fixed body) under the command's torques and base wrench gives
    qdd = -decay qd, and a joint or the gripper bound is active when the decay is below the cap."""
    pin = pytest.importorskip("pinocchio")
    fm, theta, target, base, g, stack = grasped_7dof()
    limits = np.array([60, 60, 60, 40, 20, 20, 20.0])
    c = ffsr.DetumbleController(stack, "ee", g.body, limits)
    cmd = c.step(stack, base, theta, g.v_after)
    # the same dynamics from ffsr's stack model evaluated by ffsr's ABA would not be independent: use
    # Pinocchio on the URDF with the target added as an inertia on the end-effector's body
    model = pin.buildModelFromUrdf(str(ROBOTS / "paper_7dof.urdf"), pin.JointModelFreeFlyer())
    model.gravity = pin.Motion.Zero()
    fid = model.getFrameId("ee")
    frame = model.frames[fid]
    body_pose = pin.SE3(np.asarray(g.body.pose.R), np.asarray(g.body.pose.p))
    placement = frame.placement * body_pose
    target_inertia = pin.Inertia(g.body.mass, np.zeros(3), np.asarray(g.body.inertia))
    model.inertias[frame.parentJoint] += target_inertia.se3Action(placement)
    data = model.createData()
    # the base at identity: ffsr's base twist and wrench (inertial axes, at the base origin) are
    # Pinocchio's free-flyer ones (local axes); the joints by name (continuous joints: cos, sin)
    q = np.zeros(model.nq)
    q[6] = 1.0
    v = np.zeros(model.nv)
    tau = np.zeros(model.nv)
    v[:6] = g.v_after[:6]
    tau[:6] = cmd["base_wrench"]
    idx = set_joint_angles(model, fm, theta, q)
    for k, iv in idx:
        v[iv] = g.v_after[6 + k]
        tau[iv] = cmd["tau"][k]
    a = pin.aba(model, data, q, v, tau)
    qd = np.zeros(fm.n)
    qdd = np.zeros(fm.n)
    for k, iv in idx:
        qd[k], qdd[k] = v[iv], a[iv]
    assert np.max(np.abs(qdd + cmd["decay"] * qd)) < 1e-9 * max(1.0, np.max(np.abs(cmd["decay"] * qd)))
    if cmd["decay"] < c.decay_cap:
        assert np.max(np.abs(cmd["tau"]) / limits) > 1 - 1e-9
    with pytest.raises(ffsr.InputError, match="mass must be positive"):
        ffsr.attach_body(fm, "ee", 0.0, np.eye(3), g.body.pose)


@pytest.mark.parametrize("run,grasp_after", [(None, "approach"), ("all", "approach"), (None, "contact")])
def test_detumble_job_equals_the_command(tmp_path, run, grasp_after):
    scenario = ROBOTS / "paper_7dof_detumble.toml"
    flags = [*(["--run", run] if run else []), "--grasp-after", grasp_after]
    expected = command_json(tmp_path, scenario, *flags, subcommand="detumble")
    result = ffsr.Scenario.load(str(scenario), grasp_after=grasp_after).detumble(run=run)
    got = result.to_dict()
    assert differences(got, expected) == []
    first = got["runs"][0] if run else got
    assert result.time_to_rest == first["time_to_rest"]
    assert result.peak_joint == first["peak_joint"]
    assert result.runs == (3 if run else 1)
    assert first["grasp"]["start"] == grasp_after
    with pytest.raises(ffsr.InputError,  # the Python argument, not the command's flag --run
                       match=r"^Scenario\.detumble: run: expected plain, optimized, global or all, got 'best'$"):
        ffsr.Scenario.load(str(scenario)).detumble(run="best")


def test_held_stack_equals_the_command(tmp_path):
    """robots/vyas2022_planar.toml: a stack that holds its target (grasp_after = 'held', no capture keys)
    loads and runs detumble() as the command does; the jobs that evaluate a capture refuse it; the start
    rates are keywords like the other keys."""
    scenario = ROBOTS / "vyas2022_planar.toml"
    expected = command_json(tmp_path, scenario, subcommand="detumble")
    sc = ffsr.Scenario.load(str(scenario))
    result = sc.detumble()
    got = result.to_dict()
    assert differences(got, expected) == []
    assert got["grasp"]["start"] == "held"
    assert result.time_to_rest <= 1.05 * 4.095  # the law at the limits against the published optimum
    with pytest.raises(ffsr.InputError, match=r"missing key 'target-angular-velocity-deg' \(grasp-after = held"):
        sc.run()
    with pytest.raises(ffsr.InputError, match=r"missing key '.*' \(grasp-after = held"):
        sc.inspect()
    # the keyword is the flag: the joints at rest at the start, only the chaser moving
    still = ffsr.Scenario.load(str(scenario), start_joint_rates_deg=[0, 0, 0]).detumble().to_dict()
    assert differences(still, command_json(tmp_path, scenario, "--start-joint-rates-deg", "0,0,0",
                                           subcommand="detumble")) == []
    assert still["time_to_rest"] != got["time_to_rest"]
    with pytest.raises(ffsr.InputError, match=r"start.joint.rates.deg: got 2 rates, the robot has 3 joints"):
        ffsr.Scenario.load(str(scenario), start_joint_rates_deg=[1, 2]).detumble()
    with pytest.raises(ffsr.InputError, match=r"start.base.velocity: acts with grasp-after = held only"):
        ffsr.Scenario.load(str(ROBOTS / "paper_7dof_detumble.toml"), start_base_velocity=[0, 0, 0.1])


def test_detumble_series_equals_the_command(tmp_path):
    """series_csv() is the command's --csv (the poses the 3-D view animates after the capture)."""
    scenario = ROBOTS / "paper_7dof_detumble.toml"
    out = tmp_path / "series.csv"
    subprocess.run([command(), "detumble", "--config", str(scenario), "--run", "optimized", "--quiet", "--csv",
                    str(out)], check=True, timeout=900)
    assert ffsr.Scenario.load(str(scenario)).detumble(run="optimized").series_csv() == out.read_text()


def test_detumble_plan_equals_the_command(tmp_path):
    """Scenario.detumble(plan=True) is `detumble --plan`: the plan's time, its re-run at rest within the
    limits, and its rows in series_csv() beside the law's."""
    scenario = ROBOTS / "paper_7dof_detumble.toml"
    expected = command_json(tmp_path, scenario, "--plan", subcommand="detumble")
    result = ffsr.Scenario.load(str(scenario)).detumble(plan=True)
    plan = result.to_dict()["plan"]
    assert result.plan_time_to_rest == pytest.approx(expected["plan"]["time_to_rest"], rel=1e-9)
    assert result.plan_time_to_rest < result.time_to_rest
    # on the 0.01 s tick's grid the least-effort solve may stop at IPOPT's acceptable level
    assert plan["solver_status"] in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
    assert plan["constraint_violation"] <= 1e-8
    assert plan["rerun"]["at_rest"] and plan["rerun"]["dwell_at_rest"]
    assert plan["rerun"]["worst_bound_excess"] <= 1e-9
    limits = np.array(plan and result.to_dict()["parameters"]["joint_torque_limit"])
    taus = np.array([c["tau"] for c in plan["controls"]])
    assert np.all(np.abs(taus) <= limits)
    runs = {line.split(",", 1)[0] for line in result.series_csv().splitlines()[1:]}
    assert runs == {"law", "plan"}
    assert ffsr.Scenario.load(str(scenario)).detumble().plan_time_to_rest is None


def test_detumble_keys_from_python_name_the_bound_too_small():
    """Scenario.detumble with the Detumble keys as keywords: the key of the bound that is too small,
    numbers as written (0.05, not 0.050000000000000003), no NaN accepted; a value Scenario.load refuses
    names its keyword (wheel_torque), one the job refuses the key."""
    scenario = str(ROBOTS / "paper_7dof_detumble.toml")
    wheels = dict(base_actuator="reaction-wheels", stop_stack_spin=True)
    cases = [
        (dict(stop_stack_spin=True), r"stop[-_]stack[-_]spin: .*conserved"),
        (dict(wheels, wheel_torque=0.2, wheel_momentum=0.05), r"wheel[-_]momentum: .*\(0\.05 per axis\)"),
        (dict(wheels, wheel_torque=1e-4, wheel_momentum=25), r"wheel[-_]torque: .*\(0\.0001 N m per axis\)"),
        (dict(base_actuator="thrusters", stop_stack_spin=True, thruster_force=1.0, thruster_torque=1e-4),
         r"thruster[-_]torque: .*the horizon is 120 s"),
        (dict(wheels, wheel_torque=float("nan"), wheel_momentum=1), r"wheel[-_]torque: must be finite"),
        (dict(wheels, wheel_torque=0.2, wheel_momentum=float("inf")), r"wheel[-_]momentum: must be finite"),
        (dict(wheels, wheel_torque="strong", wheel_momentum=1), r"wheel[-_]torque: 'strong' is not a number"),
        (dict(joint_torque_limit=[60, 60, 60]), r"joint[-_]torque[-_]limit: 3 values for 7 joints"),
        (dict(joint_torque_limit=-1.0), r"joint[-_]torque[-_]limit: every limit must be positive, got -1"),
        (dict(base_actuator="magnetorquer"), r"base[-_]actuator: .*'magnetorquer'"),
        (dict(rest_rate_deg=0.0), r"rest[-_]rate[-_]deg: must be positive"),
        (dict(detumble_horizon=1.0, detumble_tick=1.0), r"detumble[-_]tick: must be shorter"),
        (dict(detumble_horizon=1e6), r"detumble[-_]tick: at most 1e7 ticks"),
        (dict(detumble_horizon=0.1), r"detumble[-_]horizon: the stack is not at rest after 0\.1 s"),
    ]
    for keys, words in cases:
        with pytest.raises(ffsr.InputError, match=words) as e:
            ffsr.Scenario.load(scenario, **keys).detumble()
        assert "nan" not in str(e.value).replace("must be finite, got nan", "")
        assert not any(len(x.split(".")[-1]) >= 10 for x in str(e.value).split() if x[:1].isdigit())


def test_detumble_controller_and_attach_refuse_bad_input():
    fm, theta, target, base, g, stack = grasped_7dof()
    limits = [60, 60, 60, 40, 20, 20, 20]
    bad = [
        (dict(joint_torque=limits[:3]), r"joint_torque"),
        (dict(joint_torque=[60, 60, 60, 40, 20, 20, float("nan")]), r"joint7|finite"),
        (dict(joint_torque=[60, 60, 60, 0, 20, 20, 20]), r"joint4.* must be positive"),
        (dict(actuator="ion-drive"), r"unknown actuator 'ion-drive'"),
        (dict(actuator="reaction-wheels", wheel_torque=float("nan"), wheel_momentum=1.0, stop_stack_spin=True),
         r"wheels' torque must be positive and finite"),
        (dict(actuator="thrusters", thruster_force=1.0, thruster_torque=-1.0, stop_stack_spin=True),
         r"thrusters' torque must be positive"),
        (dict(rest_rate=0.0), r"rest"),
        (dict(rest_rate=float("nan")), r"rest"),
    ]
    bad += [
        (dict(gripper_force=0.0), r"gripper's force limit must be positive"),
        (dict(gripper_moment=float("nan")), r"gripper's moment limit must be positive"),
        (dict(max_decay=0.0), r"largest decay rate must be positive"),
        (dict(max_base_decay=float("inf")), r"stack's momentum must be positive and finite"),
        (dict(tick=0.0), r"tick must be positive"),
    ]
    for kw, words in bad:
        args = dict(joint_torque=limits)
        args.update(kw)
        with pytest.raises(ffsr.InputError, match=words):
            ffsr.DetumbleController(stack, "ee", g.body, **args)
    with pytest.raises(ffsr.InputError, match="'nope'"):
        ffsr.DetumbleController(stack, "nope", g.body, limits)
    c = ffsr.DetumbleController(stack, "ee", g.body, limits)
    with pytest.raises(ffsr.InputError, match="theta"):
        c.step(stack, base, theta[:3], g.v_after)
    with pytest.raises(ffsr.InputError, match="triangle inequality"):
        ffsr.attach_body(fm, "ee", 10.0, np.diag([1.0, 1.0, 5.0]), g.body.pose)
    with pytest.raises(ffsr.InputError, match="'nope'"):
        ffsr.attach_body(fm, "nope", 10.0, np.eye(3), g.body.pose)
    with pytest.raises(ffsr.InputError):
        ffsr.attach_body(fm, "ee", float("nan"), np.eye(3), g.body.pose)
    with pytest.raises(ffsr.InputError, match="1e7 ticks|tick"):
        ffsr.run_detumble(stack, "ee", g.body, base, theta, g.v_after, limits, horizon=1e6, tick=1e-3)
    with pytest.raises(ffsr.InputError, match="tick"):
        ffsr.run_detumble(stack, "ee", g.body, base, theta, g.v_after, limits, horizon=1.0, tick=2.0)
    with pytest.raises(ffsr.InputError, match="'nope'"):
        ffsr.grasp_at_capture(fm, "nope", base, theta, target, 0.2)
    with pytest.raises(ffsr.InputError, match="'nope'"):
        ffsr.run_detumble(stack, "nope", g.body, base, theta, g.v_after, limits)
