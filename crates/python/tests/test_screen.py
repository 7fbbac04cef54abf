"""`Plant.screen` against `plantwide screen --json`: a column's configurations and a pairing screen
give the same JSON bit for bit and the same report folder."""

import json

import plantwide as pw
from conftest import COLUMN_A, REPO

LV = str(REPO / "flowsheets" / "column_a_lv.json")
QUALITIES = ["distillate.x[light]", "bottoms.x[light]"]


def test_a_columns_configurations_equal_the_cli_with_their_report(cli, tmp_path):
    mine = pw.load(COLUMN_A).screen("column", QUALITIES, steady_only=True, report=tmp_path / "py")
    args = ["screen", COLUMN_A, "--column", "column", "--outputs", ",".join(QUALITIES), "--steady-only"]
    assert mine == json.loads(cli([*args, "--json", "--report", str(tmp_path / "cli")]).stdout)
    names = sorted(f.name for f in (tmp_path / "cli").iterdir())
    assert names == ["ranking.png", "rga.png", "rga.svg", "screen.html", "screen.json", "screen.md"]
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # LV's relative gain from the same JSON's gain matrix: λ11 = g11 g22 / (g11 g22 − g12 g21).
    lv = next(c for c in mine["structures"] if c["name"] == "LV")
    (g11, g12), (g21, g22) = lv["gain"]
    assert abs(lv["relative_gain"] - g11 * g22 / (g11 * g22 - g12 * g21)) <= 1e-9 * abs(lv["relative_gain"])


def test_a_pairing_screen_equals_the_cli_with_its_report(cli, tmp_path):
    cvs, mvs = ["distillate.x[light]", "bottoms.x[light]@ppm"], ["column.reflux", "column.boilup"]
    kw = {"cvs": cvs, "mvs": mvs, "disturbances": ["feed_source.F=+10%"], "candidates": 1, "duration": "200 min"}
    mine = pw.load(LV).screen(**kw, report=tmp_path / "py", units="metric")
    args = ["--units", "metric", "screen", LV, "--cvs", ",".join(cvs), "--mvs", ",".join(mvs)]
    args += ["--disturbances", "feed_source.F=+10%", "--candidates", "1", "--duration", "200 min"]
    assert mine == json.loads(cli([*args, "--json", "--report", str(tmp_path / "cli")]).stdout)
    names = sorted(f.name for f in (tmp_path / "cli").iterdir())
    assert "screen.md" in names and "responses_1.png" in names
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
