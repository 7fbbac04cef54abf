//! Tuning the loops of a flowsheet from its exact linearization, checked by independent routes.

use faer::{Mat, c64};
use plantwide_flowsheet::{Plant, load_with};
use plantwide_studies::TuneError;
use plantwide_studies::tune::averaging::AveragingForm;
use plantwide_studies::tune::flowsheet::{LevelSwing, averaging_loop, integrating_gain};
use plantwide_studies::tune::loops::{LoopResponse, Measurement, loop_model, loop_ultimates, plant_blt, plant_loop};
use plantwide_studies::tune::{BltSettings, max_log_modulus};

/// The shipped two-column plant at its steady state, converged once for all tests of this file.
fn two_column_plant() -> (Plant, Vec<f64>) {
    static PLANT: std::sync::OnceLock<(Plant, Vec<f64>)> = std::sync::OnceLock::new();
    PLANT
        .get_or_init(|| {
            let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../flowsheets/two_column_plant.json");
            let plant = load_with(std::path::Path::new(path), &[]).unwrap();
            let sol = plantwide_solve::converge(&plant, &Default::default()).unwrap();
            (plant, sol.x)
        })
        .clone()
}

/// Eigenvalues of the loops' state-space model with loop `i` alone closed by the proportional
/// feedback `u = −k z` through a first-order measurement lag `dz/dt = (y − z)/τ_m`: the states
/// `[x; z]` with `dx/dt = A x − B_i k z`, `dz/dt = (C_i x − D_ii k z − z)/τ_m`.
fn closed_loop_eigenvalues(ss: &plantwide_analysis::linear::StateSpace, i: usize, k: f64, lag: f64) -> Vec<c64> {
    let n = ss.a.nrows();
    let a = Mat::from_fn(n + 1, n + 1, |r, c| match (r < n, c < n) {
        (true, true) => ss.a[(r, c)],
        (true, false) => -ss.b[(r, i)] * k,
        (false, true) => ss.c[(i, c)] / lag,
        (false, false) => (-ss.d[(i, i)] * k - 1.0) / lag,
    });
    a.eigenvalues().unwrap()
}

const LOOPS: [&str; 2] = ["column1_top_T", "column1_bottom_T"];

#[test]
fn ultimate_gains_of_the_plant_put_closed_loop_poles_on_the_imaginary_axis() {
    let (plant, x) = two_column_plant();
    let loops: Vec<_> = LOOPS.iter().map(|n| plant_loop(&plant, n).unwrap()).collect();
    let ss = loop_model(&plant, &x, &loops).unwrap().ss;
    // Without measurement dynamics the bottom loop (bottoms flow → tray 11 through the sump level
    // loop) rolls off like 1/ω² with its phase tending to −180° from above: no crossover.
    let bare = LoopResponse::new(loop_model(&plant, &x, &loops).unwrap(), Measurement::default());
    let err = loop_ultimates(&bare, &loops).unwrap_err();
    assert!(matches!(&err, TuneError::NoPhaseCrossover { output, .. } if output == "column1.T[11]"), "{err}");
    let lag = 30.0;
    let seen = LoopResponse::new(loop_model(&plant, &x, &loops).unwrap(), Measurement { dead_time: 0.0, lag });
    let ultimates = loop_ultimates(&seen, &loops).unwrap();
    for (i, u) in ultimates.iter().enumerate() {
        // The frequency search found K_u and ω_u from the sparse G(jω); an eigenvalue solve of the
        // closed loop at K_u must find the pair ±jω_u (the definition of the ultimate point).
        let ev = closed_loop_eigenvalues(&ss, i, u.ku, lag);
        let scale = ev.iter().map(|l| l.norm()).fold(0.0, f64::max);
        let near = ev.iter().min_by(|a, b| (a.im - u.omega_u).abs().total_cmp(&(b.im - u.omega_u).abs())).unwrap();
        assert!(near.re.abs() < 1e-8 * scale && (near.im - u.omega_u).abs() < 1e-6 * u.omega_u, "{near} vs {u:?}");
    }
}

