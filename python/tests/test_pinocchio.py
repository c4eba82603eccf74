"""H, J_bm, J_f, m_e, M_ie and the centroidal momentum of ffsr against Pinocchio's own Python package
(`pin`), on the paper's two robots and the real URDFs of ../shared/urdf-samples, at random base poses
and joint angles (fixed seeds), 1e-10 relative to the largest entry of the reference.

Pinocchio computes the same quantities in its own coordinates: a free-flyer whose velocity is the
base frame's [v; w] in the base frame, joints in its own order, continuous joints as (cos, sin), mimic
joints as coordinates of their own. The map T from ffsr's generalized velocity [v0, w0, theta_dot]
(v0 and w0 in the inertial frame, the base frame being the bus frame when the URDF is mounted on a bus)
to Pinocchio's is written down here from the conventions alone; then H = T^T H_pin T and
J_bm = J_pin T. J_f, m_e (Eq. 4) and M_ie (Eq. 14) follow from those matrices with numpy's solve.
Pinocchio's centroidal momentum takes its velocity T v.
"""

import numpy as np
import pytest

import ffsr

pin = pytest.importorskip("pinocchio", reason="Pinocchio's Python package `pin` is a test requirement")

from conftest import ROBOTS, samples_dir_or_skip  # noqa: E402

TOL = 1e-10


def skew(d):
    return np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])


def quat_to_rot(q):  # (x, y, z, w)
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def rel_err(a, ref):
    return np.max(np.abs(np.asarray(a) - np.asarray(ref))) / max(1.0, np.max(np.abs(ref)))


