"""Steady states from Python against `plantwide steady --json` (bit for bit) and conservation."""

import plantwide as pw
import pytest
from conftest import COLUMN_A


def cli_values(cli_json, sets=(), method="auto"):
    args = ["steady", COLUMN_A, "--json", "--method", method]
    for s in sets:
        args += ["--set", s]
    return cli_json(args)


@pytest.mark.parametrize("sets", [{}, {"feed_source.F": "1.01 kmol/min", "column.reflux": "2.75 kmol/min"}])
def test_steady_equals_the_cli_bit_for_bit(cli_json, sets):
    plant = pw.load(COLUMN_A)
    ss = plant.steady(set=sets)
    cli = cli_values(cli_json, [f"{k}={v}" for k, v in sets.items()])
    assert ss.to_dict() == cli["values"]  # every path, every bit
    assert ss.warnings == [w["message"] for w in cli["warnings"]]


def test_numbers_are_si_and_exact(cli_json):
    np = pytest.importorskip("numpy")
    reflux = 2.75 * 1000 / 60  # mol/s
    plant = pw.load(COLUMN_A)
    a = plant.steady(set={"column.reflux": reflux}).to_dict()
    assert a == plant.steady(set={"column.reflux": np.float64(reflux)}).to_dict()
    assert a == cli_values(cli_json, [f"column.reflux={reflux!r}"])["values"]


def test_methods_are_the_cli_methods(cli_json):
    plant = pw.load(COLUMN_A)
    for method in ["eo", "sm"]:
        assert plant.steady(method=method).to_dict() == cli_values(cli_json, method=method)["values"]


def test_column_a_published_compositions_and_balances():
    ss = pw.load(COLUMN_A).steady()
    # S&P §12.4: yD = 0.99, xB = 0.01 at the file's L and V.
    assert abs(ss["distillate.x[light]"] - 0.99) < 1e-3
    assert abs(ss["bottoms.x[light]"] - 0.01) < 1e-3
    # Conservation, total and light component: F = D + B, F z = D yD + B xB.
    f, d, b = ss["feed.F"], ss["distillate.F"], ss["bottoms.F"]
    assert abs(f - d - b) < 1e-9 * f
    light = f * ss["feed.x[light]"] - d * ss["distillate.x[light]"] - b * ss["bottoms.x[light]"]
    assert abs(light) < 1e-9 * f


def test_steady_state_is_a_read_only_mapping():
    ss = pw.load(COLUMN_A).steady()
    assert isinstance(ss["column.reflux"], float) and "feed.F" in ss and len(ss) == len(ss.to_dict())
    with pytest.raises(KeyError, match="not a variable"):
        ss["no.such"]
    with pytest.raises(TypeError):
        ss["feed.F"] = 1.0


def test_equation_units_and_tags_from_python(cli_json):
    """A unit written as equations and a tag are plain variables to Python: the same values as the
    CLI, bit for bit, and the same steady state as the built-in CSTR they rewrite (issue 57)."""
    from conftest import REPO

    eq = str(REPO / "tests" / "data" / "cstr_equations.json")
    ss = pw.load(eq).steady().to_dict()
    assert ss == cli_json(["steady", eq, "--json"])["values"]
    builtin = pw.load(str(REPO / "flowsheets" / "cstr_multiplicity.json")).steady().to_dict()
    assert abs(ss["effluent.T"] - builtin["effluent.T"]) <= 1e-10 * builtin["effluent.T"]
    tagged = str(REPO / "tests" / "data" / "column_a_tags.json")
    t = pw.load(tagged).steady().to_dict()
    assert t["cost.value"] == cli_json(["steady", tagged, "--json"])["values"]["cost.value"]
    assert abs(t["impurity.value"] - (t["column.x[41][heavy]"] + t["column.x[1][light]"])) <= 1e-15
