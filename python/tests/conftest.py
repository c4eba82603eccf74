"""Shared fixtures of the Python tests: the repository's paths, the paper's robots, the URDF samples."""

import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
ROBOTS = REPO / "robots"
# FFSR_URDF_SAMPLES names another folder (as for the C++ tests)
SAMPLES = pathlib.Path(os.environ.get("FFSR_URDF_SAMPLES", REPO.parent / "shared" / "urdf-samples"))


@pytest.fixture(scope="session")
def robots_dir():
    return ROBOTS


def samples_dir_or_skip():
    """The URDF samples (../shared/urdf-samples beside the repository), or a skip that says where."""
    if not (SAMPLES / "panda.urdf").exists():
        pytest.skip(f"the URDF samples are not in {SAMPLES} (set FFSR_URDF_SAMPLES)")
    return SAMPLES
