//! An `equations` unit calling the thermodynamic package and tables (issue 57): bad calls and bad
//! tables make `plantwide check` exit 1 naming the field and pointing at the position in the text.

use crate::harness;

/// `tests/data/flash_recycle_thermo.json` with `edit` applied to the drum, written to a
/// temporary file.
fn broken(name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> String {
    let text = std::fs::read_to_string(harness::fixture("data/flash_recycle_thermo.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    edit(&mut v["units"]["drum"]);
    let dir = std::env::temp_dir().join(format!("plantwide-thermo-functions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    path.to_string_lossy().into_owned()
}

/// Replaces the first `from` in equation `k` by `to`.
fn in_equation(k: usize, from: &'static str, to: &'static str) -> impl FnOnce(&mut serde_json::Value) {
    move |drum| {
        let eq = drum["equations"][k].as_str().unwrap().replacen(from, to, 1);
        drum["equations"][k] = eq.into();
    }
}

/// An edit of the drum's description.
type Edit = Box<dyn FnOnce(&mut serde_json::Value)>;

fn check_fails_with(path: &str, fragments: &[&str]) {
    let out = harness::plantwide(&["check", path]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{path}: expected exit 1, stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{path} panicked:\n{stderr}");
    for frag in fragments {
        assert!(stderr.contains(frag), "{path}: missing `{frag}` in:\n{stderr}");
    }
}

#[test]
fn the_thermo_flash_checks() {
    let out = harness::plantwide(&["check", &harness::fixture("data/flash_recycle_thermo.json")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn bad_thermo_calls_exit_1_with_the_position() {
    // Equation 3 is `vapour.x[benzene]*(K(liquid, benzene, P)*… ) = …`; the caret lines up under
    // the argument at fault (29 columns in).
    let pad = " ".repeat(29);
    let cases: [(&str, Edit, Vec<String>); 4] = [
        (
            "unknown_component",
            Box::new(in_equation(3, "K(liquid, benzene, P)", "K(liquid, benzen, P)")),
            vec![
                "units.drum.equations[3]: `K`: `benzen` is not a component (components: benzene, toluene, o-xylene)"
                    .into(),
                format!("\n{pad}^^^^^^\n"),
            ],
        ),
        (
            "unknown_port",
            Box::new(in_equation(3, "K(liquid, benzene, P)", "K(liquid2, benzene, P)")),
            vec![
                "units.drum.equations[3]: `K`: `liquid2` is not a port of the unit (ports: liquid, vapour, in)".into(),
                format!("\n{}^^^^^^^\n", " ".repeat(21)),
            ],
        ),
        (
            "unknown_function",
            Box::new(|drum: &mut serde_json::Value| drum["ports"]["outlets"]["vapour"]["h"] = "h_G(vapour)".into()),
            vec![
                "units.drum.ports.outlets.vapour.h: unknown name `h_G`; did you mean `h_L`?".into(),
                "vapour.h = h_G(vapour)\n           ^^^".into(),
            ],
        ),
        (
            "not_a_pressure",
            Box::new(in_equation(3, "K(liquid, benzene, P)", "K(liquid, benzene, duty)")),
            vec!["`K`: `duty` is not a pressure of the unit (pressures: P, dp, in.P, liquid.P, vapour.P)".into()],
        ),
    ];
    for (name, edit, fragments) in cases {
        let path = broken(name, edit);
        let frags: Vec<&str> = fragments.iter().map(String::as_str).collect();
        check_fails_with(&path, &frags);
    }
}

#[test]
fn bad_tables_exit_1_naming_the_table_and_the_point() {
    let table = |t: &'static str| {
        move |drum: &mut serde_json::Value| {
            drum["tables"] = serde_json::from_str(&format!(r#"{{"kv": {t}}}"#)).unwrap();
        }
    };
    let cases: [(&str, &'static str, &[&str]); 3] = [
        (
            "table_not_increasing",
            r#"{"x": [300, 350, 340], "y": [1, 2, 3], "x_unit": "K", "interpolation": "spline"}"#,
            &["units.drum.tables.kv.x[2]: table `kv`: x must be strictly increasing, but x[2] = 340"],
        ),
        (
            "table_lengths",
            r#"{"x": [300, 350], "y": [1, 2, 3], "x_unit": "K"}"#,
            &["units.drum.tables.kv.y: table `kv`: 2 x values but 3 y values"],
        ),
        (
            "table_overflow",
            r#"{"x": [300, 350], "y": [1, 1e306], "y_unit": "kJ/mol"}"#,
            &["units.drum.tables.kv.y[1]: table `kv`: point 1 is not finite"],
        ),
    ];
    for (name, t, fragments) in cases {
        check_fails_with(&broken(name, table(t)), fragments);
    }
    // A table called with an argument of the wrong dimension: located in the equation.
    let path = broken("table_argument", |drum| {
        table(r#"{"x": [300, 350], "y": [1, 2], "x_unit": "K"}"#)(drum);
        drum["equations"][7] = "bub = kv(liquid.P) - 1".into();
    });
    check_fails_with(
        &path,
        &[
            "units.drum.equations[7]: the argument of table `kv` and its input must have the same dimension",
            "bub = kv(liquid.P) - 1\n         ^^^^^^^^",
        ],
    );
}

/// The division-at-the-guess check uses the plant's own guess (issue 57): the inlet the
/// upstream feed gives, not a made-up stream. With the feed at 350 K, `1/(in.T - 300 K)` is
/// finite where Newton starts and loads; `1/(in.T - 350 K)` divides by zero there and is refused
/// with its position.
#[test]
fn the_guess_check_sees_the_upstream_units_guess() {
    let text = std::fs::read_to_string(crate::harness::fixture("data/cstr_equations.json")).unwrap();
    let mut d: serde_json::Value = serde_json::from_str(&text).unwrap();
    d["units"]["fresh"]["T"] = "350 K".into();
    d["units"]["reactor"]["variables"]["w"] = serde_json::json!({"kind": "algebraic", "unit": "1/K", "guess": 0});
    d["units"]["reactor"]["equations"].as_array_mut().unwrap().push("w = 1/(in.T - T0)".into());
    let mut check = |t0: &str| {
        d["units"]["reactor"]["parameters"]["T0"] = t0.into();
        let file = std::env::temp_dir().join(format!("guess_check_{}_{}.json", std::process::id(), t0.len()));
        std::fs::write(&file, d.to_string()).unwrap();
        crate::harness::plantwide(&["check", file.to_str().unwrap()])
    };
    let ok = check("300 K");
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let bad = check("350.0 K");
    assert_eq!(bad.status.code(), Some(1));
    let msg = String::from_utf8_lossy(&bad.stderr);
    assert!(msg.contains("units.reactor.equations[12]") && msg.contains("at the guess") && msg.contains('^'), "{msg}");
}
