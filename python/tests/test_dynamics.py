"""The bindings' dynamics and contact functions checked by identities and independent computations:
H symmetric positive definite and equal to RNEA with unit accelerations, momentum and kinetic energy
from H, the M_ie gradient against central differences under each joint model, ModelBuilder against the
URDF loader, the closed-form force peak against the exact one and the CVODE runs, and the views into
Data."""

import numpy as np
import pytest

import ffsr
from conftest import ROBOTS


@pytest.fixture(scope="module")
def seven():
    model = ffsr.Model.from_urdf(str(ROBOTS / "paper_7dof.urdf"))
    return model, ffsr.Data(model)


def random_state(model, seed):
    rng = np.random.default_rng(seed)
    q = rng.normal(size=4)
    base = ffsr.BasePose(rng.uniform(-1, 1, 3), q / np.linalg.norm(q))
    return base, rng.uniform(-2, 2, model.n), rng.normal(size=model.nv)


def test_H_identities(seven):
    model, data = seven
    base, theta, v = random_state(model, 11)
    H = ffsr.crba(model, data, base, theta).copy()
    assert np.max(np.abs(H - H.T)) < 1e-15 * np.max(np.abs(H))
    assert np.min(np.linalg.eigvalsh(H)) > 0
    zero = np.zeros(model.nv)
    scale = np.max(np.abs(H))
    for i in range(model.nv):
        tau = ffsr.rnea(model, data, base, theta, zero, np.eye(model.nv)[i])
        assert np.max(np.abs(tau - H[:, i])) < 1e-12 * scale
    ffsr.forward_kinematics(model, data, base, theta)
    assert np.max(np.abs(ffsr.momentum(model, data, v) - (H @ v)[:6])) < 1e-12 * scale * np.max(np.abs(v))
    T = ffsr.kinetic_energy(model, data, v)
    assert abs(T - 0.5 * v @ H @ v) < 1e-12 * T


def test_views_share_memory_with_data(seven):
    model, data = seven
    base, theta, _ = random_state(model, 12)
    H = ffsr.crba(model, data, base, theta)
    assert not H.flags.writeable
    assert np.shares_memory(H, data.H)
    kept = H.copy()
    ffsr.crba(model, data, base, theta + 0.5)
    assert np.max(np.abs(H - kept)) > 0  # the view shows the next call's H, the copy does not
    del data  # the view keeps its Data alive
    assert np.isfinite(H).all()


@pytest.mark.parametrize("joints,armature", [("free", None), ("locked", None), ("armature", [0.5, 0.4, 0.3, 0.2, 0.1, 0.1, 0.05])])
def test_gradient_against_central_differences(seven, joints, armature):
    model, data = seven
    base, theta, _ = random_state(model, 13)
    target = ffsr.Target(attitude=[0.1, 0.2, -0.1, 0.97])
    M, grad = ffsr.integrated_effective_mass_gradient(model, data, base, theta, None, target, joints, armature)
    assert M == pytest.approx(
        ffsr.integrated_effective_mass_dense(model, data, base, theta, None, target, joints, armature), rel=1e-14)
    assert M == pytest.approx(ffsr.integrated_effective_mass(model, data, base, theta, None, target, joints, armature),
                              rel=1e-12)
    h = 1e-6
    for k in range(model.n):
        e = np.eye(model.n)[k] * h
        fd = (ffsr.integrated_effective_mass(model, data, base, theta + e, None, target, joints, armature) -
              ffsr.integrated_effective_mass(model, data, base, theta - e, None, target, joints, armature)) / (2 * h)
        assert abs(grad[k] - fd) < 1e-7 * max(1.0, abs(fd))  # central differences: O(h^2) + rounding/h


def test_joint_models_order(seven):
    # locked >= armature >= free: the locked arm is the stiffest reaction, armature in between
    model, data = seven
    base, theta, _ = random_state(model, 14)
    free = ffsr.integrated_effective_mass(model, data, base, theta)
    arm = ffsr.integrated_effective_mass(model, data, base, theta, joints="armature", armature=0.3)
    locked = ffsr.integrated_effective_mass(model, data, base, theta, joints="locked")
    assert free < arm < locked
    assert ffsr.integrated_effective_mass(model, data, base, theta, joints="armature", armature=0.0) == \
        pytest.approx(free, rel=1e-13)