class Case:
    """One robot loaded by both libraries: ffsr's Model and Pinocchio's model with the same bus."""

    def __init__(self, path, end_effector="", offset=None, bus=None):
        self.fm = ffsr.Model.from_urdf(str(path), end_effector=end_effector, end_effector_offset=offset, bus=bus)
        pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        self.R_m, self.p_m = np.eye(3), np.zeros(3)
        if bus is not None:
            self.R_m, self.p_m = bus.mount.R, bus.mount.p
            # the bus as a body of the free-flyer: its frame in the URDF root frame is mount^-1
            bus_in_root = pin.SE3(self.R_m, self.p_m).inverse()
            pm.appendBodyToJoint(1, pin.Inertia(bus.mass, bus.com, bus.inertia), bus_in_root)
        ee = self.fm.frame_names[self.fm.end_effector]
        if offset is not None:
            hand = pm.frames[pm.getFrameId(end_effector)]
            placement = hand.placement * pin.SE3(np.eye(3), np.asarray(offset, dtype=float))
            pm.addFrame(pin.Frame(ee, hand.parentJoint, pm.getFrameId(end_effector), placement,
                                  pin.FrameType.OP_FRAME))
        self.fid = pm.getFrameId(ee)
        assert self.fid < len(pm.frames), ee
        self.pm, self.pd = pm, pm.createData()
        moving = {b.joint.name for b in self.fm.bodies[1:]}
        for name in list(pm.names)[2:]:
            assert name in moving, f"Pinocchio's joint {name} has no ffsr counterpart"

    def random_config(self, rng):
        theta = rng.uniform(-1.2, 1.2, self.fm.n)
        for k in range(self.fm.n):
            j = self.fm.joint(k)
            if j.type == ffsr.JointType.Prismatic:
                theta[k] = rng.uniform(j.lower, j.upper)
        quat = rng.normal(size=4)
        base = ffsr.BasePose(rng.uniform(-1, 1, 3), quat / np.linalg.norm(quat))
        return base, theta

    def pin_state(self, base, theta):
        """Pinocchio's q and the velocity map T (Pinocchio's v = T ffsr's v)."""
        fm, pm = self.fm, self.pm
        R_b = quat_to_rot(base.orientation)
        R_r = R_b @ self.R_m
        d = R_b @ self.p_m
        q = np.zeros(pm.nq)
        q[:3] = base.position + d
        q[3:7] = pin.Quaternion(R_r).coeffs()
        T = np.zeros((pm.nv, fm.nv))
        T[0:3, 0:3] = R_r.T
        T[0:3, 3:6] = -R_r.T @ skew(d)
        T[3:6, 3:6] = R_r.T
        for b in fm.bodies[1:]:
            j = pm.joints[pm.getJointId(b.joint.name)]
            value = b.multiplier * theta[b.coord] + b.offset
            if j.nq == 2:  # continuous joint: (cos, sin)
                q[j.idx_q:j.idx_q + 2] = [np.cos(value), np.sin(value)]
            else:
                q[j.idx_q] = value
            T[j.idx_v, 6 + b.coord] += b.multiplier
        return q, T

    def reference(self, base, theta):
        """H, J_bm, J_f in ffsr's coordinates from Pinocchio's CRBA and frame Jacobian."""
        q, T = self.pin_state(base, theta)
        pin.crba(self.pm, self.pd, q)
        M = np.triu(self.pd.M) + np.triu(self.pd.M, 1).T  # Pinocchio fills the upper triangle
        pin.computeJointJacobians(self.pm, self.pd, q)
        pin.updateFramePlacements(self.pm, self.pd)
        J = pin.getFrameJacobian(self.pm, self.pd, self.fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        H = T.T @ M @ T
        J = J @ T
        Jf = J[:, 6:] - J[:, :6] @ np.linalg.solve(H[:6, :6], H[:6, 6:])
        return H, J, Jf


def effective_mass_ref(H, J, u):
    Jv = J[:3]
    return 1.0 / (u @ Jv @ np.linalg.solve(H, Jv.T @ u))


def integrated_effective_mass_ref(m_e, target, u):
    """Eq. 14 from the target's parameters (numpy, not ffsr's Target methods)."""
    R = quat_to_rot(target.attitude)
    r = R @ target.contact_offset
    I = R @ target.inertia @ R.T
    ru = np.cross(r, u)
    return 1.0 / (1.0 / m_e + 1.0 / target.mass + ru @ np.linalg.solve(I, ru))


def check_case(case, seed, configs=4):
    rng = np.random.default_rng(seed)
    data = ffsr.Data(case.fm)
    target = ffsr.Target(attitude=[0.1, -0.2, 0.3, 0.9], contact_offset=[-0.25, 0.15, 0.05],
                         inertia=[[100, 2, -1], [2, 80, 3], [-1, 3, 120]])
    for _ in range(configs):
        base, theta = case.random_config(rng)
        H_ref, J_ref, Jf_ref = case.reference(base, theta)
        H = ffsr.crba(case.fm, data, base, theta)
        assert rel_err(H, H_ref) < TOL
        J = ffsr.frame_jacobian(case.fm, data)
        assert rel_err(J, J_ref) < TOL
        Jf = ffsr.generalized_jacobian(case.fm, data, base, theta)
        assert rel_err(Jf, Jf_ref) < TOL
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        me_ref = effective_mass_ref(H_ref, J_ref, u)
        me = ffsr.effective_mass(case.fm, data, base, theta, None, u)
        assert abs(me - me_ref) < TOL * me_ref
        u_t = quat_to_rot(target.attitude) @ target.normal
        M_ref = integrated_effective_mass_ref(effective_mass_ref(H_ref, J_ref, u_t), target, u_t)
        M = ffsr.integrated_effective_mass(case.fm, data, base, theta, None, target)
        assert abs(M - M_ref) < TOL * M_ref
        M_dense = ffsr.integrated_effective_mass_dense(case.fm, data, base, theta, None, target)
        assert abs(M_dense - M_ref) < TOL * M_ref


def check_centroidal(case, seed, configs=3):
    """ffsr.centroidal_momentum (from the last crba's H) against pin.computeCentroidalMomentum: the centre
    of mass and [P; L_c], L_c about it, both in the inertial frame (Pinocchio's velocity is T v)."""
    rng = np.random.default_rng(seed)
    data = ffsr.Data(case.fm)
    for _ in range(configs):
        base, theta = case.random_config(rng)
        v = rng.uniform(-0.5, 0.5, case.fm.nv)
        q, T = case.pin_state(base, theta)
        hg = pin.computeCentroidalMomentum(case.pm, case.pd, q, T @ v)
        ffsr.crba(case.fm, data, base, theta)
        c, h = ffsr.centroidal_momentum(case.fm, data, v)
        assert rel_err(c, case.pd.com[0]) < TOL
        assert rel_err(h, np.concatenate([hg.linear, hg.angular])) < TOL


def test_paper_3dof():
    check_case(Case(ROBOTS / "paper_3dof.urdf"), seed=1)


def test_paper_7dof():
    check_case(Case(ROBOTS / "paper_7dof.urdf"), seed=2)


def test_paper_7dof_on_a_tilted_bus():
    # the mount and the bus: the base frame (bus) is not the URDF root frame
    bus = ffsr.Bus(500.0, [[90, 2, -1], [2, 80, 3], [-1, 3, 100]], com=[0.02, -0.03, 0.05],
                   mount=ffsr.Pose.from_xyz_rpy([0.6, 0.1, 0.4], [0.1, -0.2, 0.3]))
    check_case(Case(ROBOTS / "paper_7dof.urdf", bus=bus), seed=3)


def sample_bus():
    return ffsr.Bus(500.0, [[90, 2, -1], [2, 80, 3], [-1, 3, 100]], com=[0.02, -0.03, 0.05],
                    mount=ffsr.Pose.from_xyz_rpy([0.6, 0.1, 0.4], [0.1, -0.2, 0.3]))


def test_panda_with_its_mimic_finger():
    d = samples_dir_or_skip()
    case = Case(d / "panda.urdf", "panda_hand", [0, 0, 0.1034], sample_bus())
    assert case.fm.n == 8  # 7 arm joints and one finger coordinate (the other finger mimics it)
    check_case(case, seed=4)


def test_ur5():
    d = samples_dir_or_skip()
    check_case(Case(d / "ur5_robot.urdf", "tool0", None, sample_bus()), seed=5)


def test_kinova_with_continuous_joints():
    d = samples_dir_or_skip()
    check_case(Case(d / "kinova.urdf", "j2s6s200_end_effector", None, sample_bus()), seed=6)


def test_centroidal_momentum():
    check_centroidal(Case(ROBOTS / "paper_3dof.urdf"), seed=7)
    check_centroidal(Case(ROBOTS / "paper_7dof.urdf", bus=sample_bus()), seed=8)


def test_centroidal_momentum_with_a_mimic_joint():
    d = samples_dir_or_skip()
    check_centroidal(Case(d / "panda.urdf", "panda_hand", [0, 0, 0.1034], sample_bus()), seed=9)
