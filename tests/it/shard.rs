//! `--shard I/N` and `plantwide merge`: a sweep split over processes and put together equals the
//! one-process run bit for bit (text, CSV, JSON), and parts that do not make one job are refused
//! by name.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::harness::{command, flowsheet};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("plantwide-shard-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `plantwide ARGS` run in `dir`.
fn run_in(dir: &Path, args: &[&str]) -> Output {
    command().current_dir(dir).args(args).output().expect("the plantwide binary runs")
}

fn ok(out: &Output) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The part files in `dir`, sorted.
fn parts(dir: &Path) -> Vec<String> {
    let mut p: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".part-"))
        .collect();
    p.sort();
    p
}

#[test]
fn a_sharded_sensitivity_sweep_merges_into_the_one_process_sweep_bit_for_bit() {
    let fs = flowsheet("column_a.json");
    let sweep = |csv: &str| -> Vec<String> {
        [
            "sensitivity",
            &fs,
            "--disturb",
            "feed_source.F=-10%:+10%",
            "--disturb",
            "feed_source.z[light]=-5%:+5%",
            "--outputs",
            "bottoms.x[light],distillate.x[light]",
            "--points",
            "5",
            "--csv",
            csv,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let whole_dir = scratch("sens-whole");
    let whole = ok(&run_in(&whole_dir, &sweep("out.csv").iter().map(String::as_str).collect::<Vec<_>>()));
    // Three shards of four walks (two disturbances, up and down): 2, 1 and 1 walks.
    let dir = scratch("sens-parts");
    for (i, n) in [(0, 2), (1, 1), (2, 1)] {
        let mut args = sweep("out.csv");
        args.extend(["--shard".to_string(), format!("{i}/3")]);
        let said = ok(&run_in(&dir, &args.iter().map(String::as_str).collect::<Vec<_>>()));
        assert!(said.contains(&format!("shard {i}/3 of `sensitivity`: {n} of 4 tasks computed")), "{said}");
    }
    // A shard writes its part only: no CSV before the merge.
    assert!(!dir.join("out.csv").exists());
    let names = parts(&dir);
    assert_eq!(names.len(), 3, "{names:?}");
    let mut merge = vec!["merge"];
    merge.extend(names.iter().rev().map(String::as_str));
    let merged = ok(&run_in(&dir, &merge));
    assert_eq!(merged, whole);
    assert_eq!(std::fs::read(dir.join("out.csv")).unwrap(), std::fs::read(whole_dir.join("out.csv")).unwrap());
    // The merged numbers close the column's component balance: with L and V held (LV, level loops
    // P-only) D = V − L = 0.5 kmol/min at every feed rate, B = F − D, and F zF = D yD + B xB.
    let csv = std::fs::read_to_string(dir.join("out.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .filter(|l| l.starts_with("feed_source.F,"))
        .map(|l| l.split(',').skip(2).map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 5);
    let d = 0.5e3 / 60.0;
    for r in &rows {
        let (f, xb, yd) = (r[0], r[2], r[3]);
        assert!((f * 0.5 - d * yd - (f - d) * xb).abs() < 1e-7 * f, "{r:?}");
    }
    // And the sweep moved the bottoms (a merge of empty walks would also match the whole).
    assert!(rows[4][2] > 5.0 * rows[2][2], "{rows:?}");
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_dir_all(&whole_dir).ok();
}

#[test]
fn a_sharded_pairing_screen_merges_into_the_one_process_screen() {
    // Column A with its quality loops: three throughput choices, one pairing each, all three tested
    // dynamically (the tasks); scored and ranked only once merged.
    let fs = flowsheet("column_a_lv.json");
    let args = [
        "screen",
        fs.as_str(),
        "--cvs",
        "distillate.x[light],bottoms.x[light]",
        "--mvs",
        "column.reflux,column.boilup,feed_source.F",
        "--throughput",
        "column.reflux,column.boilup,feed_source.F",
        "--disturbances",
        "feed_source.z[light]=+5%",
        "--duration",
        "100 min",
        "--json",
    ];
    let whole_dir = scratch("screen-whole");
    let whole: serde_json::Value = serde_json::from_str(&ok(&run_in(&whole_dir, &args))).unwrap();
    let tested = whole["structures"].as_array().unwrap().iter().filter(|s| !s["dynamic"].is_null()).count();
    assert_eq!(tested, 3, "{whole}");
    let dir = scratch("screen-parts");
    for i in 0..2 {
        let shard = format!("{i}/2");
        let part = format!("p{i}.json");
        ok(&run_in(&dir, &[&args[..], &["--shard", &shard, "--part", &part]].concat()));
    }
    let merged: serde_json::Value = serde_json::from_str(&ok(&run_in(&dir, &["merge", "p1.json", "p0.json"]))).unwrap();
    assert_eq!(merged, whole);
    // One shard alone holds results but no score: scores exist only relative to every candidate.
    let p0: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("p0.json")).unwrap()).unwrap();
    assert_eq!(p0["tasks"], 3);
    assert_eq!(p0["results"].as_object().unwrap().keys().collect::<Vec<_>>(), ["0", "2"]);
    assert!(p0["results"]["0"]["result"]["score"].is_null());
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_dir_all(&whole_dir).ok();
}

#[test]
fn parts_that_do_not_make_one_job_are_refused_by_name() {
    let dir = scratch("bad");
    let original = flowsheet("column_a.json");
    let fs = dir.join("column_a.json");
    std::fs::copy(&original, &fs).unwrap();
    let fs = fs.to_str().unwrap();
    let sweep = |shard: &str, part: &str, points: &str| {
        let a = ["sensitivity", fs, "--disturb", "feed_source.F=-5%:+5%", "--outputs", "bottoms.x[light]"];
        ok(&run_in(&dir, &[&a[..], &["--points", points, "--shard", shard, "--part", part]].concat()));
    };
    sweep("0/2", "a0.json", "3");
    sweep("1/2", "a1.json", "3");
    sweep("1/2", "b1.json", "4");
    let refused = |args: &[&str], needle: &str| {
        let out = run_in(&dir, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    };
    refused(&["merge", "a0.json"], "shards 1 of 2 are missing; run them (--shard I/2)");
    refused(&["merge", "a0.json", "a0.json", "a1.json"], "a0.json: shard 0/2 is also in a0.json");
    refused(&["merge", "a0.json", "b1.json"], "b1.json: a part of another job (command line differs");
    refused(&["merge", "a0.json", fs], "not a plantwide part file");
    refused(
        &["sensitivity", fs, "--disturb", "feed_source.F=-5%:+5%", "--outputs", "bottoms.x[light]", "--shard", "2/2"],
        "the index counting from 0",
    );
    refused(
        &["screen", fs, "--column", "column", "--outputs", "distillate.x[light],bottoms.x[light]", "--shard", "0/2"],
        "drop --shard",
    );
    // Parts edited by hand to claim fewer tasks than the command line makes.
    for (from, to, drop) in [("a0.json", "c0.json", None), ("a1.json", "c1.json", Some("1"))] {
        let mut p: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join(from)).unwrap()).unwrap();
        p["tasks"] = 1.into();
        if let Some(t) = drop {
            p["results"].as_object_mut().unwrap().remove(t);
        }
        std::fs::write(dir.join(to), p.to_string()).unwrap();
    }
    refused(&["merge", "c0.json", "c1.json"], "the parts hold 1 task results, but the command line makes 2 tasks");
    // The flowsheet edited between the shards and the merge.
    let text = std::fs::read_to_string(fs).unwrap();
    std::fs::write(fs, format!("{text}\n")).unwrap();
    refused(&["merge", "a0.json", "a1.json"], "changed since the shards ran");
    std::fs::remove_dir_all(&dir).ok();
}
