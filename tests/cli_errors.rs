//! Every deliberately broken flowsheet under tests/broken/ must make `plantwide check` exit 1 with
//! a message naming the file, the JSON path and what would fix it — and never panic.

use std::process::Command;

/// (file, fragments the error message must contain).
const CASES: &[(&str, &[&str])] = &[
    ("malformed_json.json", &["malformed_json.json:4:3", "malformed JSON", "expected `,` or `}`"]),
    ("unknown_top_level_field.json", &["solver: unknown field", "the top level has"]),
    ("unknown_unit_type.json", &["units.h1.type", "unknown unit type `heatr`", "did you mean `heater`"]),
    ("unknown_unit_field.json", &["units.h1", "unknown field `area`", "expected one of `duty`"]),
    ("unknown_component.json", &["components[1]", "unknown component `toulene`", "did you mean `toluene`"]),
    ("stream_to_missing_unit.json", &["streams.s1.to", "no unit named `heater1`"]),
    ("stream_to_missing_port.json", &["streams.s1.to", "has no inlet port `inlet`", "inlet ports: in"]),
    (
        "port_connected_twice.json",
        &["streams.s3.from", "already the source of stream `s2`", "streams.s3.to", "already fed by stream `s2`"],
    ),
    ("port_left_open.json", &["outlet port `h1.out` is not connected", "inlet port `sink.in` is not connected"]),
    ("negative_flow.json", &["units.src.F", "must not be negative", "-5 kmol/h"]),
    ("non_finite_temperature.json", &["units.src.T", "1e400 K"]),
    ("wrong_dimension.json", &["units.src.F", "`5 K` is a temperature but a molar flow is expected", "kmol/min"]),
    ("composition_sum.json", &["units.src.z", "sum to 1.1"]),
    ("two_controllers_one_input.json", &["controllers.tc2.output", "already driven by controller `tc1`"]),
    ("controller_unknown_measurement.json", &["controllers.tc1.pv", "no variable `s2.temperature`"]),
    ("controller_gain_dimension.json", &["controllers.tc1.kc", "is a molar flow but a heat-transfer conductance"]),
    ("wrong_format_version.json", &["format_version", "reads format_version 1, the file has 2"]),
    ("heater_overspecified.json", &["units.h1", "exactly one of `duty`"]),
    ("cstr_temperature_guess_dimension.json", &["units.reactor.T_guess", "a temperature is expected"]),
    (
        "uncontrolled_level.json",
        &[
            "steady state is not determined",
            "tank.N[water]",
            "inventory of `tank` is uncontrolled",
            "level (or pressure) controller",
        ],
    ),
    ("flow_fixed_twice.json", &["11 equations for 10 variables", "a flow is set twice"]),
];

#[test]
fn broken_flowsheets_give_clear_errors_and_exit_1() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/broken");
    let mut listed: Vec<&str> = CASES.iter().map(|(f, _)| *f).collect();
    listed.sort();
    let mut on_disk: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    on_disk.sort();
    assert_eq!(listed, on_disk, "every broken file needs a case, every case a file");
    for (file, fragments) in CASES {
        let out =
            Command::new(env!("CARGO_BIN_EXE_plantwide")).args(["check", &format!("{dir}/{file}")]).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{file}: expected exit 1, stderr:\n{stderr}");
        assert!(!stderr.contains("panicked"), "{file} panicked:\n{stderr}");
        assert!(stderr.contains(file), "{file}: message must name the file:\n{stderr}");
        for frag in *fragments {
            assert!(stderr.contains(frag), "{file}: missing `{frag}` in:\n{stderr}");
        }
    }
}

#[test]
fn missing_file_is_a_user_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_plantwide")).args(["check", "no/such/file.json"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/file.json: cannot read the file"));
}
