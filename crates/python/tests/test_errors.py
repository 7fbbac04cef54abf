"""Library errors as Python exceptions: the class the CLI's exit code implies, the CLI's message."""

import plantwide as pw
import pytest
from conftest import COLUMN_A, LV_INPUTS, LV_OUTPUTS, REPO


def cli_message(cli, args):
    p = cli(args, check=False)
    assert p.returncode == 1, p.stderr
    return p.stderr.strip().removeprefix("error: ")


def test_exception_hierarchy():
    assert issubclass(pw.InputError, pw.PlantwideError) and issubclass(pw.ConvergenceError, pw.PlantwideError)
    assert issubclass(pw.PlantwideError, Exception)


def test_an_unknown_field_in_the_file_is_named(cli):
    broken = str(REPO / "tests" / "broken" / "unknown_unit_field.json")
    with pytest.raises(pw.InputError) as e:
        pw.load(broken)
    for fragment in ["units.h1", "unknown field `area`", "expected one of `duty`"]:
        assert fragment in str(e.value)
    assert str(e.value) == cli_message(cli, ["check", broken])


@pytest.mark.parametrize(
    "path, value",
    [("feed_source.Fx", "1 kmol/min"), ("feed_source.F", "-1 kmol/min"), ("column.reflux", "2 kelvin")],
)
def test_a_bad_set_names_the_keyword_the_cli_names_by_its_flag(cli, path, value):
    plant = pw.load(COLUMN_A)
    with pytest.raises(pw.InputError) as e:
        plant.steady(set={path: value})
    assert str(e.value).startswith(f"set {path}")
    assert "--" + str(e.value) == cli_message(cli, ["steady", COLUMN_A, "--set", f"{path}={value}"])


def test_a_bad_output_of_gains_is_named(cli):
    plant = pw.load(COLUMN_A)
    bad = ["distillate.x[lite]", LV_OUTPUTS[1]]
    with pytest.raises(pw.InputError) as e:
        plant.gains(LV_INPUTS, bad)
    assert "distillate.x[lite]" in str(e.value)
    args = ["gains", COLUMN_A, "--inputs", ",".join(LV_INPUTS), "--outputs", ",".join(bad)]
    assert str(e.value) == cli_message(cli, args)


def test_a_bad_sweep_point_is_named():
    with pytest.raises(pw.InputError, match="sweep point 1 .*feed_source.Fx"):
        pw.sweep(COLUMN_A, sets=[{}, {"feed_source.Fx": 1.0}], outputs=["bottoms.x[light]"])
    with pytest.raises(pw.InputError, match="bottoms.x\\[lite\\]"):
        pw.sweep(COLUMN_A, sets=[{}], outputs=["bottoms.x[lite]"])


def test_a_bad_method_is_an_input_error():
    plant = pw.load(COLUMN_A)
    with pytest.raises(pw.InputError, match="method `newton`"):
        plant.steady(method="newton")
    with pytest.raises(pw.InputError, match="method `exact`"):
        plant.gains(LV_INPUTS, LV_OUTPUTS, method="exact")


def test_a_bad_pairing_screen_request_names_the_field_the_cli_names_by_its_flag(cli):
    lv = COLUMN_A.replace("column_a.json", "column_a_lv.json")
    cvs, mvs = ["distillate.x[light]", "bottoms.x[light]"], ["column.reflux", "column.boilup"]
    with pytest.raises(pw.InputError) as e:
        pw.screen_pairings(lv, cvs, mvs, disturbances=["feed_source.F=ten%"])
    assert str(e.value).startswith("disturbances feed_source.F=ten%: ")
    assert "--" + str(e.value) == cli_message(
        cli, ["screen", lv, "--cvs", ",".join(cvs), "--mvs", ",".join(mvs), "--disturbances", "feed_source.F=ten%"]
    )
    with pytest.raises(pw.InputError, match="^duration soon: "):
        pw.screen_pairings(lv, cvs, mvs, disturbances=["feed_source.F"], duration="soon")
    with pytest.raises(pw.InputError, match="^mvs: `column.reflx` is no input"):
        pw.screen_pairings(lv, cvs, ["column.reflx", "column.boilup"])
