"""``Plant.optimize`` and ``Plant.select``: the same JSON as ``plantwide optimize --json`` and
``plantwide select FILE --json``, and the CLI's errors as exceptions."""

import json

import plantwide as pw
import pytest
from conftest import REPO

EVAPORATOR = str(REPO / "flowsheets" / "evaporator.json")
DISTURBANCES = ["evaporator.X1=±0.25 %", "evaporator.T1=±8 degC", "evaporator.T200=±5 degC"]
CANDIDATES = ["evaporator.F3@kg/min", "evaporator.F200@kg/min", "evaporator.T201@degC", "evaporator.P2@kPa"]
ERRORS = ["evaporator.F3=±0.494 kg/min", "evaporator.F200=±4.355 kg/min", "evaporator.T201=±1 degC",
          "evaporator.P2=±1.285 kPa"]


def test_optimize_returns_what_the_cli_prints(cli):
    got = pw.load(EVAPORATOR).optimize()
    printed = json.loads(cli(["optimize", EVAPORATOR, "--json"]).stdout)
    assert got == printed
    assert sorted(got["active"]) == ["evaporator.P100:max", "evaporator.X2:min"]
    assert abs(got["objective"] + 582.2330795577536) < 1e-6


def test_optimize_keywords_are_the_cli_flags(cli):
    plant = pw.load(EVAPORATOR)
    got = plant.optimize(constraints={"evaporator.P2": {"max": "50 kPa"}})
    printed = json.loads(cli(["optimize", EVAPORATOR, "--constraint", "evaporator.P2=:50 kPa", "--json"]).stdout)
    assert got == printed
    assert "evaporator.P2:max" in got["active"]
    with pytest.raises(pw.InputError, match="optimization.vary.evaporator.F9"):
        plant.optimize(vary=["evaporator.F9"])
    with pytest.raises(pw.ConvergenceError, match="no feasible point"):
        plant.optimize(constraints={"evaporator.T201": {"max": "26 degC"}})


def test_select_on_the_plant_returns_what_the_cli_prints(cli):
    got = pw.load(EVAPORATOR).select(DISTURBANCES, CANDIDATES, ERRORS, 2, best=2)
    printed = json.loads(cli(["select", EVAPORATOR, "--disturbances", ",".join(DISTURBANCES),
                              "--candidates", ",".join(CANDIDATES), "--errors", ",".join(ERRORS),
                              "--size", "2", "--best", "2", "--json"]).stdout)
    assert got == printed
    assert got["subsets"][0]["measurements"] == ["evaporator.F3@kg/min", "evaporator.F200@kg/min"]
    assert all(p["loss"] is not None for s in got["subsets"] for p in s["nonlinear"])


def test_select_keywords_pose_the_problem_as_the_cli_flags_do(cli, tmp_path):
    # The evaporator without its "optimization" section: the keywords (and the CLI's flags) give
    # the section back, and the answer is the file's.
    doc = json.loads((REPO / "flowsheets" / "evaporator.json").read_text())
    section = doc.pop("optimization")
    bare = tmp_path / "evaporator_bare.json"
    bare.write_text(json.dumps(doc))
    lists = ["--disturbances", ",".join(DISTURBANCES), "--candidates", ",".join(CANDIDATES),
             "--errors", ",".join(ERRORS), "--size", "2", "--best", "2", "--json"]
    with_file = json.loads(cli(["select", EVAPORATOR, *lists]).stdout)
    flags = ["--objective", section["objective"]]
    for path, limits in section["vary"].items():
        flags += ["--vary", f"{path}={limits.get('min', '')}:{limits.get('max', '')}" if limits else path]
    for path, limits in section["constraints"].items():
        flags += ["--constraint", f"{path}={limits.get('min', '')}:{limits.get('max', '')}"]
    with_flags = json.loads(cli(["select", str(bare), *flags, *lists]).stdout)
    got = pw.load(str(bare)).select(DISTURBANCES, CANDIDATES, ERRORS, 2, best=2, objective=section["objective"],
                                    vary=section["vary"], constraints=section["constraints"])
    assert got == with_flags == with_file
    with pytest.raises(pw.InputError, match="objective"):
        pw.load(str(bare)).select(DISTURBANCES, CANDIDATES, ERRORS, 2)
