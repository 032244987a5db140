import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


def fmu_path(name):
    d = pathlib.Path(os.environ.get("YARNSIM_FMU_DIR", ROOT / "target" / "fmu"))
    p = d / name
    if not p.is_file():
        pytest.fail(f"{p} is missing: build it first (bash tools/fmu/fmu_check.sh builds it; YARNSIM_FMU_DIR points elsewhere)")
    return str(p)


@pytest.fixture(scope="session")
def small_fmu():
    return fmu_path("YarnBundle-small.fmu")


@pytest.fixture(scope="session")
def wire_fmu():
    return fmu_path("MassSpring-wire.fmu")


def make_cluster():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                           env={"RAYON_NUM_THREADS": "1"}, silence_logs=40)
    return Client(cluster, set_as_default=False)


@pytest.fixture(scope="session")
def client():
    c = make_cluster()
    yield c
    cluster = c.cluster
    c.close()
    cluster.close()


@pytest.fixture
def write_sweep(tmp_path):
    def write(text, name="sweep.toml"):
        p = tmp_path / name
        p.write_text(text)
        return str(p)

    return write
