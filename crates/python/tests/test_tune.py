"""`Plant.tune` against `plantwide tune FILE --json`: the same request gives the same JSON bit for
bit, the same report folder and the same written flowsheet; refusals name the request's field;
loops whose margins refute their settings raise `ConvergenceError` with the result kept."""

import json

import pytest

import plantwide as pw
from conftest import REPO

COLUMN = str(REPO / "flowsheets" / "column_a_lv.json")
SURGE = str(REPO / "flowsheets" / "surge_tank_pi.json")
TL = ["--method", "tl", "--measurement-dead-time", "1.5 min", "--time-unit", "min"]


@pytest.fixture(scope="module")
def column():
    return pw.load(COLUMN)


def test_loops_tuned_in_sequence_equal_the_cli_bit_for_bit(column, cli):
    mine = column.tune(
        ["top_composition", "bottom_composition"], "tl", measurement_dead_time="1.5 min", time_unit="min"
    )
    theirs = json.loads(cli(["tune", COLUMN, "--loops", "top_composition,bottom_composition", *TL, "--json"]).stdout)
    assert mine == theirs
    # Tyreus–Luyben from the relay's ultimate gain and period: Kc = Ku/3.2, τI = 2.2 Pu.
    for loop in mine["loops"]:
        assert loop["kc"] == pytest.approx(loop["ku"] / 3.2, rel=1e-12)
        assert loop["tau_i"] == pytest.approx(2.2 * loop["pu"], rel=1e-12)


def test_the_report_and_the_written_flowsheet_are_the_clis(column, cli, tmp_path):
    column.tune("top_composition", "tl", measurement_dead_time="1.5 min", time_unit="min",
                report=tmp_path / "py", write=tmp_path / "py.json")
    cli(["tune", COLUMN, "--loop", "top_composition", *TL, "--report", str(tmp_path / "cli"),
         "--write", str(tmp_path / "cli.json")])
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == ["tune.html", "tune.json", "tune.md", "tune.svg"]
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert (tmp_path / "py.json").read_bytes() != open(COLUMN, "rb").read()


def test_a_step_fit_of_a_level_equals_the_cli(cli):
    mine = pw.load(SURGE).tune("lc", "simc", scan="10 s", tau_c="10 min")
    args = ["tune", SURGE, "--loop", "lc", "--method", "simc", "--scan", "10 s", "--tau-c", "10 min", "--json"]
    assert mine == json.loads(cli(args).stdout)
    assert mine["loops"][0]["fit"]["model"]["type"] == "integrating"


def test_refusals_name_the_request_field(column):
    with pytest.raises(pw.InputError, match=r"^scan 3 kg: "):
        column.tune("top_composition", "tl", scan="3 kg")
    with pytest.raises(pw.InputError, match=r"^time_unit kg: not a unit of time"):
        column.tune("top_composition", "tl", time_unit="kg")
    with pytest.raises(pw.InputError, match=r"^loops: `top_composition` is given twice"):
        column.tune(["top_composition", "top_composition"], "blt")
    with pytest.raises(pw.InputError, match="unknown variant `fast`"):
        column.tune("top_composition", "fast")
    with pytest.raises(pw.InputError, match="no PID controller `nowhere`"):
        column.tune("nowhere", "tl")


def test_settings_their_margins_refute_raise_with_the_result_kept(cli, tmp_path):
    # The generator's lag-dominant distillate loop (tests/it/tune.rs): SIMC's settings at the τc
    # asked for have a negative phase margin on the plant's linear model; the CLI exits 2 and
    # writes nothing.
    plant = str(REPO / "tests" / "data" / "generated" / "rigorous_dc13c1b0.json")
    args = ["tune", plant, "--loop", "AC101", "--method", "simc", "--set", "AC102.auto=0", "--tau-c", "1 min"]
    p = cli([*args, "--measurement-dead-time", "1 min", "--json", "--write", str(tmp_path / "cli.json")], check=False)
    assert p.returncode == 2, p.stderr
    with pytest.raises(pw.ConvergenceError) as raised:
        pw.load(plant).tune("AC101", "simc", measurement_dead_time="1 min", tau_c="1 min", set={"AC102.auto": 0},
                            write=tmp_path / "py.json")
    assert str(raised.value).endswith("nothing written")
    assert str(raised.value) in p.stderr
    assert raised.value.result == json.loads(p.stdout)
    assert not (tmp_path / "py.json").exists() and not (tmp_path / "cli.json").exists()
