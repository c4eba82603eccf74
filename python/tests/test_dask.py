"""Studies on Dask: a map and a Monte Carlo run (the job robust) cut into shards that run on the workers of
a dask.distributed LocalCluster (two worker processes of one thread each), merged with ffsr.studies as
the command merges its shards, equal to one run in this process to the bit (bytes of the arrays, == on
the JSON). A Slurm or Kubernetes cluster changes only the cluster object (docs/python.md).
"""

import json
import logging
import subprocess

import numpy as np
import pytest
from dask.distributed import Client, LocalCluster

import ffsr
from conftest import ROBOTS
from ffsr import studies
from test_jobs import command

MAP_SCENARIO = ROBOTS / "paper_7dof_position.toml"
MAP = dict(range_deg=[-180, 180], step_deg=[12])  # joints 2 and 4: 30 x 30 points
ROBUST_SCENARIO = ROBOTS / "paper_7dof_position_uncertain.toml"
ROBUST = dict(samples=61, seed=7)  # 61 samples: the shards are not all of one size
NO_GLOBAL = {"global": False}  # the plain and the paper's runs: planned in about a second


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    # on the loopback address only; the scheduler's HTTP server on a free port, not 8787
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address="127.0.0.1:0",
                      local_directory=str(tmp_path_factory.mktemp("dask")),
                      silence_logs=logging.ERROR) as cluster:
        with Client(cluster) as c:
            c.wait_for_workers(2)
            yield c


def workers_used(client, futures):
    """The addresses of the workers that computed the futures."""
    return {w for held in client.who_has(futures).values() for w in held}


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def test_map_shards_on_workers_merge_to_one_run(client):
    n = 7  # 900 points in 7 parts: the first 4 hold 129 points, the other 3 hold 128
    futures = [client.submit(studies.map_shard, str(MAP_SCENARIO), [2, 4], k, n, pure=False, **MAP)
               for k in range(n)]
    parts = client.gather(futures)
    assert len(workers_used(client, futures)) == 2
    assert [p.end - p.first for p in parts] == [129] * 4 + [128] * 3
    merged = studies.merge_map(reversed(parts))  # any order
    one = ffsr.Scenario.load(str(MAP_SCENARIO)).map([2, 4], threads=2, **MAP)
    for name in ("angles_deg", "M_ie", "f_max"):
        assert same_bits(getattr(merged, name), np.asarray(getattr(one, name))), name
    assert merged.summary == one.to_dict()
    assert (merged.first, merged.end, merged.points) == (0, 900, 900)


def test_map_merge_refuses_gaps_overlaps_and_other_grids():
    parts = [studies.map_shard(MAP_SCENARIO, [2, 4], k, 3, **MAP) for k in range(3)]
    with pytest.raises(ValueError, match="merge_map: points 300 to 600 are missing"):
        studies.merge_map([parts[0], parts[2]])
    with pytest.raises(ValueError, match="merge_map: points 300 to 600 are in two parts"):
        studies.merge_map([parts[0], parts[1], parts[1], parts[2]])
    with pytest.raises(ValueError, match="merge_map: the parts cover points 0 to 600 of 900"):
        studies.merge_map(parts[:2])
    moved = {"joints_deg": [0, 90, 90, -90, 90, 90, 10]}
    other = studies.map_shard(MAP_SCENARIO, [2, 4], 2, 3, overrides=moved, **MAP)
    with pytest.raises(ValueError, match="merge_map: the parts differ in 'joints_deg'"):
        studies.merge_map(parts[:2] + [other])
    with pytest.raises(ValueError, match="merge_map: no part to merge"):
        studies.merge_map([])


@pytest.fixture(scope="module")
def robust_runs(client):
    """Three shards of the Monte Carlo run on the workers (their --json texts) and the run in one piece."""
    n = 3
    futures = [client.submit(studies.robust_shard, str(ROBUST_SCENARIO), k, n, overrides=NO_GLOBAL,
                             pure=False, **ROBUST) for k in range(n)]
    parts = client.gather(futures)
    assert len(workers_used(client, futures)) == 2
    one = ffsr.Scenario.load(str(ROBUST_SCENARIO), **NO_GLOBAL).robust(threads=2, **ROBUST)
    return parts, one


def test_robust_shards_hold_the_samples_of_one_run(robust_runs):
    """Without the command: each shard's samples are those of one run at the same indices."""
    import json

    parts, one = robust_runs
    shards = [json.loads(p) for p in parts]
    whole = one.to_dict()
    assert [(s["shard"]["first"], s["shard"]["end"]) for s in shards] == [(0, 20), (20, 40), (40, 61)]
    assert whole["estimator"] == "stiffness-conditional"
    for key in ("stiffness", "exponent"):
        assert sum((s[key] for s in shards), []) == whole[key]
    for c, config in enumerate(one.configurations):
        f = np.array(sum((s["configurations"][c]["f_max"] for s in shards), []))
        assert same_bits(f, np.asarray(config.f_max)), config.name


def test_robust_shards_merged_equal_one_run(robust_runs, tmp_path):
    """The shards merged in this process (the library's merge): the JSON of one run, but for the record
    of the shard (merged_from); and the same JSON as ffsr-optimize robust --merge makes of them."""
    parts, one = robust_runs
    merged = studies.merge_robust(list(reversed(parts)))
    files = []
    for i, text in enumerate(parts):
        files.append(tmp_path / f"shard{i}.json")
        files[-1].write_text(text)
    out = tmp_path / "merged.json"
    subprocess.run([command(), "robust", "--merge", *map(str, files), "--json", str(out), "--quiet"],
                   check=True)
    assert json.loads(out.read_text()) == merged  # the command's merge, to the bit
    whole = one.to_dict()
    assert merged.pop("shard") == {"k": 0, "n": 1, "first": 0, "end": 61, "merged_from": 3}
    assert whole.pop("shard") == {"k": 0, "n": 1, "first": 0, "end": 61}
    assert merged == whole  # every double bit for bit: the percentiles, the mean, the tails
    with pytest.raises(ffsr.InputError, match="merge_robust: .*samples 20 to 40 are missing"):
        studies.merge_robust([parts[0], parts[2]])


def test_merge_robust_names_what_it_lacks():
    with pytest.raises(ValueError, match="merge_robust: no shard to merge"):
        studies.merge_robust([])
    with pytest.raises(ffsr.InputError, match="merge_robust: .*part 0 is not JSON"):
        studies.merge_robust(["{not json"])
    with pytest.raises(ffsr.InputError, match="merge_robust: "):
        studies.merge_robust(['{"kind": "ffsr-robust"}'])
