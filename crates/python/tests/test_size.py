"""`Plant.size` against `plantwide size --json`: the same request gives the same JSON bit for bit
and the same report folder, refusals name the request's field, and parts without an answer raise
`ConvergenceError` with the result kept."""

import json

import pytest

import plantwide as pw
from conftest import REPO

SURGE = str(REPO / "flowsheets" / "surge_tank_pi.json")
INFLOW_STEP = str(REPO / "flowsheets" / "scenarios" / "surge_tank_inflow_step.json")
ARGS = ["--disturbance", "F_in=+10 mol/s", "--level-band", "0.2 m", "--max-outflow-rate", "3 mol/s/min"]
REQUEST = {"disturbance": "F_in=+10 mol/s", "level_band": "0.2 m", "max_outflow_rate": "3 mol/s/min"}


@pytest.fixture(scope="module")
def tank():
    return pw.load(SURGE)


def test_a_vessels_sizing_equals_the_cli_bit_for_bit(tank, cli):
    mine = tank.size("tank", **REQUEST)
    theirs = json.loads(cli(["size", SURGE, "--vessel", "tank", *ARGS, "--json"]).stdout)
    assert mine == theirs
    # The closed form of the optimal averaging law: A = v_L Δu² / (2 r Δh), Δu = 10 mol/s.
    optimal = next(d for d in mine["designs"] if d["controller"] == "optimal")
    area = mine["liquid_molar_volume"] * 10.0**2 / (2 * (3.0 / 60.0) * 0.2)
    assert optimal["area"] == pytest.approx(area, rel=1e-9)


def test_a_ranking_and_a_scenario_equal_the_cli(tank, cli):
    mine = tank.size(candidates=["tank", "out"], **REQUEST)
    theirs = json.loads(cli(["size", SURGE, "--candidates", "tank,out", *ARGS, "--json"]).stdout)
    assert mine == theirs
    by_file = tank.size("tank", scenario=INFLOW_STEP, level_band="0.2 m", max_outflow_rate="3 mol/s/min")
    with open(INFLOW_STEP) as f:
        by_dict = tank.size("tank", scenario=json.load(f), level_band=0.2, max_outflow_rate=0.05)
    theirs = json.loads(
        cli(["size", SURGE, "--vessel", "tank", "--scenario", INFLOW_STEP, *ARGS[2:], "--json"]).stdout
    )
    assert by_file == theirs
    assert [d["area"] for d in by_dict["designs"]] == [d["area"] for d in theirs["designs"]]


def test_the_report_folder_is_the_clis(tank, cli, tmp_path):
    tank.size("tank", **REQUEST, report=tmp_path / "py", units="metric")
    cli(["--units", "metric", "size", SURGE, "--vessel", "tank", *ARGS, "--report", str(tmp_path / "cli")])
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == ["size.html", "size.json", "size.md", "size.svg"]
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == names
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert "kmol/h" in (tmp_path / "py" / "size.md").read_text()
    # A ranking's report: its bars drawn in one order on every run, so the files are equal too.
    tank.size(candidates=["tank", "out"], **REQUEST, report=tmp_path / "py_rank")
    cli(["size", SURGE, "--candidates", "tank,out", *ARGS, "--report", str(tmp_path / "cli_rank")])
    for name in names:
        assert (tmp_path / "py_rank" / name).read_bytes() == (tmp_path / "cli_rank" / name).read_bytes(), name


def test_refusals_name_the_request_field(tank):
    with pytest.raises(pw.InputError, match=r"^level_band 5 kmol/h: "):
        tank.size("tank", **{**REQUEST, "level_band": "5 kmol/h"})
    with pytest.raises(pw.InputError, match=r"^disturbance F_in ±10 %: sizing verifies one step"):
        tank.size("tank", **{**REQUEST, "disturbance": "F_in=±10%"})
    with pytest.raises(pw.InputError, match=r"^vessel is missing"):
        tank.size(**REQUEST)
    with pytest.raises(pw.InputError, match=r"^attenuation: the ratio 1.5 must lie between 0 and 1"):
        tank.size("tank", disturbance="F_in=+10 mol/s", level_band="0.2 m", attenuation=1.5, period="10 min")
    with pytest.raises(pw.InputError, match="unknown field"):
        pw._plantwide.size(tank.text, tank.file, [], json.dumps({**REQUEST, "band": 1}))


def test_parts_without_an_answer_raise_with_the_result_kept(tank, cli, tmp_path):
    # A band far too tight for a run to settle within a 1 s verification: every design's run is
    # cut short, the CLI exits 2 naming the parts, and Python raises the same message.
    args = ["size", SURGE, "--vessel", "tank", *ARGS, "--duration", "1 s", "--json"]
    p = cli(args, check=False)
    with pytest.raises(pw.ConvergenceError) as raised:
        tank.size("tank", **REQUEST, duration="1 s")
    if p.returncode == 0:
        pytest.fail("a 1 s verification was expected to leave parts without an answer")
    assert p.returncode == 2
    assert str(raised.value) in p.stderr
    assert raised.value.result == json.loads(p.stdout)
    assert raised.value.result["failed"]
