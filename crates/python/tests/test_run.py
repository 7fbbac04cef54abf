"""Runs from Python: the CLI's trends, and the end of a long step at the new steady state."""

import csv

import numpy as np
import plantwide as pw
import pytest
from conftest import COLUMN_A, REPO

SCENARIO = str(REPO / "flowsheets" / "scenarios" / "column_a_feed_step.json")


@pytest.fixture(scope="module")
def trends():
    return pw.load(COLUMN_A).run(SCENARIO)


def test_run_is_a_frame_of_si_trends(trends):
    pd = pytest.importorskip("pandas")
    assert isinstance(trends, pd.DataFrame)
    assert "bottoms.x[light]" in trends.columns and trends.index.name == "time"
    assert trends.index[0] == 0.0 and abs(trends.index[-1] - 2000 * 60) < 1e-6
    assert trends.attrs["units"]["distillate.F"] == "mol/s"


def test_run_equals_the_cli_csv(trends, cli, tmp_path):
    out = tmp_path / "run.csv"
    cli(["run", COLUMN_A, "--scenario", SCENARIO, "--csv", str(out)])
    with open(out) as f:
        rows = list(csv.reader(f))
    head = rows[0]
    data = np.array(rows[1:], dtype=float)
    # The CSV is in the scenario's units: time in min, flows in kmol/min (1 kmol/min = 1000/60 mol/s).
    assert np.allclose(data[:, 0] * 60.0, trends.index.to_numpy(), rtol=1e-12)
    col = next(k for k, h in enumerate(head) if h.startswith("bottoms.x[light]"))
    assert np.allclose(data[:, col], trends["bottoms.x[light]"].to_numpy(), rtol=1e-9, atol=1e-12)
    col = next(k for k, h in enumerate(head) if h.startswith("distillate.F"))
    assert np.allclose(data[:, col] * 1000 / 60, trends["distillate.F"].to_numpy(), rtol=1e-9)


def test_a_long_step_ends_at_the_new_steady_state(trends):
    # 2000 min ≈ 10 time constants (τ ≈ 194 min): within 1e-3 of the change of the steady state.
    plant = pw.load(COLUMN_A)
    before, after = plant.steady(), plant.steady(set={"feed_source.F": "1.01 kmol/min"})
    for path in ["bottoms.x[light]", "distillate.x[light]"]:
        change = after[path] - before[path]
        assert abs(trends[path].iloc[-1] - after[path]) < 1e-3 * abs(change), path
