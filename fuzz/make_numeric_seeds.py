#!/usr/bin/env python3
"""Writes the seed corpus of fuzz_numeric (fuzz/corpus/fuzz_numeric/): the paper's values in the
input layout of fuzz/numeric_check.hpp (a selector byte, then 8-byte little-endian doubles and bytes)."""
import math, os, struct, sys

out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "corpus", "fuzz_numeric")
os.makedirs(out, exist_ok=True)
d = lambda *xs: b"".join(struct.pack("<d", x) for x in xs)
deg = math.pi / 180
theta3 = d(0, 150 * deg, -100 * deg)
theta7 = d(0, 90 * deg, 90 * deg, -90 * deg, 90 * deg, 90 * deg, 0)
base = d(0, 0, 0, 1, 0, 0, 0)
target = d(200, 100, 100, 100, 0, 0, 0, 1, 0, 0, 0, -0.25, 0.15, 0, 1, 0, 0)
motion = d(2.75, 1.45, 0, 0, 0, 0, 0, 0, 2 * deg)
params = d(1e9, 1.5, 0.9)
seeds = {
    # 0: effective mass at the paper's 3-DOF configuration (Table 3: M_ie 5.8158 kg), frame byte 0
    "em_3dof": bytes([0]) + theta3 + base + target + bytes([0]) + d(1, 0, 0, 5.8),
    "em_7dof": bytes([4]) + theta7 + base + target + bytes([0]) + d(1, 0, 0, 5.8),
    # 1: the contact law (herbert-mcwhannell = index 1), Table 3's approach velocity and M_ie
    "law_hm": bytes([1, 1]) + params + d(0.2052, 5.8158, 1e-4, 0.1, 1840, 1851),
    "law_hc_cr1": bytes([1, 0]) + d(1e9, 1.5, 1.0) + d(0.2, 5.0, 1e-4, -0.1, 1000, 1000),
    "law_flores_soft": bytes([1, 4]) + d(1e5, 1.0, 0.05) + d(0.01, 1e6, 1e-2, 0.001, 1, 2),
    # 2: multibody contact (CVODE)
    "sim_3dof": bytes([2]) + theta3 + base + target + motion + d(0.2) + params + bytes([1, 2]) + d(0),
    "sim_7dof": bytes([6]) + theta7 + base + target + motion + d(0.2) + params + bytes([1, 3]) + d(0),
    # 3: the planner, 2 s, step 0.2 s
    "plan_3dof": bytes([3]) + theta3 + base + target + d(0.6, 1.2, 0, 0, 0, 0, 0, 0, 2 * deg) + params + bytes([1])
                 + d(0.2) + bytes([0x03]) + d(2, 0.2, -0.01, 1, 1e-3),
    "plan_7dof_pose": bytes([7]) + theta7 + base + target + d(1.0, -0.5, 1.2, 0, 0, 0, 1 * deg, -0.5 * deg, 2 * deg)
                      + params + bytes([1]) + d(0.2) + bytes([0x10]) + d(2, 0.2, -0.2, 1, 1e-3),
    "plan_7dof_position": bytes([7]) + theta7 + base + target + d(1.0, -0.5, 1.2, 0, 0, 0, 0, 0, 0) + params
                          + bytes([1]) + d(0.2) + bytes([0x07]) + d(2, 0.2, -0.01, 1, 1e-3),
}
for name, data in seeds.items():
    with open(os.path.join(out, name), "wb") as f:
        f.write(data)
