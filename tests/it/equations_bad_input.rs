//! Bad equation text in an `equations` unit (issue 57): `plantwide check` exits 1 with a message
//! that names the file, the unit, the equation, and points at the fault in the text. Each case is
//! `tests/data/cstr_equations.json` with one equation replaced.

use crate::harness;

/// One broken variant of the equations CSTR.
struct Case {
    /// File name of the variant (written to a scratch directory).
    file: &'static str,
    /// The equation replaced (by its text in `cstr_equations.json`) and its replacement.
    replace: (&'static str, &'static str),
    /// Fragments the message must contain.
    fragments: &'static [&'static str],
}

const CASES: &[Case] = &[
    Case {
        file: "cstr_dimension_error.json",
        // `rate` is a volumetric rate [mol/(m3 s)]: without `V*` the balance adds mol/s to it.
        replace: ("in.F*in.x[A] - out.F*out.x[A] - V*rate", "in.F*in.x[A] - out.F*out.x[A] - rate"),
        fragments: &[
            "units.reactor.equations[0]",
            "must have the same dimension, found mol/s and mol/(m3*s)",
            "der(NA) = in.F*in.x[A] - out.F*out.x[A] - rate\n          ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^",
        ],
    },
    Case {
        file: "cstr_undefined_name.json",
        replace: ("level*area = V", "levle*area = V"),
        fragments: &[
            "units.reactor.equations[8]",
            "unknown name `levle`; did you mean `level`?",
            "levle*area = V\n^^^^^",
        ],
    },
    Case {
        file: "cstr_zero_denominator.json",
        // M and NA are both guessed at 1000 mol: M − NA is zero at the guess.
        replace: ("out.x[B]*M = NB", "out.x[B] = NB/(M - NA)"),
        fragments: &[
            "units.reactor.equations[7]",
            "at the guess",
            "the denominator is zero at the guess values",
            "out.x[B] = NB/(M - NA)\n              ^^^^^^^^",
        ],
    },
    Case {
        file: "cstr_log_non_positive.json",
        // NB is guessed at 0 mol.
        replace: ("rate = exp(-Ea/Rg/out.T)*k0*(NA/V)", "rate = exp(-Ea/Rg/out.T - ln(NB/NA))*k0*(NA/V)"),
        fragments: &[
            "units.reactor.equations[11]",
            "at the guess",
            "ln of 0 at the guess values, outside its domain",
            // The caret is under the argument.
            "rate = exp(-Ea/Rg/out.T - ln(NB/NA))*k0*(NA/V)\n                             ^^^^^",
        ],
    },
    Case {
        file: "cstr_structurally_singular.json",
        // `V = M*vl` twice and no equation for `level`: 12 equations of the file, the outlet's
        // two mappings (`out.F = outflow`, `out.P = P`) and its closed enthalpy, for the outlet's
        // 6 quantities and the 9 variables. Which of the two `V` equations is left over depends
        // on the matching; `level` is read by no equation. The summary names the equation by its
        // text; the equation left over is also reported at its own index with its text marked.
        replace: ("level*area = V", "V = vl*M"),
        fragments: &[
            "units.reactor.equations: the equations are structurally singular (15 equations, 15 unknowns)",
            "left without an unknown: `V = ",
            "left without an equation: `level`",
            "structurally singular: every unknown this equation reads is already determined by the others",
            "\n^^^^^^^^",
        ],
    },
    Case {
        file: "cstr_duty_not_power.json",
        // A duty is a heat flow: `V` is a volume.
        replace: (r#""duties": ["Q"]"#, r#""duties": ["V"]"#),
        fragments: &["units.reactor.duties[0]", "`V` is in m3, not a heat duty (W)"],
    },
    Case {
        file: "cstr_duty_unknown.json",
        replace: (r#""duties": ["Q"]"#, r#""duties": ["Qj"]"#),
        fragments: &["units.reactor.duties[0]", "`Qj` is not a variable or input of the unit; did you mean `Q`?"],
    },
];

#[test]
fn bad_equations_are_reported_with_file_unit_equation_and_position() {
    let good = std::fs::read_to_string(harness::fixture("data/cstr_equations.json")).unwrap();
    let dir = std::env::temp_dir().join(format!("plantwide_equations_bad_input_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut failures = Vec::new();
    for case in CASES {
        let (from, to) = case.replace;
        assert_eq!(good.matches(from).count(), 1, "{}: `{from}` must occur once in cstr_equations.json", case.file);
        let path = dir.join(case.file);
        std::fs::write(&path, good.replace(from, to)).unwrap();
        let out = harness::plantwide(&["check", path.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{}: expected exit 1, stderr:\n{stderr}", case.file);
        assert!(!stderr.contains("panicked"), "{} panicked:\n{stderr}", case.file);
        for frag in [case.file].iter().chain(case.fragments) {
            if !stderr.contains(frag) {
                failures.push(format!("{}: missing `{frag}` in:\n{stderr}", case.file));
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
