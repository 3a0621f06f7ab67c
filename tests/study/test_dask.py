"""A small sweep through a real dask.distributed.LocalCluster."""

import pytest

distributed = pytest.importorskip("dask.distributed")

from grainlab.study import read_table, run_sweep  # noqa: E402 - after the skip

PLAN = """
base = "packing"
mode = "zip"
seed = 1
[fixed]
width = 0.02
height = 0.04
[vary]
kind = ["hexagonal", "irregular", "irregular"]
porosity = [0.12, 0.18, 2.0]
"""


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.filterwarnings("ignore::ResourceWarning")
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_sweep_on_local_cluster(tmp_path):
    from grainlab.study.plan import parse_plan

    with pytest.raises(ValueError, match="vary.porosity"):
        parse_plan(PLAN)  # the out-of-range value is caught before anything runs
    plan = parse_plan(PLAN.replace("2.0]", "0.2]"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        result = run_sweep(plan, tmp_path, scheduler=cluster.scheduler_address, progress=False)
        assert result.failed == []
        rows = read_table(tmp_path / "sweep.csv")
        assert [r["name"] for r in rows] == ["run_0000", "run_0001", "run_0002"]
        assert [r["kind"] for r in rows] == ["hexagonal", "irregular", "irregular"]
        assert all((tmp_path / "runs" / r["name"] / "result.json").exists() for r in rows)
        # resumed on the cluster: nothing left to do
        again = run_sweep(plan, tmp_path, scheduler=cluster.scheduler_address, progress=False)
        assert sorted(again.skipped) == ["run_0000", "run_0001", "run_0002"] and again.executed == []


LAB_PLANS = {
    "oedometer": {"oedometer.vertical_stresses": '["200 kPa", "100 kPa"]'},
    "cyclic": {"cyclic.cycles": "1", "cyclic.strain_amplitude": "0.002"},
    "simple_shear": {"simple_shear.final_strain": "0.1", "simple_shear.record_interval": "0.05",
                     "simple_shear.snapshot_strains": "[0, 0.1]", "simple_shear.inertial_number": "0.01"},
}


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.filterwarnings("ignore::ResourceWarning")
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_the_labs_tests_sweep_on_a_local_cluster(tmp_path):
    """The oedometer, the cyclic test and simple shear each run as a sweep on the cluster,
    each to its summary, as on a local pool."""
    import json

    from grainlab.study.plan import parse_plan

    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        for protocol, keys in LAB_PLANS.items():
            fixed = "\n".join(f'"{k}" = {v}' for k, v in {**keys, "run.threads": "1"}.items())
            plan = parse_plan(f'base = "{protocol}"\nmode = "zip"\nseed = 1\nquick = true\n[fixed]\n{fixed}\n'
                              '[vary]\n"sample.seed" = [1, 2]\n')
            out = tmp_path / protocol
            result = run_sweep(plan, out, scheduler=cluster.scheduler_address, progress=False)
            assert result.failed == [], protocol
            rows = read_table(out / "sweep.csv")
            assert [r["status"] for r in rows] == ["ok", "ok"], rows
            for r in rows:
                summary = json.loads((out / "runs" / r["name"] / protocol / "summary.json").read_text())
                assert summary["n_particles"] > 200
