//! Unit tests of the rigorous column: exact Jacobian, the Francis weir, the Murphree relation, the
//! cold-start profile as a steady state, and the build errors.

use plantwide_thermo::{Library, ThermoPackage, VleModel};

use super::*;
use crate::testing::{binary_package, jacobian_error};
use crate::units::column::Column;
use crate::units::column::ColumnConfig;
use crate::units::outflow::test_support::{Lcg, at_guess};
use crate::{BuildCx, FieldError};
use crate::{Unit, UnitIo};

/// Ethanol–water with the library's NRTL pair.
fn ethanol_water() -> ThermoPackage {
    let lib = Library::builtin().unwrap();
    let components = ["ethanol", "water"].map(|c| lib.component(c).unwrap().clone()).to_vec();
    let model = lib.activity_model("nrtl", &["ethanol", "water"], &[]).unwrap();
    ThermoPackage { components, vle: VleModel::Activity(model) }
}

/// A six-stage column (reboiler, four trays, drum) fed on stage 3, reflux 30 mol/s and a reboiler
/// duty Q_R that boils up about 35 mol/s; `extra` adds to `rigorous` (`QC` stands for the duty of
/// the same column with its drum at the bubble point, plus 0.5 %).
fn config(thermo: &ThermoPackage, extra: &str) -> String {
    let z = [0.5, 0.5];
    let b = thermo.bubble_t(101_325.0, &z).unwrap();
    let duty = 35.0 * (thermo.h_vap(b.t, &b.incipient) - thermo.h_liq(b.t, &z));
    format!(
        r#"{{"model": "rigorous", "stages": 6, "feeds": [{{"stage": 3}}], "P": "1 atm",
        "condenser_holdup": "2 kmol", "reboiler_holdup": "3 kmol", "reflux": "30 mol/s",
        "distillate": "5 mol/s", "bottoms": "5 mol/s",
        "rigorous": {{"reboiler_duty": {duty}, "weir_length": "0.5 m", "weir_height": "40 mm",
        "tray_area": "0.4 m2"{}}}}}"#,
        if extra.contains("QC") {
            extra.replace("QC", &(1.005 * bubble_point_duty(thermo)).to_string())
        } else {
            extra.into()
        }
    )
}

/// `Qc` of the cold-start guess of `config(thermo, "")` (a steady state, see below).
fn bubble_point_duty(thermo: &ThermoPackage) -> f64 {
    let u = build(&config(thermo, ""), thermo).unwrap();
    let Column::Rigorous(col) = &u else { panic!("not rigorous") };
    let (lay, local) = at_guess(&u, thermo, &feed(thermo));
    local[lay.n_outlets * lay.stream.len() + col.qc()]
}

fn build(json: &str, thermo: &ThermoPackage) -> Result<Column, Vec<FieldError>> {
    let names: Vec<String> = thermo.components.iter().map(|c| c.name.clone()).collect();
    let c: ColumnConfig = serde_json::from_str(json).unwrap();
    Column::build(&c, BuildCx::new(&names, thermo, "units.column"), ())
}

/// The test binary at constant relative volatility 2.
fn alpha_package() -> ThermoPackage {
    ThermoPackage { vle: VleModel::ConstantAlpha { alpha: vec![2.0, 1.0] }, ..binary_package() }
}

/// A short name of the VLE model, for messages.
fn vle_name(thermo: &ThermoPackage) -> &'static str {
    match thermo.vle {
        VleModel::ConstantAlpha { .. } => "constant α",
        VleModel::Ideal => "Raoult",
        VleModel::Activity(_) => "NRTL",
    }
}

/// 10 mol/s of an equimolar liquid at its bubble point at 1.2 atm.
fn feed(thermo: &ThermoPackage) -> Vec<f64> {
    let z = [0.5, 0.5];
    let t = thermo.bubble_t(1.2 * 101_325.0, &z).unwrap().t;
    vec![10.0, t, 1.2 * 101_325.0, thermo.h_liq(t, &z), z[0], z[1]]
}

fn n_eq(u: &dyn Unit, lay: &LocalLayout) -> usize {
    (lay.n_own() as isize + u.extra_equations()) as usize
}

