"""Array arguments as numpy converts them: every array a call only reads accepts what
numpy.asarray(x, dtype=numpy.float64) accepts and gives the same result as the float64 C-ordered array
of the same values; an empty batch gives an empty result; NaN is an InputError naming the call and the
argument (the controller's measured state: a fault status). The table of docs/python.md ("Argument
kinds") says what each call does with each kind; this test reads that table and checks every cell."""

import re

import numpy as np
import pytest

import ffsr
from conftest import REPO, ROBOTS

KINDS = ["list", "tuple", "int64", "float32", "Fortran order", "strided view", "0-row batch", "NaN"]


@pytest.fixture(scope="module")
def env():
    model = ffsr.Model.from_urdf(str(ROBOTS / "paper_7dof.urdf"))
    scenario = ffsr.Scenario.load(str(ROBOTS / "paper_7dof_position.toml"), **{"global": False})
    return model, ffsr.Data(model), scenario


def theta0():
    return np.array([0.3, -0.7, 0.5, 1.1, -0.2, 0.8, 0.4])


def thetas0():
    return np.array([theta0() + 0.1 * k for k in range(4)])


def _step(sc, x):
    ctrl = ffsr.CaptureController(sc)
    td, xb = np.zeros(7), np.zeros(6)
    status = ctrl.step(1.0, sc.base.position, sc.base.orientation, x, td, xb)
    return status, td, xb


def _pose():
    return ffsr.BasePose()


def _fk(e, x):
    ffsr.forward_kinematics(e[0], e[1], _pose(), x)
    return e[1].positions


def _momentum(e, x):
    ffsr.crba(e[0], e[1], _pose(), theta0())
    return ffsr.momentum(e[0], e[1], x)


def _max_force(e, x):
    law = ffsr.make_contact_law("hunt-crossley", ffsr.ContactParams(), 0.2)
    return np.array(ffsr.max_force_batch(e[0], _pose(), x, law))


def _armature(e, x):
    return ffsr.integrated_effective_mass(e[0], e[1], _pose(), theta0(), joints="armature", armature=x)


# call name -> (argument, the float64 value it is tested at, the call of that argument)
CALLS = {
    "forward_kinematics": ("theta", theta0(), _fk),
    "crba": ("theta", theta0(), lambda e, x: ffsr.crba(e[0], e[1], _pose(), x).copy()),
    "rnea": ("v", np.arange(13.0) / 10,
             lambda e, x: ffsr.rnea(e[0], e[1], _pose(), theta0(), x, np.ones(13)).copy()),
    "effective_mass": ("u", np.array([1.0, 0.0, 0.0]),
                       lambda e, x: ffsr.effective_mass(e[0], e[1], _pose(), theta0(), None, x)),
    "integrated_effective_mass": (
        "theta", theta0(), lambda e, x: ffsr.integrated_effective_mass(e[0], e[1], _pose(), x)),
    "integrated_effective_mass_dense": (
        "theta", theta0(), lambda e, x: ffsr.integrated_effective_mass_dense(e[0], e[1], _pose(), x)),
    "integrated_effective_mass_gradient": (
        "theta", theta0(), lambda e, x: ffsr.integrated_effective_mass_gradient(e[0], e[1], _pose(), x)[1]),
    "integrated_effective_mass (armature)": ("armature", np.array([1.0, 2.0, 3.0, 1.0, 2.0, 3.0, 1.0]),
                                             _armature),
    "momentum": ("v", np.arange(13.0) / 10, _momentum),
    "integrated_effective_mass_batch": (
        "thetas", thetas0(), lambda e, x: ffsr.integrated_effective_mass_batch(e[0], _pose(), x, threads=2)),
    "max_force_batch": ("thetas", thetas0(), _max_force),
    "approach_velocity": (
        "v_e", np.array([0.2, 0.0, 0.1]),
        lambda e, x: ffsr.approach_velocity([1, 0, 0], x, [0, 0, 0], [0, 0, 0.1], [1, 0, 0])),
    "BasePose": ("position", np.array([1.0, -2.0, 0.5]), lambda e, x: ffsr.BasePose(position=x).position),
    "Target": ("inertia", np.array([[100.0, 1.0, 0.0], [1.0, 90.0, 0.0], [0.0, 0.0, 80.0]]),
               lambda e, x: ffsr.Target(inertia=x).inertia),
    "CaptureController.step": ("theta", None, lambda e, x: _step(e[2], x)),
}


