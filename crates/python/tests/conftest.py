"""Shared fixtures: the repository, the CLI binary (the independent face the Python results are
checked against) and a two-worker Dask cluster."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
COLUMN_A = str(REPO / "flowsheets" / "column_a.json")
LV_INPUTS = ["column.reflux@kmol/min", "column.boilup@kmol/min"]
LV_OUTPUTS = ["distillate.x[light]", "bottoms.x[light]"]


def _binary() -> str:
    """`PLANTWIDE_BIN`, else the workspace's debug build (built here if missing)."""
    if os.environ.get("PLANTWIDE_BIN"):
        return os.environ["PLANTWIDE_BIN"]
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    binary = target / "debug" / "plantwide"
    if not binary.exists():
        subprocess.run(["cargo", "build", "--bin", "plantwide"], cwd=REPO, check=True)
    return str(binary)


@pytest.fixture(scope="session")
def cli():
    """Run the CLI; `cli(args)` returns the completed process (text)."""
    binary = _binary()

    def run(args, check=True):
        p = subprocess.run([binary, *args], capture_output=True, text=True, cwd=REPO)
        if check and p.returncode != 0:
            raise AssertionError(f"plantwide {' '.join(args)} exited {p.returncode}: {p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    """Run the CLI and parse its JSON output."""
    return lambda args: json.loads(cli(args).stdout)


@pytest.fixture(scope="session")
def cluster_client():
    """A LocalCluster of two single-threaded worker processes."""
    distributed = pytest.importorskip("dask.distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()