#[test]
fn jacobian_matches_finite_differences() {
    let mut rng = Lcg(7);
    for thermo in [binary_package(), alpha_package(), ethanol_water()] {
        for extra in [
            "",
            r#", "murphree_efficiency": 0.7, "tray_pressure_drop": "0.8 kPa""#,
            r#", "condenser_duty": QC, "murphree_efficiency": 0.5"#,
            r#", "condenser": {"coolant_flow": "15 kg/s", "coolant_T_in": "300 K", "ua": "50 kW/K"}"#,
            r#", "condenser_type": "partial", "murphree_efficiency": 0.6"#,
        ] {
            let json = config(&thermo, extra).replace(
                r#""bottoms": "5 mol/s","#,
                r#""bottoms": "5 mol/s", "side_draws": [{"port": "side", "stage": 4, "flow": "1 mol/s"},
                {"port": "vside", "stage": 2, "flow": "2 mol/s", "phase": "vapour"}],"#,
            );
            let u = build(&json, &thermo).unwrap();
            let (lay, base) = at_guess(&u, &thermo, &feed(&thermo));
            let mut worst: f64 = 0.0;
            for _ in 0..4 {
                let local: Vec<f64> = base.iter().map(|v| v * rng.range(0.97, 1.03)).collect();
                worst = worst.max(jacobian_error(&u, &lay, &thermo, &local, n_eq(&u, &lay)));
            }
            eprintln!("rigorous column jacobian_error {worst:.1e} ({}){extra}", vle_name(&thermo));
            assert!(worst < 1e-6, "{extra}: {worst}");
        }
    }
}

#[test]
fn francis_weir_closed_form() {
    let w = Weir { length: 0.8, height: 0.05, area: 0.76 };
    let v = 2.0e-5;
    // 2 cm of crest: L = 1.84 l_w h^1.5 / v exactly.
    let m = (0.05 + 0.02) * 0.76 / v;
    let l = w.flow(m, v);
    let expected = 1.84 * 0.8 * 0.02f64.powf(1.5) / v;
    assert!((l - expected).abs() < 1e-14 * expected, "{l} vs {expected}");
    assert!((w.holdup(l, v) - m).abs() < 1e-12 * m);
    // Below the weir (beyond the smoothing band) nothing flows; C¹ at both band edges.
    assert_eq!(w.flow(0.04 * 0.76 / v, v), 0.0);
    let d = CREST_SMOOTH;
    let at = |z: f64| num_dual::Dual64::new((0.05 + z) * 0.76 / v, 1.0);
    for edge in [-d, d] {
        let (lo, hi) = (w.flow(at(edge - 1e-12), v.into()), w.flow(at(edge + 1e-12), v.into()));
        assert!((lo.re - hi.re).abs() <= 1e-6 * hi.re.max(1e-300) + 1e-12, "value jump at {edge}");
        assert!((lo.eps - hi.eps).abs() <= 1e-6 * hi.eps.abs().max(1e-12), "slope jump at {edge}");
    }
    // The inverse also holds inside the band.
    let small = w.flow((0.05 + 0.3 * d) * 0.76 / v, v);
    assert!((w.holdup(small, v) - (0.05 + 0.3 * d) * 0.76 / v).abs() < 1e-9 * m);
}