def test_model_builder_against_the_urdf_loader(seven):
    urdf, data = seven
    base_body = urdf.bodies[0]
    b = ffsr.ModelBuilder(base_body.name, base_body.inertia)
    for body in urdf.bodies[1:]:
        parent = urdf.bodies[body.parent].name
        b.add_joint(body.joint.name, body.joint.type, parent, body.tree, body.joint.axis, body.name, body.inertia,
                    body.joint.lower, body.joint.upper)
    bodies = {body.name for body in urdf.bodies}
    for f in urdf.frames:  # links merged by fixed joints: frames without inertia of their own (in their body's)
        if f.name not in bodies:
            b.add_fixed(f.name + "_joint", urdf.bodies[f.body].name, f.pose, f.name, ffsr.Inertia(0.0))
    built = b.set_end_effector(urdf.frame_names[urdf.end_effector]).build()
    assert built.n == urdf.n and built.joint_names == urdf.joint_names
    base, theta, _ = random_state(urdf, 15)
    H_urdf = ffsr.crba(urdf, data, base, theta).copy()
    bd = ffsr.Data(built)
    assert np.max(np.abs(ffsr.crba(built, bd, base, theta) - H_urdf)) < 1e-12 * np.max(np.abs(H_urdf))


def test_batch_equals_single_calls(seven):
    model, data = seven
    rng = np.random.default_rng(16)
    thetas = rng.uniform(-2, 2, (1000, model.n))
    base = ffsr.BasePose([0.1, 0.2, 0.3], [0, 0, 0.3826834323650898, 0.9238795325112867])
    single = np.array([ffsr.integrated_effective_mass(model, data, base, th) for th in thetas])
    for threads in (1, 2, 3):
        batch = ffsr.integrated_effective_mass_batch(model, base, thetas, threads=threads)
        assert np.max(np.abs(batch - single) / single) < 1e-12
    locked = ffsr.integrated_effective_mass_batch(model, base, thetas[:50], joints="locked")
    assert np.array_equal(locked, [ffsr.integrated_effective_mass(model, data, base, th, joints="locked")
                                   for th in thetas[:50]])
    law = ffsr.ContactLaw("herbert-mcwhannell", ffsr.ContactParams(), 0.2052)
    M, F = ffsr.max_force_batch(model, base, thetas[:50], law)
    assert np.array_equal(F, [law.max_force_closed_form(m) for m in M])
    M2, F2 = ffsr.max_force_batch(model, base, thetas[:5], law, exact=True)
    assert np.array_equal(F2, [law.max_force_exact(m) for m in M2])


def test_contact_law_closed_forms():
    params = ffsr.ContactParams(1e9, 1.5, 0.9)
    assert len(ffsr.contact_law_names()) == 8
    for name in ffsr.contact_law_names():
        law = ffsr.ContactLaw(name, params, 0.2052)
        M = 5.8
        # Eq. 23 and Eq. 24 are the same force; Eq. 20's delta_max gives it as K delta^alpha
        assert law.max_force_closed_form(M) == pytest.approx(law.max_force_estimate(M), rel=1e-12)
        assert law.max_force_estimate(M) == pytest.approx(1e9 * law.max_deformation(M) ** 1.5, rel=1e-12)
        # xi (Eq. 21) relates the closed form to the exact peak
        exact = law.max_force_exact(M)
        assert law.xi == pytest.approx(100 * (exact - law.max_force_closed_form(M)) / exact, rel=1e-9, abs=1e-12)
        # the exact peak of Eq. 16 against CVODE's integration of it
        run = ffsr.simulate_single_body(law, M)
        assert run.f_max == pytest.approx(exact, rel=1e-7)
        assert run.delta_max == pytest.approx(law.max_deformation(M), rel=1e-7)  # Eq. 20


def test_multibody_contact_against_the_single_body_peak():
    model = ffsr.Model.from_urdf(str(ROBOTS / "paper_3dof.urdf"))
    theta = np.radians([0.0, 90.0, -90.0])
    params = ffsr.ContactParams()
    res = ffsr.simulate_contact(model, ffsr.BasePose(), theta, None, ffsr.Target(), 0.2052, params,
                                "herbert-mcwhannell", record_series=True)
    data = ffsr.Data(model)
    M = ffsr.integrated_effective_mass(model, data, ffsr.BasePose(), theta)
    assert res.integrated_effective_mass == pytest.approx(M, rel=1e-12)
    law = ffsr.ContactLaw("herbert-mcwhannell", params, res.approach_velocity)
    assert res.f_max == pytest.approx(law.max_force_exact(M), rel=2e-3)  # the single-body model of the contact
    # momentum conserved: against the scale of the bodies' momenta (the target's 200 kg at the approach speed)
    assert np.max(np.abs(res.momentum_end - res.momentum_start)) < 1e-9 * 200 * 0.2052
    assert len(res.t) == len(res.force) > 10 and np.max(res.force) == pytest.approx(res.f_max, rel=1e-3)
