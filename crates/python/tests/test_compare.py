"""`plantwide.compare` against `plantwide compare --json`: the same request gives the same JSON bit
for bit and the same report folder; the energy balance the CLI's test checks holds from Python;
refusals name the request's field."""

import json

import pytest

import plantwide as pw
from conftest import REPO

WITH = str(REPO / "flowsheets" / "fehe_reactor.json")
WITHOUT = str(REPO / "flowsheets" / "fehe_reactor_without_fehe.json")
ARGS = ["--disturbances", "feed_T=+3 K,feed_rate=+10%", "--outputs", "effluent.T@degC,effluent.x[A]"]
KW = {"disturbances": ["feed_T=+3 K", "feed_rate=+10%"], "outputs": ["effluent.T@degC", "effluent.x[A]"]}


def test_a_comparison_equals_the_cli_bit_for_bit_with_its_report(cli, tmp_path):
    mine = pw.compare([WITH, pw.load(WITHOUT)], **KW, report=tmp_path / "py", units="metric")
    p = cli(["--units", "metric", "compare", WITH, WITHOUT, *ARGS, "--json", "--report", str(tmp_path / "cli")])
    assert mine == json.loads(p.stdout)
    names = sorted(f.name for f in (tmp_path / "cli").iterdir())
    assert "compare.md" in names and "energy.png" in names
    assert sorted(f.name for f in (tmp_path / "py").iterdir()) == names
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert "degC" in (tmp_path / "py" / "compare.md").read_text()
    # The exchanger's recovered heat plus its trim heater's duty is the heater-only scheme's
    # 135 kW = F c_p (390 − 300 K) (tests/it/compare.rs).
    with_fehe, heater_only = mine["schemes"]
    e = lambda s, k: s["energy"][k]
    assert e(heater_only, "heating") == pytest.approx(10.0 * 150.0 * 90.0, rel=1e-6)
    assert e(with_fehe, "heating") + e(with_fehe, "recovered") == pytest.approx(e(heater_only, "heating"), rel=1e-6)


def test_refusals_name_the_request_field():
    with pytest.raises(pw.InputError, match=r"^hours 9000: give the operating hours"):
        pw.compare([WITH, WITHOUT], **KW, hours=9000)
    with pytest.raises(pw.InputError, match=r"^duration 2 kg: "):
        pw.compare([WITH, WITHOUT], **KW, duration="2 kg")
    with pytest.raises(pw.InputError, match=r"^disturbances "):
        pw.compare([WITH, WITHOUT], disturbances=["feed_T=+3 kg"], outputs=["effluent.T"])
    with pytest.raises(pw.InputError, match="unknown variant `best`"):
        pw.compare([WITH, WITHOUT], **KW, tuning="best")
