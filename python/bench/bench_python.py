"""The Python side's speed, one process: ffsr.integrated_effective_mass on the paper's 7-DOF robot,
median per call from Python, beside

  - the same value computed with Pinocchio from Python (pin.crba, pin.computeFrameJacobian, numpy's
    solve): the ratio ffsr / pin (target: at most 0.3);
  - the same call from C++ in this process (timed as bench/bench_main.cpp times it): the overhead of
    the binding per call (target: below 1 us);

and the batch call ffsr.integrated_effective_mass_batch on 1e5 configurations against a Python loop
over the single call, per configuration (target: at least 20x), with one thread and with one per core.

The single calls run pinned to one core (os.sched_setaffinity). Each timing is the median of 31
batches of calls, a batch lasting about 5 ms, over 1000 random configurations (fixed seed) cycled.
Run it as
    build-python/venv/bin/python python/bench/bench_python.py
It prints a table and never fails: a benchmark, not a test.
"""

import os
import pathlib
import statistics
import sys
import time

import numpy as np

import ffsr

try:
    import pinocchio as pin
except ImportError:  # the reference is a test requirement (scripts/install-python.sh installs it)
    pin = None

ROBOTS = pathlib.Path(__file__).resolve().parents[2] / "robots"
BATCHES, BATCH_SECONDS = 31, 5e-3


def median_per_call(fn, configs):
    """Median over BATCHES batches of the mean time per call of fn(config), configs cycled."""
    m = len(configs)
    n = 1
    while True:  # calibrate the calls per batch
        t0 = time.perf_counter()
        for i in range(n):
            fn(configs[i % m])
        dt = time.perf_counter() - t0
        if dt >= 0.2 * BATCH_SECONDS:
            n = max(1, round(n * BATCH_SECONDS / dt))
            break
        n *= 4
    per_call = []
    for _ in range(BATCHES):
        t0 = time.perf_counter()
        for i in range(n):
            fn(configs[i % m])
        per_call.append((time.perf_counter() - t0) / n)
    return statistics.median(per_call)


def main():
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    urdf = str(ROBOTS / "paper_7dof.urdf")
    model = ffsr.Model.from_urdf(urdf)
    data = ffsr.Data(model)
    base = ffsr.BasePose()
    target = ffsr.Target()
    rng = np.random.default_rng(1)
    thetas = rng.uniform(-np.pi, np.pi, (1000, model.n))
    configs = list(thetas)  # rows: contiguous float64 views

    t_ffsr = median_per_call(lambda th: ffsr.integrated_effective_mass(model, data, base, th, None, target), configs)
    t_cpp = ffsr._ffsr._time_cpp_integrated_effective_mass(model, data, base, thetas, target, BATCHES, BATCH_SECONDS)
    print(f"{'7-DOF M_ie (Eq. 14), one call':44s} {'median per call':>16s}")
    print(f"{'ffsr from C++ (this process)':44s} {t_cpp * 1e6:13.3f} us")
    print(f"{'ffsr.integrated_effective_mass from Python':44s} {t_ffsr * 1e6:13.3f} us"
          f"   binding overhead {(t_ffsr - t_cpp) * 1e6:.3f} us (target < 1 us)")

    if pin is not None:
        pm = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
        pd = pm.createData()
        fid = pm.getFrameId(model.frame_names[model.end_effector])
        u = target.normal_world()
        inv_t = target.inverse_mass_along_normal()
        lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        def pin_q(theta):  # the same configuration in Pinocchio's q (continuous joints as cos, sin)
            q = pin.neutral(pm)
            for k, name in enumerate(model.joint_names):
                j = pm.joints[pm.getJointId(name)]
                if j.nq == 2:
                    q[j.idx_q:j.idx_q + 2] = [np.cos(theta[k]), np.sin(theta[k])]
                else:
                    q[j.idx_q] = theta[k]
            return q

        qs = [pin_q(th) for th in thetas]

        def pin_mie(q):
            M = pin.crba(pm, pd, q)
            M = np.triu(M) + np.triu(M, 1).T  # Pinocchio fills the upper triangle
            Jv = pin.computeFrameJacobian(pm, pd, q, fid, lwa)[:3]
            w = Jv.T @ u
            return 1.0 / (w @ np.linalg.solve(M, w) + inv_t)

        # the same numbers first (the bench compares like with like)
        for q, th in zip(qs[:20], configs[:20]):
            a, b = pin_mie(q), ffsr.integrated_effective_mass(model, data, base, th, None, target)
            assert abs(a - b) < 1e-10 * b, (a, b)
        t_pin = median_per_call(pin_mie, qs)
        print(f"{'pin from Python (crba, frame Jacobian, solve)':44s} {t_pin * 1e6:13.3f} us"
              f"   ffsr / pin = {t_ffsr / t_pin:.3f} (target <= 0.3)")
    else:
        print("pin is not installed: no Pinocchio comparison (scripts/install-python.sh installs it)")

    # the batch against a Python loop over the single call, per configuration
    big = rng.uniform(-np.pi, np.pi, (100_000, model.n))
    rows = list(big)
    t0 = time.perf_counter()
    loop = [ffsr.integrated_effective_mass(model, data, base, th, None, target) for th in rows]
    t_loop = (time.perf_counter() - t0) / len(rows)
    print(f"\n{'1e5 configurations':44s} {'per configuration':>16s}")
    print(f"{'Python loop over the single call':44s} {t_loop * 1e6:13.3f} us")
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, set(range(os.cpu_count() or 1)))
    for threads in (1, 0):
        times = []
        for _ in range(5):
            t0 = time.perf_counter()
            batch = ffsr.integrated_effective_mass_batch(model, base, big, None, target, threads=threads)
            times.append((time.perf_counter() - t0) / len(rows))
        t_batch = statistics.median(times)
        assert np.max(np.abs(batch - loop) / np.asarray(loop)) < 1e-12
        label = "one thread" if threads == 1 else f"{os.cpu_count()} threads"
        print(f"{'integrated_effective_mass_batch, ' + label:44s} {t_batch * 1e6:13.3f} us"
              f"   loop / batch = {t_loop / t_batch:.1f}x (target >= 20x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