#[test]
fn plant_blt_reaches_luybens_target_log_modulus() {
    let (plant, x) = two_column_plant();
    let loops: Vec<_> = LOOPS.iter().map(|n| plant_loop(&plant, n).unwrap()).collect();
    let minute = Measurement { dead_time: 60.0, lag: 0.0 };
    let t = plant_blt(&plant, &x, &loops, minute, &BltSettings::default()).unwrap();
    let f = t.detuning_factor.unwrap();
    assert!(f >= 1.0, "{t:?}");
    // Settings are ZN/F of each loop's own ultimate values.
    for l in &t.loops {
        assert!(
            (l.kc - l.ku / 2.2 / f).abs() < 1e-12 * l.kc.abs() && (l.tau_i - l.pu / 1.2 * f).abs() < 1e-9 * l.tau_i
        );
    }
    // An independent evaluation of the peak: the dense state-space solve `D + C (jωI − A)⁻¹ B`
    // instead of the sparse LU of `jωM − J`, on a grid four times finer around the peak: 2n = 4 dB (or below, when F = 1 already keeps it there).
    let ss = loop_model(&plant, &x, &loops).unwrap().ss;
    let g = |w: f64| {
        let g = ss.frequency_response(w);
        Mat::from_fn(2, 2, |i, k| g[(i, k)] * minute.response(w))
    };
    let kc: Vec<f64> = t.loops.iter().map(|l| l.kc).collect();
    let ti: Vec<f64> = t.loops.iter().map(|l| l.tau_i).collect();
    let w = t.peak_omega.unwrap();
    let (_, peak) = max_log_modulus(&g, &kc, &ti, (w / 10.0, w * 10.0), 200);
    if f > 1.0 {
        assert!((peak - 4.0).abs() < 1e-6, "peak {peak} dB, {t:?}");
    } else {
        assert!(peak <= 4.0 + 1e-9, "peak {peak} dB");
    }
}

#[test]
fn a_name_that_is_no_pid_loop_is_refused_with_the_loops_listed() {
    let (plant, _) = two_column_plant();
    let err = plant_loop(&plant, "column1_top").unwrap_err();
    let TuneError::NotALoop { loops, .. } = &err else { panic!("{err}") };
    assert!(loops.contains("column1_top_T") && loops.contains("reactor_level"), "{err}");
}

#[test]
fn a_tanks_integrating_gain_is_its_molar_volume_over_its_area() {
    // Flow-set outflow: dM/dt = F_in − F_out and level = M v_L / A, so d(level)/dt per unit outflow
    // is −v_L/A, v_L = V/M at the steady state and A = π d²/4 with d = 1.5 m.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../flowsheets/surge_tank.json");
    let plant = load_with(std::path::Path::new(path), &[]).unwrap();
    let x = plantwide_solve::converge(&plant, &Default::default()).unwrap().x;
    let l = plant_loop(&plant, "level_control").unwrap();
    let du = 10.0 / 3.6;
    let k = integrating_gain(&plant, &x, &l, LevelSwing { du, band: 0.5 }).unwrap();
    let v_l = x[plant.var("tank.V").unwrap()] / x[plant.var("tank.M").unwrap()];
    let area = std::f64::consts::PI * 1.5f64.powi(2) / 4.0;
    assert!((k + v_l / area).abs() < 1e-6 * v_l / area, "{k} vs {}", -v_l / area);
    // P-only averaging for a 10 kmol/h inflow step in a ±0.5 m band: |Kc| = 10 kmol/h / 0.5 m,
    // direct action (more level, more outflow), filter time Δh/(|k| Δu).
    let t = averaging_loop(&plant, &x, &l, Some(du), Some(0.5), AveragingForm::P).unwrap();
    let e = &t.loops[0];
    assert!((e.kc + du / 0.5).abs() < 1e-12 * du && e.action == "direct" && e.file_action.is_none(), "{e:?}");
    let tau = e.averaging.unwrap().time;
    assert!((tau - 0.5 * area / (v_l * du)).abs() < 1e-5 * tau, "{tau}");
    // A temperature is no level: for a swing of a tenth of the reflux it settles inside a band of a
    // quarter of its value.
    let (two, x2) = two_column_plant();
    let l2 = plant_loop(&two, "column1_top_T").unwrap();
    let swing = LevelSwing { du: 0.1 * x2[l2.op].abs(), band: 0.25 * x2[l2.pv].abs() };
    let err = integrating_gain(&two, &x2, &l2, swing).unwrap_err();
    assert!(matches!(err, TuneError::NotIntegrating { .. }), "{err}");
}

