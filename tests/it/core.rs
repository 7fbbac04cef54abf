//! The equation-oriented core on small plants, against closed forms and independent methods.

use crate::harness::{component_balance_error, converge, flowsheet, value};
use plantwide::flowsheet::{Plant, assemble, load_file, parse_spec};
use plantwide::solve::{NewtonSettings, steady_state};

fn newton_only() -> NewtonSettings {
    NewtonSettings { pseudo_transient: false, ..NewtonSettings::default() }
}

/// Enthalpy flow of a stream [W].
fn enthalpy_flow(plant: &Plant, x: &[f64], stream: &str) -> f64 {
    value(plant, x, &format!("{stream}.F")) * value(plant, x, &format!("{stream}.h"))
}

#[test]
fn flash_recycle_loop_converges_by_newton_alone_from_a_cold_start() {
    let plant = load_file(std::path::Path::new(&flowsheet("flash_recycle.json"))).unwrap();
    let u = plant.input_values();
    let ss = steady_state(&plant, &u, None, &newton_only()).unwrap_or_else(|e| panic!("{e}"));
    assert!(ss.report.history.iter().all(|h| h.pseudo_dt.is_none()));
    let x = &ss.x;
    assert!(component_balance_error(&plant, x, &[]) < 1e-9);
    // Plant energy balance: feed enthalpy + heater duty = products' enthalpy (adiabatic drum, mixer, splitter).
    let e_in = enthalpy_flow(&plant, x, "feed") + value(&plant, x, "heater.Q");
    let e_out = enthalpy_flow(&plant, x, "vapour") + enthalpy_flow(&plant, x, "bottoms");
    assert!((e_in - e_out).abs() < 1e-9 * value(&plant, x, "heater.Q"), "{e_in} vs {e_out}");
    // The drum is a real two-phase drum: vapour and liquid in equilibrium at the drum pressure.
    let v = value(&plant, x, "vapour.F");
    assert!(v > 0.1 * value(&plant, x, "feed.F") && value(&plant, x, "bottoms.F") > 0.1 * value(&plant, x, "feed.F"));
    let (t, p) = (value(&plant, x, "vapour.T"), value(&plant, x, "vapour.P"));
    let xl: Vec<f64> = plant.components().iter().map(|c| value(&plant, x, &format!("liquid.x[{c}]"))).collect();
    let mut k = vec![0.0; 3];
    plant.thermo().k_values(t, p, &xl, &mut k);
    for (j, c) in plant.components().iter().enumerate() {
        assert!((value(&plant, x, &format!("vapour.x[{c}]")) - k[j] * xl[j]).abs() < 1e-10);
    }
}

/// Reduced steady-state energy balance of the jacketed CSTR of `cstr_multiplicity.json`, with the
/// mass balance solved in closed form (x_A = F/(F + k M)) and the jacket eliminated.
fn cstr_energy_residual(t: f64) -> f64 {
    let (f, m, cp, t0, dh, e, r) = (10.0, 1000.0, 150.0, 300.0, -5.0e4, 8.0e4, 8.314_462_618);
    let (tc, wc, cpc, ua) = (300.0, 5.0, 4184.0, 2000.0);
    let k = 0.01 * (-(e / r) * (1.0 / t - 1.0 / 350.0)).exp();
    let xa = f / (f + k * m);
    let tj = (wc * cpc * tc + ua * t) / (wc * cpc + ua);
    f * cp * (t0 - t) + ua * (tj - t) - dh * k * m * xa
}

