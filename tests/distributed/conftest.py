"""A LocalCluster of 2 worker processes on loopback, shared by the tests of a module,
and the cloudgen_dask package of this checkout on sys.path."""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "distributed"))
sys.path.insert(0, str(ROOT / "tests"))
CLI = ROOT / "build" / "bin" / "cloudgen"

if not CLI.is_file():
    pytest.skip("build/bin/cloudgen not built", allow_module_level=True)
dask_distributed = pytest.importorskip("dask.distributed")


@pytest.fixture(scope="module")
def client():
    cluster = dask_distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                            dashboard_address=None, host="127.0.0.1",
                                            env={"PYTHONPATH": str(ROOT / "distributed")})
    c = dask_distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()
