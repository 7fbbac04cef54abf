"""Sweeps in this process and on a two-worker Dask LocalCluster against `plantwide steady --json
--set` point by point; sensitivity and screening sweeps with and without a client."""

import numpy as np
import plantwide as pw
import pytest
from conftest import COLUMN_A

OUTPUTS = ["distillate.x[light]", "bottoms.x[light]", "column.T[21]", "column.reflux"]
FEEDS = [0.96, 0.98, 1.0, 1.02, 1.04]
SETS = [{"feed_source.F": f"{f} kmol/min"} for f in FEEDS]


@pytest.fixture(scope="module")
def cli_points(cli_json):
    """The CLI's steady state at each point: the values of OUTPUTS."""
    rows = []
    for s in SETS:
        (path, value), = s.items()
        values = cli_json(["steady", COLUMN_A, "--json", "--set", f"{path}={value}"])["values"]
        rows.append([values[o] for o in OUTPUTS])
    return np.array(rows)


def test_sweep_in_process_equals_steady_set_bit_for_bit(cli_points):
    got = pw.sweep(COLUMN_A, sets=SETS, outputs=OUTPUTS)
    assert got.shape == (5, 4)
    assert np.array_equal(got, cli_points)


def test_five_point_sweep_on_a_local_cluster_equals_steady_set(cluster_client, cli_points):
    got = pw.sweep(COLUMN_A, sets=SETS, outputs=OUTPUTS, client=cluster_client)
    assert np.max(np.abs(got - cli_points)) <= 1e-10
    assert np.array_equal(got, cli_points), "bit for bit, as in process"
    # The points really moved: the sweep is not five copies of one state.
    assert len(set(got[:, 0])) == 5


def test_sensitivity_with_and_without_a_client(cluster_client, cli, tmp_path):
    disturb = ["feed_source.F=-5%:+5%", "feed_source.z[light]=0.48:0.52"]
    outputs = ["bottoms.x[light]", "distillate.x[light]"]
    here = pw.sensitivity(COLUMN_A, disturb, outputs, points=3)
    there = pw.sensitivity(COLUMN_A, disturb, outputs, points=3, client=cluster_client)
    assert [c["path"] for c in here] == ["feed_source.F", "feed_source.z[light]"]
    for a, b in zip(here, there):
        assert np.array_equal(a["values"], b["values"]) and np.array_equal(a["outputs"], b["outputs"])
    # Against the CLI's CSV of the same sweep (values printed in full precision).
    out = tmp_path / "s.csv"
    args = ["sensitivity", COLUMN_A, "--outputs", ",".join(outputs), "--points", "3", "--csv", str(out)]
    for d in disturb:
        args += ["--disturb", d]
    cli(args)
    lines = out.read_text().splitlines()[1:]
    ys = [[float(v) for v in line.split(",")[-2:]] for line in lines]
    mine = [list(y) for c in here for y in c["outputs"]]
    assert np.allclose(np.array(ys), np.array(mine), rtol=1e-12), (ys, mine)


def test_screening_with_and_without_a_client(cluster_client, cli_json):
    args = dict(column="column", outputs=["distillate.x[light]", "bottoms.x[light]"])
    sets = [{}, {"feed_source.F": "1.02 kmol/min"}]
    here = pw.screen(COLUMN_A, sets=sets, **args)
    there = pw.screen(COLUMN_A, sets=sets, client=cluster_client, **args)
    assert here == there and len(here) == 2
    cli = cli_json(["screen", COLUMN_A, "--column", "column", "--outputs", ",".join(args["outputs"]), "--steady-only", "--json"])
    assert here[0] == cli


def test_an_error_on_a_worker_reaches_the_client_as_the_same_exception(cluster_client):
    with pytest.raises(pw.InputError, match="feed_source.Fx"):
        pw.sweep(COLUMN_A, sets=[{}, {"feed_source.Fx": "1 kmol/min"}], outputs=OUTPUTS, client=cluster_client)


def test_pairing_screen_on_a_cluster_equals_the_cli(cluster_client, cli_json):
    """The dynamic tests split one shard per worker and scored together here give the CLI's
    one-process screen: three throughput choices of column A with its quality loops, all tested."""
    lv = COLUMN_A.replace("column_a.json", "column_a_lv.json")
    cvs, mvs = ["distillate.x[light]", "bottoms.x[light]"], ["column.reflux", "column.boilup", "feed_source.F"]
    opts = dict(throughput=mvs, disturbances=["feed_source.z[light]=+5%"], duration="100 min")
    there = pw.screen_pairings(lv, cvs, mvs, client=cluster_client, **opts)
    here = pw.screen_pairings(lv, cvs, mvs, **opts)
    cli = cli_json(
        ["screen", lv, "--cvs", ",".join(cvs), "--mvs", ",".join(mvs), "--throughput", ",".join(mvs),
         "--disturbances", "feed_source.z[light]=+5%", "--duration", "100 min", "--json"]
    )
    assert there == cli and here == cli
    tested = [s for s in cli["structures"] if s["dynamic"] is not None]
    assert len(tested) == 3 and sorted(s["rank"] for s in tested) == [1, 2, 3]
    # The best candidate scores 1 on the one CV pair it is best on everywhere; scores are relative.
    assert min(s["dynamic"]["score"] for s in tested) >= 1.0