/// Generated cyclohexane/n-heptane column 0x9d41ed2c17189e4b: BLT of its two quality loops listed
/// as AC101, AC102 and as AC102, AC101 moved AC102's gain crossover by 1.3e-5 (its element, a
/// bottoms purity at 2e-4 driven by the reboiler duty, is 1e-13 per W beside flows of order one,
/// and is resolved to about 1e-6 of its size by arithmetic that the loops' order changed). The
/// loops are now computed in the file's order, so both listings give the same settings and margins
/// to the bit. Checked by a second route: at the reported crossover, the loop's element evaluated as
/// `C (jωM − J)⁻¹ B` on the full sparse Jacobian (not the reduced state space's Hessenberg form the
/// study uses) times the PI `K_c (1 + 1/(jω τ_I))` and the dead time `e^(−jωθ)` has modulus 1 and
/// the reported phase margin.
#[test]
fn blt_settings_and_margins_do_not_depend_on_the_order_the_loops_are_listed_in() {
    use plantwide_studies::tune::request::{TuneRequest, tune};
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/generated/rigorous_9d41ed2c.json");
    let plant = load_with(std::path::Path::new(path), &[]).unwrap();
    let x = plantwide_solve::converge(&plant, &Default::default()).unwrap().x;
    let request = |loops: &str| -> TuneRequest {
        serde_json::from_str(&format!(r#"{{"loops": [{loops}], "method": "blt", "measurement_dead_time": "1 min"}}"#))
            .unwrap()
    };
    let a = tune(&plant, &x, &request(r#""AC101", "AC102""#)).unwrap().tuning;
    let mut b = tune(&plant, &x, &request(r#""AC102", "AC101""#)).unwrap().tuning;
    assert_eq!(b.loops[0].controller, "AC102");
    b.loops.reverse();
    assert_eq!(a, b);
    let l = &a.loops[1];
    let m = l.margins.unwrap();
    let (w, pm) = (m.gain_crossover.unwrap(), m.phase_margin.unwrap());
    let loops = [plant_loop(&plant, "AC101").unwrap(), plant_loop(&plant, "AC102").unwrap()];
    let manual = plantwide_studies::tune::loops::in_manual(&plant, &x, &loops);
    let lin = plantwide_analysis::linear::Linearization::new(&manual, &x, &manual.input_values());
    let g = lin.response(&[loops[1].op_manual], &[loops[1].pv]).unwrap().at(w).unwrap()[(0, 0)];
    let c = c64::new(l.kc, 0.0) * (c64::new(1.0, 0.0) + c64::new(0.0, -1.0 / (w * l.tau_i.unwrap())));
    let lw = g * c * c64::new(0.0, -60.0 * w).exp();
    let phase_margin = 180.0 + lw.arg().to_degrees();
    assert!((lw.norm() - 1.0).abs() < 1e-4, "|L(jω_gc)| = {}", lw.norm());
    assert!((phase_margin - pm).abs() < 1e-3, "phase margin {phase_margin} against {pm}");
}
