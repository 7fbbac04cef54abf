"""``pw.select``: the same JSON as ``plantwide select --matrices --json``, and the CLI's errors."""

import json

import plantwide as pw
import pytest
from conftest import REPO

EVAPORATOR = str(REPO / "crates" / "soc" / "tests" / "data" / "evaporator.json")


def test_select_returns_what_the_cli_prints(cli):
    got = pw.select(EVAPORATOR, 3, best=4, criterion="average")
    printed = json.loads(cli(["select", "--matrices", EVAPORATOR, "--size", "3", "--best", "4",
                              "--criterion", "average", "--json"]).stdout)
    assert got == printed
    assert got["criterion"] == "average" and len(got["subsets"]) == 4
    losses = [s["average_loss"] for s in got["subsets"]]
    assert losses == sorted(losses)


def test_bad_requests_raise_as_the_cli_exits(cli):
    with pytest.raises(pw.InputError) as e:
        pw.select(EVAPORATOR, 1)
    assert str(e.value).startswith("size 1:")
    p = cli(["select", "--matrices", EVAPORATOR, "--size", "1"], check=False)
    assert p.returncode == 1 and p.stderr.strip() == "error: --" + str(e.value)
    with pytest.raises(pw.InputError, match="criterion `best`"):
        pw.select(EVAPORATOR, 2, criterion="best")
    cao = str(REPO / "crates" / "soc" / "tests" / "data" / "cao_ny40_nu15_nd5.json")
    with pytest.raises(pw.ConvergenceError, match="stopped after 50 nodes"):
        pw.select(cao, 15, max_nodes=50)