fn bisect(mut lo: f64, mut hi: f64) -> f64 {
    let flo = cstr_energy_residual(lo);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (cstr_energy_residual(mid) > 0.0) == (flo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Cold start moved to a reactor temperature `t`: reactor holdups, energy, jacket and effluent
/// consistent with the closed-form mass balance at that temperature.
fn guess_at(plant: &Plant, t: f64) -> Vec<f64> {
    let mut x = plant.initial_guess();
    let (f, m) = (10.0, 1000.0);
    let k = 0.01 * (-(8.0e4 / 8.314_462_618) * (1.0 / t - 1.0 / 350.0)).exp();
    let xa = f / (f + k * m);
    let comp = [xa, 1.0 - xa];
    let h = plant.thermo().h_liq(t, &comp);
    let tj = (5.0 * 4184.0 * 300.0 + 2000.0 * t) / (5.0 * 4184.0 + 2000.0);
    let mut set = |p: &str, v: f64| {
        let i = plant.var(p).unwrap_or_else(|| panic!("{p}"));
        x[i] = v;
    };
    set("effluent.T", t);
    set("effluent.h", h);
    set("effluent.x[A]", comp[0]);
    set("effluent.x[B]", comp[1]);
    set("reactor.N[A]", m * comp[0]);
    set("reactor.N[B]", m * comp[1]);
    set("reactor.U", m * h);
    set("reactor.Tj", tj);
    set("reactor.Q", 2000.0 * (tj - t));
    set("reactor.rate[1]", k * m * comp[0] / 0.1);
    x
}

#[test]
fn exothermic_cstr_has_three_steady_states_found_from_three_guesses() {
    // Independent roots of the reduced energy balance (brackets from a scan of its sign).
    let roots = [bisect(295.0, 320.0), bisect(320.0, 400.0), bisect(400.0, 500.0)];
    assert!(
        (roots[0] - 301.848).abs() < 0.01 && (roots[1] - 335.787).abs() < 0.01 && (roots[2] - 450.020).abs() < 0.01
    );
    let plant = load_file(std::path::Path::new(&flowsheet("cstr_multiplicity.json"))).unwrap();
    let u = plant.input_values();
    for (&root, start) in roots.iter().zip([300.0, 336.5, 460.0]) {
        let x0 = guess_at(&plant, start);
        let ss = steady_state(&plant, &u, Some(&x0), &newton_only()).unwrap_or_else(|e| panic!("from {start} K: {e}"));
        let t = value(&plant, &ss.x, "effluent.T");
        assert!((t - root).abs() < 1e-6, "from {start} K converged to {t} K, expected {root} K");
        // First-order kinetics: conversion kτ/(1 + kτ) with τ = M/F.
        let k = 0.01 * (-(8.0e4 / 8.314_462_618) * (1.0 / t - 1.0 / 350.0)).exp();
        let tau = value(&plant, &ss.x, "reactor.M") / value(&plant, &ss.x, "feed.F");
        let conversion = value(&plant, &ss.x, "effluent.x[B]");
        assert!((conversion - k * tau / (1.0 + k * tau)).abs() < 1e-9, "X = {conversion}");
        assert!((value(&plant, &ss.x, "reactor.level") - 1.0).abs() < 1e-9, "PI level control holds the level");
    }
}

#[test]
fn pi_level_loop_holds_its_setpoint_and_p_only_leaves_the_predicted_offset() {
    let (plant, ss) = converge("surge_tank.json");
    assert!((value(&plant, &ss.x, "tank.level") - 2.0).abs() < 1e-9);
    assert!(component_balance_error(&plant, &ss.x, &[]) < 1e-12);

    // P-only: same loop without reset; move the inflow by ΔF and the level moves by ΔF/Kc.
    let text = std::fs::read_to_string(flowsheet("surge_tank.json")).unwrap().replace("\"tau_i\": \"10 min\", ", "");
    let spec = parse_spec(&text, "surge_tank_p_only").unwrap();
    let plant = assemble(&spec, "surge_tank_p_only").unwrap();
    let mut u = plant.input_values();
    let base = steady_state(&plant, &u, None, &NewtonSettings::default()).unwrap();
    // At the bias flow the P-only loop has no offset.
    assert!((value(&plant, &base.x, "tank.level") - 2.0).abs() < 1e-9);
    let i = plant.input("inflow_rate").unwrap();
    let df = 10.0 / 3.6; // +10 kmol/h in mol/s
    u[i] += df;
    let moved = steady_state(&plant, &u, Some(&base.x), &NewtonSettings::default()).unwrap();
    let kc = 50.0 / 3.6; // 50 kmol/h per m in (mol/s)/m
    let dlevel = value(&plant, &moved.x, "tank.level") - 2.0;
    assert!((dlevel - df / kc).abs() < 1e-9, "offset {dlevel} m, theory {} m", df / kc);
}

/// Every shipped flowsheet's assembled Jacobian agrees with central differences of its residual.
#[test]
fn plant_jacobians_match_central_differences() {
    for name in ["column_a.json", "flash_recycle.json", "cstr_multiplicity.json", "surge_tank.json"] {
        let (plant, ss) = converge(name);
        let u = ss.u.clone();
        for x in [plant.initial_guess(), ss.x.clone()] {
            let n = plant.n_vars();
            let mut r = vec![0.0; n];
            let (mut jx, mut ju) = (Vec::new(), Vec::new());
            plant.jacobian(&x, &u, 0.0, &mut r, &mut jx, &mut ju);
            let mut dense = vec![0.0; n * n];
            for &(i, j, v) in &jx {
                dense[i * n + j] += v;
            }
            let row_scale: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| (dense[i * n + j] * plant.vars()[j].spec.nominal).abs()).fold(1e-300, f64::max))
                .collect();
            let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
            let mut worst: f64 = 0.0;
            for j in 0..n {
                let h = 1e-6 * x[j].abs().max(plant.vars()[j].spec.nominal * 1e-3);
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[j] += h;
                xm[j] -= h;
                plant.residual(&xp, &u, 0.0, &mut rp);
                plant.residual(&xm, &u, 0.0, &mut rm);
                for i in 0..n {
                    let fd = (rp[i] - rm[i]) / (2.0 * h);
                    let err = (fd - dense[i * n + j]).abs() * plant.vars()[j].spec.nominal / row_scale[i];
                    worst = worst.max(err);
                }
            }
            assert!(worst < 1e-6, "{name}: Jacobian mismatch {worst:e}");
        }
    }
}

/// Parallel block evaluation gives exactly the sequential result.
#[test]
fn parallel_and_sequential_jacobians_are_identical() {
    use plantwide::flowsheet::Parallelism;
    for name in ["column_a.json", "flash_recycle.json"] {
        let plant = load_file(std::path::Path::new(&flowsheet(name))).unwrap();
        let (x, u) = (plant.initial_guess(), plant.input_values());
        let n = plant.n_vars();
        let run = |par| {
            let mut r = vec![0.0; n];
            let (mut jx, mut ju) = (Vec::new(), Vec::new());
            plant.jacobian_with(par, &x, &u, 0.0, &mut r, &mut jx, &mut ju);
            (r, jx, ju)
        };
        assert!(run(Parallelism::Sequential) == run(Parallelism::Rayon), "{name}");
    }
}
