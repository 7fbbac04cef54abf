"""`Plant.identify` against `plantwide identify --json`: the same request gives the same JSON bit
for bit and the same report folder (the step model with it); a model the verdict finds not usable
raises `ConvergenceError` with the CLI's message and the result kept; refusals name the field."""

import json

import pytest

import plantwide as pw
from conftest import REPO

COLUMN = str(REPO / "flowsheets" / "column_a.json")
INPUTS = ["column.reflux@kmol/min", "column.boilup@kmol/min"]
OUTPUTS = ["column.x[41][light]", "column.x[1][light]"]
ARGS = ["--inputs", ",".join(INPUTS), "--outputs", ",".join(OUTPUTS)]


@pytest.fixture(scope="module")
def column():
    return pw.load(COLUMN)


def test_an_identification_equals_the_cli_bit_for_bit_with_its_report(column, cli, tmp_path):
    kw = {"noise": 1e-4, "amplitude": 0.02, "duration": "16300 min"}
    mine = column.identify(INPUTS, OUTPUTS, **kw, report=tmp_path / "py")
    extra = ["--noise", "1e-4", "--amplitude", "0.02", "--duration", "16300 min", "--json"]
    p = cli(["identify", COLUMN, *ARGS, *extra, "--report", str(tmp_path / "cli")])
    assert mine == json.loads(p.stdout)
    assert mine["verdict"]["reliable"]
    names = sorted(f.name for f in (tmp_path / "cli").iterdir())
    assert "step_model.json" in names and "validation.png" in names
    assert sorted(f.name for f in (tmp_path / "py").iterdir()) == names
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # The identified gains against the exact linearization the same JSON carries (the verdict's
    # 20 % on each element; tests/it/identify.rs holds the published ones).
    for row, exact in zip(mine["gain"], mine["exact"]["gain"]):
        for g, e in zip(row, exact):
            assert abs(g - e) <= 0.2 * abs(e)


def test_a_model_lost_in_noise_raises_with_the_clis_message(column, cli, tmp_path):
    p = cli(["identify", COLUMN, *ARGS, "--noise", "1000", "--json", "--report", str(tmp_path / "cli")], check=False)
    assert p.returncode == 2
    with pytest.raises(pw.ConvergenceError) as raised:
        column.identify(INPUTS, OUTPUTS, noise=1000, report=tmp_path / "py")
    assert str(raised.value) in p.stderr
    assert "step_model.json not written" in str(raised.value)
    assert raised.value.result == json.loads(p.stdout)
    assert not (tmp_path / "py" / "step_model.json").exists()


def test_refusals_name_the_request_field(column):
    with pytest.raises(pw.InputError, match=r"`noise` gives 3 values for 2 outputs"):
        column.identify(INPUTS, OUTPUTS, noise=[1e-4, 1e-4, 1e-4])
    with pytest.raises(pw.InputError, match=r"`duration` 3 kg: "):
        column.identify(INPUTS, OUTPUTS, duration="3 kg")
    with pytest.raises(pw.InputError, match="unknown variant `chirp`"):
        column.identify(INPUTS, OUTPUTS, design="chirp")
