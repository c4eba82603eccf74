"""Bad input raises the Python class of the library's exception, with the library's message: the C++
hierarchy (ffsr::Error > InputError, ModelError, NumericalError > JointLimitError, IntegrationError)
mirrored, a message that names the function or file and the argument; arrays converted as numpy
converts them, but never one of the wrong shape or one holding NaN or infinity."""

import numpy as np
import pytest

import ffsr
from conftest import ROBOTS


@pytest.fixture(scope="module")
def robot():
    model = ffsr.Model.from_urdf(str(ROBOTS / "paper_3dof.urdf"))
    return model, ffsr.Data(model)


def test_hierarchy():
    assert issubclass(ffsr.Error, RuntimeError)
    for cls in (ffsr.InputError, ffsr.ModelError, ffsr.NumericalError, ffsr.IntegrationError):
        assert issubclass(cls, ffsr.Error)
    assert issubclass(ffsr.JointLimitError, ffsr.NumericalError)
    assert issubclass(ffsr.JointRateLimitError, ffsr.InputError)
    assert issubclass(ffsr.InputError, ValueError)
    assert not issubclass(ffsr.ModelError, ffsr.InputError)


def test_urdf_that_is_not_xml(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text("this is not XML\n")
    with pytest.raises(ffsr.ModelError) as e:
        ffsr.Model.from_urdf(str(path))
    assert str(e.value).startswith(f"{path}: ")  # the loader names the file first


def test_missing_urdf(tmp_path):
    path = tmp_path / "absent.urdf"
    with pytest.raises(ffsr.ModelError, match="absent.urdf: cannot open the URDF file"):
        ffsr.Model.from_urdf(str(path))


def test_urdf_string_names_its_source():
    with pytest.raises(ffsr.ModelError, match="^mine.urdf: "):
        ffsr.Model.from_urdf_string("<robot name='x'><link name='a'/></robot>", "mine.urdf")


def test_unknown_inertia_repair():
    with pytest.raises(ffsr.InputError, match="inertia-repair: unknown mode 'fix'"):
        ffsr.Model.from_urdf(str(ROBOTS / "paper_3dof.urdf"), inertia_repair="fix")


def test_wrong_joint_count(robot):
    model, data = robot
    with pytest.raises(ffsr.InputError, match=r"^forward_kinematics: theta has 4 entries, expected 3$"):
        ffsr.crba(model, data, ffsr.BasePose(), np.zeros(4))
    with pytest.raises(ffsr.InputError, match=r"theta has 2 entries, expected 3"):
        ffsr.integrated_effective_mass(model, data, ffsr.BasePose(), [0.0, 1.0])


def test_nan(robot):
    model, data = robot
    theta = np.array([0.0, np.nan, 0.0])
    with pytest.raises(ffsr.InputError, match=r"^integrated_effective_mass: theta must be finite, entry 1 is nan$"):
        ffsr.integrated_effective_mass(model, data, ffsr.BasePose(), theta)
    with pytest.raises(ffsr.InputError, match="^BasePose: position must be finite, entry 1 is inf$"):
        ffsr.BasePose(position=[0, np.inf, 0])
    with pytest.raises(ffsr.InputError, match="^crba: theta must be finite, entry 2 is inf$"):
        ffsr.crba(model, data, ffsr.BasePose(), [0, 0, np.inf])
    with pytest.raises(ffsr.InputError, match="thetas must be finite"):
        ffsr.integrated_effective_mass_batch(model, ffsr.BasePose(), np.array([[0, 0, 0], [0, np.nan, 0.0]]))


def test_strided_and_transposed_arrays_are_read(robot):
    model, data = robot
    theta = np.array([0.1, -0.4, 0.9])
    strided = np.repeat(theta, 2)[::2]
    assert not strided.flags.c_contiguous
    ref = ffsr.crba(model, data, ffsr.BasePose(), theta).copy()
    assert np.array_equal(ffsr.crba(model, data, ffsr.BasePose(), strided), ref)
    thetas = np.tile(theta, (3, 1))
    wide = np.zeros((3, 10))
    wide[:, :3] = thetas  # rows of 3 in a wider array
    single = ffsr.integrated_effective_mass_batch(model, ffsr.BasePose(), thetas)
    assert np.array_equal(ffsr.integrated_effective_mass_batch(model, ffsr.BasePose(), wide[:, :3]), single)
    assert np.array_equal(ffsr.integrated_effective_mass_batch(model, ffsr.BasePose(), thetas.T.copy().T), single)


def test_wrong_type(robot):
    model, data = robot
    with pytest.raises(ffsr.InputError, match=r"^crba: theta cannot be read as an array of float64 \(ValueError: "):
        ffsr.crba(model, data, ffsr.BasePose(), [0.0, "a", 0.0])
    with pytest.raises(ffsr.InputError, match=r"crba: theta cannot be read as an array of float64 \(TypeError"):
        ffsr.crba(model, data, ffsr.BasePose(), {})


def test_wrong_shape(robot):
    model, data = robot
    with pytest.raises(ffsr.InputError, match="^crba: theta must be a 1-dimensional array, got 2 dimensions$"):
        ffsr.crba(model, data, ffsr.BasePose(), np.zeros((3, 1)))
    with pytest.raises(ffsr.InputError, match=r"thetas has shape \(5, 4\), expected \(5, 3\)"):
        ffsr.integrated_effective_mass_batch(model, ffsr.BasePose(), np.zeros((5, 4)))
    with pytest.raises(ffsr.InputError, match=r"Target: inertia has shape \(2, 2\), expected \(3, 3\)"):
        ffsr.Target(inertia=np.eye(2))
    with pytest.raises(ffsr.InputError, match="rnea: v has 8 entries, expected 9"):
        ffsr.rnea(model, data, ffsr.BasePose(), np.zeros(3), np.zeros(8), np.zeros(9))


def test_data_of_another_model(robot):
    model, _ = robot
    other = ffsr.Model.from_urdf(str(ROBOTS / "paper_7dof.urdf"))
    with pytest.raises(ffsr.InputError, match="data was made for a model with 7 joints"):
        ffsr.crba(model, ffsr.Data(other), ffsr.BasePose(), np.zeros(3))


def test_unknown_names(robot):
    model, data = robot
    with pytest.raises(ffsr.InputError, match="unknown frame 'hand'; the model has: base"):
        ffsr.frame_jacobian(model, data, "hand")
    with pytest.raises(ffsr.InputError, match="frame index 99 out of range"):
        ffsr.frame_jacobian(model, data, 99)
    with pytest.raises(ffsr.InputError) as e:
        ffsr.ContactLaw("hertz", ffsr.ContactParams(), 0.2)
    assert "hunt-crossley" in str(e.value)  # the valid names are listed
    with pytest.raises(ffsr.InputError, match="joints: unknown joint model 'stiff'"):
        ffsr.integrated_effective_mass(model, data, ffsr.BasePose(), np.zeros(3), joints="stiff")


def test_bad_physical_values(robot):
    model, data = robot
    with pytest.raises(ffsr.InputError, match="target: mass must be positive"):
        ffsr.Target(mass=-1.0)
    with pytest.raises(ffsr.InputError, match="ContactParams"):
        ffsr.ContactParams(c_r=1.5)
    with pytest.raises(ffsr.InputError, match="effective_mass: direction u must be a unit vector"):
        ffsr.effective_mass(model, data, ffsr.BasePose(), np.zeros(3), None, [1.0, 1.0, 0.0])
    with pytest.raises(ffsr.InputError, match="armature: the value of joint 'joint2' must be finite and >= 0"):
        ffsr.integrated_effective_mass(model, data, ffsr.BasePose(), np.zeros(3), joints="armature",
                                       armature=[0.1, -1.0, 0.1])
    with pytest.raises(ffsr.ModelError, match="mass must be positive"):
        ffsr.ModelBuilder("base", ffsr.Inertia(10.0, I=np.eye(3))).add_joint(
            "j1", ffsr.JointType.Revolute, "base", ffsr.Pose(), [0, 0, 1], "l1", ffsr.Inertia(0.0)).build()


def test_overflow_from_finite_values_is_a_numerical_error():
    # omega_t x r = (0, 1e400, 0) overflows; u . (...) then multiplies inf by u_y = 0 (NaN before)
    with pytest.raises(ffsr.NumericalError, match="approach_velocity: the relative velocity overflows"):
        ffsr.approach_velocity([1, 0, 0], [0.2, 0, 0], [0, 0, 0], [0, 0, 1e200], [1e200, 0, 0])
    # the fuzz_numeric finding (tests/data/fuzz_regressions/fuzz_numeric/approach_velocity_nan)
    with pytest.raises(ffsr.NumericalError):
        ffsr.approach_velocity([6.663691e-317, 0.0, 1.0], [0.0, 0.0, 0.0],
                               [200.0, 100.0, 3.893880265755862e-308],
                               [-9.255963143549733e61, -4.783214422640232e300, 4.228978974595545e159],
                               [-3.197300970554343e168, 1.27855629e-314, 8.1387e-320])
    # finite values still answer: u . (v_e - omega_t x r) with (omega_t x r)_x = -omega_z r_y
    assert ffsr.approach_velocity([1, 0, 0], [0.2, 0, 0], [0, 0, 0], [0, 0, 0.03], [-0.25, 0.15, 0]) == \
        pytest.approx(0.2 + 0.03 * 0.15, rel=1e-15)


def test_an_approach_speed_is_positive_in_every_call(robot):
    """The main job's bound on approach-speed (positive, finite) in the calls that take a speed, each
    naming itself and its argument."""
    model, _ = robot
    theta = np.radians([0.0, 90.0, -90.0])
    target = ffsr.Target()
    for bad, shown in ((0.0, "0"), (-0.2, "-0.2"), (float("nan"), "nan"), (float("inf"), "inf")):
        with pytest.raises(ffsr.InputError, match=rf"^grasp_at_capture: approach_speed must be positive \(m/s\), "
                                                  rf"got {shown}$"):
            ffsr.grasp_at_capture(model, None, ffsr.BasePose(), theta, target, bad)
        with pytest.raises(ffsr.InputError, match=rf"^grasp_after_contact: approach_speed must be positive"):
            ffsr.grasp_after_contact(model, None, ffsr.BasePose(), theta, target, bad)
        with pytest.raises(ffsr.InputError, match=rf"^simulate_contact: approach_speed must be positive"):
            ffsr.simulate_contact(model, ffsr.BasePose(), theta, approach_speed=bad)
    # as a scenario key: Scenario.load's keyword, named as the keyword
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: approach_speed: must be positive, got -0\.2$"):
        ffsr.Scenario.load(str(ROBOTS / "paper_3dof.toml"), approach_speed=-0.2)
    assert ffsr.grasp_at_capture(model, None, ffsr.BasePose(), theta, target, 0.2) is not None


def test_an_error_names_the_python_argument():
    """A job's or Scenario.load's keyword at fault is named as the keyword (an underscore for a dash),
    after the call, not as the command's flag."""
    scenario = str(ROBOTS / "paper_3dof.toml")
    with pytest.raises(ffsr.InputError,
                       match=r"^Scenario\.detumble: run: expected plain, optimized, global or all, got 'nope'$"):
        ffsr.Scenario.load(scenario).detumble(run="nope")
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: stop_stack_spin: expected true or false, got 'yes'$"):
        ffsr.Scenario.load(scenario, stop_stack_spin="yes")
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: stop_stack_spin: expected true or false, got '1'$"):
        ffsr.Scenario.load(scenario, stop_stack_spin=1)
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: global: expected true or false, got 'on'$"):
        ffsr.Scenario.load(scenario, **{"global": "on"})
    # a keyword with a key of the file: both named as keywords, not located at the file's line of the other
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: target_mass/target_inertia: "):
        ffsr.Scenario.load(scenario, target_inertia=[1, 1, 5])
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: joint_torque_limit: "):
        ffsr.Scenario.load(scenario, joint_torque_limit="strong")
    with pytest.raises(ffsr.InputError, match=r"^Scenario\.load: no_such_key: not a scenario key$"):
        ffsr.Scenario.load(scenario, no_such_key=1)
    assert ffsr.Scenario.load(scenario, stop_stack_spin=True) is not None  # the words themselves