/// The y rows are `y − y_below − E (K x − y_below)` on trays and `y − K x` on the reboiler and drum,
/// with `K` from the thermo package at the stage pressure.
#[test]
fn murphree_identity() {
    let thermo = ethanol_water();
    for e in [1.0, 0.7, 0.3] {
        let u = build(
            &config(&thermo, &format!(r#", "murphree_efficiency": {e}, "tray_pressure_drop": "1 kPa""#)),
            &thermo,
        )
        .unwrap();
        let Column::Rigorous(col) = &u else { panic!("not rigorous") };
        let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
        let ix = StageIdx { nc: 2 };
        let at = |s: usize| lay.n_outlets * lay.stream.len() + col.stage(s);
        // Overwrite y with the Murphree recursion from K at (T, P_s, x).
        let mut k = [0.0; 2];
        for s in 0..6 {
            let o = at(s);
            let x = [local[o + ix.x(0)], local[o + ix.x(1)]];
            thermo.k_values(local[o + ix.t()], 101_325.0 + (5 - s) as f64 * 1000.0, &x, &mut k);
            for j in 0..2 {
                let eq = k[j] * x[j];
                local[o + ix.y(j)] =
                    if s == 0 || s == 5 { eq } else { local[at(s - 1) + ix.y(j)] * (1.0 - e) + e * eq };
            }
        }
        let mut r = vec![0.0; n_eq(&u, &lay)];
        u.residual(&UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut r);
        let worst =
            (0..6).flat_map(|s| (0..2).map(move |j| (s, j))).map(|(s, j)| r[at(s) + ix.y(j)].abs()).fold(0.0, f64::max);
        assert!(worst < 1e-15, "E = {e}: {worst}");
        // A y off the relation by δ gives the residual δ.
        local[at(3) + ix.y(0)] += 1e-3;
        u.residual(&UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut r);
        assert!((r[at(3) + ix.y(0)] - 1e-3).abs() < 1e-15 && (r[at(4) + ix.y(0)] + (1.0 - e) * 1e-3).abs() < 1e-15);
    }
}

/// The cold-start guess is a steady state of the model: with D and B at the guess's product flows
/// every residual vanishes, the energy balance closes and Σ y = 1 on every stage.
#[test]
fn cold_start_profile_is_a_steady_state() {
    let side_draw = |json: String| {
        json.replace(
            r#""bottoms": "5 mol/s","#,
            r#""bottoms": "5 mol/s", "side_draws": [{"port": "side", "stage": 4, "flow": "1 mol/s"}],"#,
        )
    };
    for (thermo, extra, draw) in [
        (binary_package(), "", false),
        (binary_package(), r#", "murphree_efficiency": 0.8"#, true),
        (alpha_package(), r#", "tray_pressure_drop": "1 kPa""#, false),
        (ethanol_water(), r#", "murphree_efficiency": 0.7, "tray_pressure_drop": "0.6 kPa""#, false),
        (ethanol_water(), r#", "condenser_duty": QC"#, false),
    ] {
        let json = config(&thermo, extra);
        let u = build(&if draw { side_draw(json) } else { json }, &thermo).unwrap();
        let Column::Rigorous(col) = &u else { panic!("not rigorous") };
        let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
        let slen = lay.stream.len();
        let inputs = lay.inputs_offset();
        local[inputs + IN_DISTILLATE] = local[F];
        local[inputs + IN_BOTTOMS] = local[slen + F];
        let mut r = vec![0.0; n_eq(&u, &lay)];
        let mut jac = vec![0.0; r.len() * local.len()];
        let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
        u.jacobian(&io, &mut r, &mut jac);
        let n = local.len();
        let scaled_k = |k: usize| r[k].abs() / (0..n).map(|j| (jac[k * n + j] * local[j]).abs()).fold(1e-300, f64::max);
        let scaled = (0..r.len()).map(scaled_k).fold(0.0, f64::max);
        let (d, feed) = (io.outlet(0), io.inlet(0));
        let products: Vec<_> = (0..lay.n_outlets).map(|k| io.outlet(k)).collect();
        let q_r = io.input(IN_REBOILER_DUTY);
        let qc = io.var(col.qc());
        let imbalance = q_r + feed.f() * feed.h() - qc - products.iter().map(|p| p.f() * p.h()).sum::<f64>();
        let comp = (0..2)
            .map(|j| (feed.f() * feed.z()[j] - products.iter().map(|p| p.f() * p.z()[j]).sum::<f64>()).abs() / feed.f())
            .fold(0.0, f64::max);
        let ix = StageIdx { nc: 2 };
        let y_sum = (0..5)
            .map(|s| (io.var(col.stage(s) + ix.y(0)) + io.var(col.stage(s) + ix.y(1)) - 1.0).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "profile ({}{extra}, side draw {draw}): scaled residual {scaled:.1e}, energy {:.1e}, components {comp:.1e}, Σy−1 {y_sum:.1e}, \
             D {:.4} mol/s, xD {:.6}, T_N {:.3} K, Qc {:.4e} W",
            vle_name(&thermo),
            imbalance.abs() / q_r,
            d.f(),
            d.z()[0],
            d.t(),
            qc
        );
        assert!(scaled < 1e-9, "{extra}: {scaled}");
        assert!(imbalance.abs() < 1e-9 * q_r && comp < 1e-10 && y_sum < 1e-10);
        if extra.contains("condenser_duty") {
            // Subcooled reflux: the drum sits below its bubble point and removes exactly Q_C.
            let x: Vec<f64> = d.z().to_vec();
            assert!(
                d.t() < thermo.bubble_t(101_325.0, &x).unwrap().t - 0.1
                    && (qc - 1.005 * bubble_point_duty(&thermo)).abs() < 1e-9 * q_r
            );
        }
    }
}

#[test]
fn build_errors_name_the_fields() {
    let thermo = binary_package();
    let msg = |json: &str| match build(json, &thermo) {
        Ok(_) => String::new(),
        Err(e) => e.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("\n"),
    };
    let simple_fields = config(&thermo, "").replace(
        r#""model": "rigorous","#,
        r#""model": "rigorous", "tau_l": "1 min", "boilup": "1 mol/s", "lambda": 0.1,"#,
    );
    let m = msg(&simple_fields);
    for f in ["units.column.tau_l", "units.column.boilup", "units.column.lambda"] {
        assert!(m.contains(&format!("{f}: the rigorous model does not use")), "{m}");
    }
    let m = msg(&config(&thermo, "").replace(r#""stage": 3"#, r#""stage": 3, "q": 1.0"#));
    assert!(m.contains("units.column.feeds[0].q: the rigorous model does not use `feeds[0].q`"), "{m}");
    let no_block = r#"{"model": "rigorous", "stages": 6, "feeds": [{"stage": 3}], "condenser_holdup": 1,
        "reboiler_holdup": 1, "reflux": 1, "distillate": 1, "bottoms": 1}"#;
    assert!(
        msg(no_block).contains("units.column.rigorous: the rigorous model needs `rigorous`, e.g. {"),
        "{}",
        msg(no_block)
    );
    let m = msg(&config(&thermo, r#", "murphree_efficiency": 1.5"#));
    assert!(m.contains("units.column.rigorous.murphree_efficiency: must lie in (0, 1]"), "{m}");
    let m = msg(&config(&thermo, "").replace(r#""0.5 m""#, r#""0.5 kg""#));
    assert!(m.contains("units.column.rigorous.weir_length"), "{m}");
    // The simple model reports the rigorous block and its own missing fields.
    let m = msg(&config(&thermo, "").replace(r#""model": "rigorous""#, r#""model": "simple""#));
    for f in ["tray_holdup", "tau_l", "boilup"] {
        assert!(m.contains(&format!("units.column.{f}: the simple model needs `{f}`")), "{m}");
    }
    assert!(m.contains("units.column.rigorous: the simple model does not use `rigorous`"), "{m}");
}

#[test]
fn variables_and_inputs() {
    let thermo = binary_package();
    let u = build(&config(&thermo, r#", "condenser_duty": "1 MW""#), &thermo).unwrap();
    let vars: Vec<String> = UnitModel::internal_vars(&u).into_iter().map(|v| v.name).collect();
    assert_eq!(vars.len(), 6 * 10 + 1);
    assert_eq!(
        &vars[..10],
        [
            "n[1][light]",
            "n[1][heavy]",
            "x[1][light]",
            "x[1][heavy]",
            "y[1][light]",
            "y[1][heavy]",
            "T[1]",
            "M[1]",
            "L[1]",
            "V[1]"
        ]
    );
    assert_eq!(vars[60], "Qc");
    let inputs: Vec<String> = UnitModel::inputs(&u).into_iter().map(|i| i.name).collect();
    assert_eq!(inputs, ["reflux", "reboiler_duty", "distillate", "bottoms", "condenser_duty"]);
    assert_eq!(UnitModel::outlet_ports(&u), ["distillate", "bottoms"]);
}

/// A steam reboiler with `m_s = Q_R / λ_s` is the duty-specified column: the same cold-start steady
/// state (to 1e-10) and the same residuals at that state; its input is `steam_flow` in kg/s.
#[test]
fn steam_reboiler_reproduces_the_duty() {
    let thermo = ethanol_water();
    let lambda = 2.1e6;
    let duty_json = config(&thermo, r#", "murphree_efficiency": 0.8"#);
    let c: ColumnConfig = serde_json::from_str(&duty_json).unwrap();
    let q_r = match &c.rigorous.as_ref().unwrap().reboiler_duty {
        Some(plantwide_units::QuantityValue::Number(q)) => *q,
        other => panic!("duty not a number: {other:?}"),
    };
    let steam_json = duty_json.replace(
        &format!(r#""reboiler_duty": {q_r}"#),
        &format!(
            r#""reboiler": {{"steam_flow": "{} kg/h", "steam_latent_heat": "2100 kJ/kg"}}"#,
            q_r / lambda * 3600.0
        ),
    );
    assert_ne!(steam_json, duty_json);
    let (duty, steam) = (build(&duty_json, &thermo).unwrap(), build(&steam_json, &thermo).unwrap());
    let inputs: Vec<(String, f64)> = UnitModel::inputs(&steam).into_iter().map(|i| (i.name, i.value)).collect();
    assert_eq!(inputs[1].0, "steam_flow");
    assert!((inputs[1].1 - q_r / lambda).abs() < 1e-14 * q_r / lambda, "{inputs:?}");
    let (lay, a) = at_guess(&duty, &thermo, &feed(&thermo));
    let (_, b) = at_guess(&steam, &thermo, &feed(&thermo));
    let own = lay.n_own();
    let worst = (0..own).map(|i| (a[i] - b[i]).abs() / a[i].abs().max(1.0)).fold(0.0, f64::max);
    eprintln!("steam vs duty reboiler: worst relative difference of the steady state {worst:.1e}");
    assert!(worst < 1e-10, "{worst}");
    // Residuals of both at the duty column's state, with the steam input at Q_R / λ_s.
    let mut b_local = a.clone();
    b_local[lay.inputs_offset() + IN_REBOILER_DUTY] = q_r / lambda;
    let (mut ra, mut rb) = (vec![0.0; n_eq(&duty, &lay)], vec![0.0; n_eq(&steam, &lay)]);
    duty.residual(&UnitIo { local: &a, layout: &lay, thermo: &thermo, time: 0.0 }, &mut ra);
    steam.residual(&UnitIo { local: &b_local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut rb);
    let diff = ra.iter().zip(&rb).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(diff < 1e-10 * q_r, "{diff}");
}

#[test]
fn steam_coolant_partial_and_vapour_draw_errors() {
    let thermo = binary_package();
    let msg = |json: &str| match build(json, &thermo) {
        Ok(_) => String::new(),
        Err(e) => e.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("\n"),
    };
    let steam = r#""reboiler": {"steam_flow": "1 kg/s", "steam_latent_heat": "2100 kJ/kg"}"#;
    let both = config(&thermo, &format!(", {steam}"));
    assert!(msg(&both).contains("units.column.rigorous.reboiler: give either"), "{}", msg(&both));
    let c: ColumnConfig = serde_json::from_str(&config(&thermo, "")).unwrap();
    let Some(plantwide_units::QuantityValue::Number(q)) = c.rigorous.unwrap().reboiler_duty else { panic!() };
    let none = config(&thermo, "").replace(&format!(r#""reboiler_duty": {q}, "#), "");
    assert!(msg(&none).contains("units.column.rigorous.reboiler_duty: the rigorous model needs"), "{}", msg(&none));
    let bad = config(&thermo, "").replace(&format!(r#""reboiler_duty": {q}"#), &steam.replace("kJ/kg", "kJ"));
    assert!(msg(&bad).contains("units.column.rigorous.reboiler.steam_latent_heat"), "{}", msg(&bad));
    // Coolant condenser, partial condenser, vapour draws.
    let coolant = r#""condenser": {"coolant_flow": "10 kg/s", "coolant_T_in": "30 degC", "ua": "50 kW/K""#;
    let m = msg(&config(&thermo, &format!(r#", "condenser_duty": "1 MW", {coolant}}}"#)));
    assert!(m.contains("units.column.rigorous.condenser: give either"), "{m}");
    let m = msg(&config(&thermo, &format!(r#", {coolant}, "cp": "4 kJ/kg"}}"#)));
    assert!(m.contains("units.column.rigorous.condenser.cp"), "{m}");
    let m = msg(&config(&thermo, &format!(r#", {}}}"#, coolant.replace("50 kW/K", "-5 kW/K"))));
    assert!(m.contains("units.column.rigorous.condenser.ua: must be positive"), "{m}");
    let m = msg(&config(&thermo, r#", "condenser_type": "partial", "condenser_duty": "1 MW""#));
    assert!(m.contains("units.column.rigorous.condenser_type: a partial condenser"), "{m}");
    let vapour_draw = |json: String| {
        json.replace(
            r#""bottoms": "5 mol/s","#,
            r#""bottoms": "5 mol/s", "side_draws": [{"port": "v", "stage": 2, "flow": 1, "phase": "vapour"}],"#,
        )
    };
    assert_eq!(msg(&vapour_draw(config(&thermo, ""))), "");
    let m = msg(&vapour_draw(config(&thermo, "")).replace(r#""model": "rigorous""#, r#""model": "simple""#));
    assert!(m.contains("units.column.side_draws[0].phase: the simple model does not use `side_draws[0].phase`"), "{m}");
}

/// Coolant flow [kg/s] at which `coolant_duty(m, t_hot, …) = q` (the duty rises with the flow), by
/// bisection.
fn coolant_flow_for(q: f64, t_hot: f64, t_in: f64, ua: f64, cp: f64) -> f64 {
    let (mut lo, mut hi) = (1e-6f64, 1e6f64);
    for _ in 0..300 {
        let mid = (lo * hi).sqrt();
        if coolant_duty(mid, t_hot, t_in, ua, cp) > q { hi = mid } else { lo = mid }
    }
    (lo * hi).sqrt()
}

/// A water-cooled condenser: at its cold-start steady state `Qc` obeys the effectiveness relation
/// and, independently, `Qc = m c_p (T_out − T_in) = UA ΔT_lm` between the drum at `T_N` and the
/// coolant; a coolant flow that removes the duty `QC` reproduces the duty-specified column.
#[test]
fn coolant_condenser_closed_forms() {
    let thermo = ethanol_water();
    let duty = build(&config(&thermo, r#", "condenser_duty": QC"#), &thermo).unwrap();
    let Column::Rigorous(col) = &duty else { panic!("not rigorous") };
    let (lay, a) = at_guess(&duty, &thermo, &feed(&thermo));
    let internal0 = lay.n_outlets * lay.stream.len();
    let ix = StageIdx { nc: 2 };
    let (qc, t_n) = (a[internal0 + col.qc()], a[internal0 + col.stage(5) + ix.t()]);
    let (t_in, ua, cp) = (303.15, 4.0e4, 4184.0);
    let m = coolant_flow_for(qc, t_n, t_in, ua, cp);
    let coolant_json = config(
        &thermo,
        &format!(r#", "condenser": {{"coolant_flow": {m}, "coolant_T_in": "30 degC", "ua": "40 kW/K"}}"#),
    );
    let coolant = build(&coolant_json, &thermo).unwrap();
    let inputs: Vec<String> = UnitModel::inputs(&coolant).into_iter().map(|i| i.name).collect();
    assert_eq!(inputs, ["reflux", "reboiler_duty", "distillate", "bottoms", "coolant_flow"]);
    let (_, b) = at_guess(&coolant, &thermo, &feed(&thermo));
    let io = UnitIo { local: &b, layout: &lay, thermo: &thermo, time: 0.0 };
    // Every residual of the coolant column vanishes at its guess (with D, B at the guess's flows).
    let mut local = b.clone();
    local[lay.inputs_offset() + IN_DISTILLATE] = b[F];
    local[lay.inputs_offset() + IN_BOTTOMS] = b[lay.stream.len() + F];
    let mut r = vec![0.0; n_eq(&coolant, &lay)];
    coolant.residual(&UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut r);
    let qc_b = io.var(col.qc());
    let t_nb = io.var(col.stage(5) + ix.t());
    assert!(r[internal0 + col.qc()].abs() < 1e-9 * qc_b, "Qc row {}", r[internal0 + col.qc()]);
    // Closed forms: effectiveness, and the coolant's own balance against UA ΔT_lm.
    let c = m * cp;
    let eff = c * (t_nb - t_in) * (1.0 - (-ua / c).exp());
    let t_out = t_in + qc_b / c;
    let lmtd = ((t_nb - t_in) - (t_nb - t_out)) / ((t_nb - t_in) / (t_nb - t_out)).ln();
    eprintln!(
        "coolant condenser: m_c {m:.4} kg/s, T_N {t_nb:.4} K, T_out {t_out:.4} K, Qc {qc_b:.6e} W, UA ΔT_lm {:.6e} W",
        ua * lmtd
    );
    assert!((qc_b - eff).abs() < 1e-9 * qc_b && (qc_b - ua * lmtd).abs() < 1e-9 * qc_b);
    // The duty-specified column's steady state.
    let worst = (0..lay.n_own()).map(|i| (a[i] - b[i]).abs() / a[i].abs().max(1.0)).fold(0.0, f64::max);
    eprintln!("coolant vs duty condenser: worst relative difference of the steady state {worst:.1e}");
    assert!(worst < 1e-8, "{worst}");
    assert!((t_nb - t_n).abs() < 1e-8 && t_nb > t_out);
}

/// Partial condensers and vapour side draws at their cold-start steady states: every residual
/// vanishes, components and energy balance over the whole column (vapour products at `h_V`), the
/// vapour distillate is in equilibrium with the reflux, `y_D = K(T_N, P_top, x_N) x_N`, and a
/// vapour draw carries its tray's `y` and `h_V(T, y)`.
#[test]
fn partial_condenser_and_vapour_draws() {
    let draws = |json: String, list: &str| {
        json.replace(r#""bottoms": "5 mol/s","#, &format!(r#""bottoms": "5 mol/s", "side_draws": [{list}],"#))
    };
    let vapour = r#"{"port": "vside", "stage": 2, "flow": "3 mol/s", "phase": "vapour"}"#;
    let liquid = r#"{"port": "side", "stage": 4, "flow": "1 mol/s"}"#;
    for thermo in [binary_package(), ethanol_water()] {
        for (partial, list) in [(true, ""), (false, vapour), (true, &format!("{vapour}, {liquid}") as &str)] {
            let extra = if partial { r#", "condenser_type": "partial", "murphree_efficiency": 0.8"# } else { "" };
            let u = build(&draws(config(&thermo, extra), list), &thermo).unwrap();
            let Column::Rigorous(col) = &u else { panic!("not rigorous") };
            let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
            let slen = lay.stream.len();
            local[lay.inputs_offset() + IN_DISTILLATE] = local[F];
            local[lay.inputs_offset() + IN_BOTTOMS] = local[slen + F];
            let mut r = vec![0.0; n_eq(&u, &lay)];
            let mut jac = vec![0.0; r.len() * local.len()];
            let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
            u.jacobian(&io, &mut r, &mut jac);
            let n = local.len();
            let scaled = (0..r.len())
                .map(|k| r[k].abs() / (0..n).map(|j| (jac[k * n + j] * local[j]).abs()).fold(1e-300, f64::max))
                .fold(0.0, f64::max);
            let feed = io.inlet(0);
            let products: Vec<_> = (0..lay.n_outlets).map(|k| io.outlet(k)).collect();
            let q_r = io.input(IN_REBOILER_DUTY);
            let qc = io.var(col.qc());
            let energy = (q_r + feed.f() * feed.h() - qc - products.iter().map(|p| p.f() * p.h()).sum::<f64>()) / q_r;
            let comp = (0..2)
                .map(|j| (feed.f() * feed.z()[j] - products.iter().map(|p| p.f() * p.z()[j]).sum::<f64>()) / feed.f())
                .fold(0.0, |a: f64, b| a.max(b.abs()));
            let ix = StageIdx { nc: 2 };
            let stage_var = |s: usize, i: usize| io.var(col.stage(s - 1) + i);
            // Independent phase checks from the thermo package.
            let mut k = [0.0; 2];
            let mut phase_err: f64 = 0.0;
            let d = &products[0];
            if partial {
                let x_n = [stage_var(6, ix.x(0)), stage_var(6, ix.x(1))];
                thermo.k_values(stage_var(6, ix.t()), 101_325.0, &x_n, &mut k);
                for j in 0..2 {
                    phase_err = phase_err.max((d.z()[j] - k[j] * x_n[j]).abs());
                }
                phase_err = phase_err.max((d.z()[0] + d.z()[1] - 1.0).abs());
                let h_v = thermo.h_vap(d.t(), d.z());
                phase_err = phase_err.max((d.h() - h_v).abs() / h_v.abs());
                assert!((d.f() - stage_var(6, ix.v())).abs() < 1e-12 * d.f(), "V_N = D");
            }
            for (k, p) in products.iter().enumerate().skip(2) {
                let (s, vap) = (col.draws[k - 2].stage + 1, col.draws[k - 2].vapour);
                let z0 = if vap { ix.y(0) } else { ix.x(0) };
                let z = [stage_var(s, z0), stage_var(s, z0 + 1)];
                let h =
                    if vap { thermo.h_vap(stage_var(s, ix.t()), &z) } else { thermo.h_liq(stage_var(s, ix.t()), &z) };
                phase_err = phase_err.max((p.z()[0] - z[0]).abs()).max((p.z()[1] - z[1]).abs());
                phase_err = phase_err.max((p.h() - h).abs() / h.abs());
            }
            eprintln!(
                "{} partial {partial}, draws [{list}]: scaled residual {scaled:.1e}, energy {energy:.1e}, components {comp:.1e}, \
                 phase {phase_err:.1e}, D {:.4} mol/s, yD {:.6}, T_N {:.3} K, Qc {:.4e} W",
                vle_name(&thermo),
                d.f(),
                d.z()[0],
                d.t(),
                qc
            );
            assert!(scaled < 1e-9, "{scaled}");
            assert!(energy.abs() < 1e-9 && comp < 1e-9 && phase_err < 1e-12, "{energy} {comp} {phase_err}");
        }
    }
}

/// The `rigorous` additions of a column whose top pressure is a state.
const PRESSURE_STATES: [&str; 2] = [
    r#", "condenser_duty": QC, "vapour_volume": "1.5 m3", "tray_pressure_drop": "0.8 kPa""#,
    r#", "condenser": {"coolant_flow": "15 kg/s", "coolant_T_in": "300 K", "ua": "50 kW/K"}, "vapour_volume": "2 m3", "murphree_efficiency": 0.7"#,
];

/// With a pressure state: the dual-number Jacobian agrees with finite differences, the declared
/// pattern holds every nonzero of it, and the coloured Jacobian is the dense one.
#[test]
fn pressure_state_jacobian_and_pattern() {
    let mut rng = Lcg(11);
    for thermo in [binary_package(), ethanol_water()] {
        for extra in PRESSURE_STATES {
            let u = build(&config(&thermo, extra), &thermo).unwrap();
            let (lay, base) = at_guess(&u, &thermo, &feed(&thermo));
            let pattern = Unit::pattern(&u, &lay).expect("the rigorous column declares its pattern");
            let coloring = crate::Coloring::new(&pattern, n_eq(&u, &lay), lay.len());
            let declared: std::collections::HashSet<(usize, usize)> = pattern.iter().copied().collect();
            for _ in 0..3 {
                let local: Vec<f64> = base.iter().map(|v| v * rng.range(0.97, 1.03)).collect();
                let err = jacobian_error(&u, &lay, &thermo, &local, n_eq(&u, &lay));
                assert!(err < 1e-6, "{extra}: {err}");
                let (m, n) = (n_eq(&u, &lay), lay.len());
                let io = UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 };
                let (mut r, mut dense, mut colored) = (vec![0.0; m], vec![0.0; m * n], vec![0.0; m * n]);
                Unit::jacobian(&u, &io, &mut r, &mut dense);
                Unit::jacobian_colored(&u, &io, &mut r, &mut colored, Some(&coloring));
                for i in 0..m {
                    for j in 0..n {
                        let v = dense[i * n + j];
                        assert!(v == 0.0 || declared.contains(&(i, j)), "{extra}: ({i}, {j}) = {v} undeclared");
                        assert!((colored[i * n + j] - v).abs() <= 1e-12 * v.abs().max(1.0), "{extra}: ({i}, {j})");
                    }
                }
            }
        }
    }
}

/// A pressure state needs a condenser whose duty is an input.
#[test]
fn pressure_state_needs_a_condenser_input() {
    let thermo = binary_package();
    let errs = build(&config(&thermo, r#", "vapour_volume": "1 m3""#), &thermo).unwrap_err();
    assert!(errs.iter().any(|e| e.to_string().contains("rigorous.vapour_volume")), "{errs:?}");
    let errs = build(&config(&thermo, r#", "condenser_duty": 1e6, "vapour_volume": "-1 m3""#), &thermo).unwrap_err();
    assert_eq!(errs.len(), 1, "{errs:?}");
}