def kind_value(kind, x):
    """The argument `x` (float64) as `kind`."""
    if kind == "list":
        return x.tolist()
    if kind == "tuple":
        return tuple(map(tuple, x)) if x.ndim == 2 else tuple(x)
    if kind in ("int64", "float32"):
        return x.astype(kind)
    if kind == "Fortran order":
        return np.asfortranarray(x)
    if kind == "strided view":
        wide = np.repeat(x, 2, axis=-1)  # every entry twice: the view of every other one is x, strided
        v = wide[..., ::2]
        assert not v.flags.c_contiguous and np.array_equal(v, x)
        return v
    if kind == "0-row batch":
        return np.zeros((0, x.shape[1]))
    y = x.copy()
    y.flat[1] = np.nan
    return y


def same(a, b):
    if isinstance(a, tuple):
        return all(same(x, y) for x, y in zip(a, b))
    return np.array_equal(np.asarray(a), np.asarray(b))


def documented():
    """The table of docs/python.md, section "Argument kinds": {call: {kind: cell}}."""
    doc = (REPO / "docs" / "python.md").read_text()
    start = doc.index("### Argument kinds")
    section = doc[start:doc.index("\n## ", start)]
    lines = [x for x in section.splitlines() if x.startswith("| `")]
    table = {}
    for line in lines:
        cells = [c.strip() for c in line.strip("|").split("|")]
        name = re.match(r"`([^`]+)`", cells[0]).group(1)
        table[name] = dict(zip(KINDS, cells[1:]))
    return table


def test_the_table_lists_every_call():
    assert set(documented()) == set(CALLS)
    assert all(len(row) == len(KINDS) for row in documented().values())


@pytest.mark.parametrize("name", sorted(CALLS))
def test_each_kind_does_what_the_table_says(env, name):
    arg, x, call = CALLS[name]
    if x is None:  # the controller's theta: the scenario's start
        x = np.asarray(env[2].theta)
    reference = call(env, x)
    where = name.split(" ")[0]  # "integrated_effective_mass (armature)": the call's name
    for kind, cell in documented()[name].items():
        if cell == "-":
            continue
        value = kind_value(kind, x)
        if cell == "same as float64":
            expected = call(env, np.array(value, dtype=np.float64, order="C"))
            assert same(call(env, value), expected), (name, kind)
            if kind in ("list", "tuple", "Fortran order", "strided view"):
                assert same(expected, reference), (name, kind)  # the same values
        elif cell == "empty result":
            got = np.asarray(call(env, value))
            assert got.size == 0 and got.shape[-1] == 0, (name, kind)
        elif cell == "InputError":
            message = rf"^{re.escape(where)}: {arg} must be finite, entry 1 is nan$"
            with pytest.raises(ffsr.InputError, match=message):
                call(env, value)
        elif cell == "fault status":
            status, td, xb = call(env, value)
            assert status == "fault" and not td.any() and not xb.any()
        else:
            pytest.fail(f"docs/python.md: unknown cell {cell!r} ({name}, {kind})")


def test_no_copy_of_a_float64_c_array(env):
    # the reader takes the caller's buffer: a million-row batch is read without a second million-row array
    model = env[0]
    thetas = np.tile(theta0(), (200000, 1))
    import tracemalloc
    tracemalloc.start()
    ffsr.integrated_effective_mass_batch(model, ffsr.BasePose(), thetas, threads=2)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < thetas.nbytes / 4  # the result (200000 doubles = 1/7 of thetas), never a copy of thetas
    with pytest.raises(ffsr.InputError, match=r"thetas must be a 2-dimensional array, got 1 dimensions"):
        ffsr.integrated_effective_mass_batch(model, ffsr.BasePose(), [])
