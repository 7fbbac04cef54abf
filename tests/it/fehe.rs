//! The reactor with a feed–effluent exchanger (`flowsheets/fehe_reactor.json`) and without it
//! (`fehe_reactor_without_fehe.json`): steady state against the closed forms of an adiabatic
//! first-order CSTR, the open-loop instability the exchanger's positive feedback causes (its
//! linearized eigenvalues against the closed forms of the two-state reactor model), and that
//! instability seen in a nonlinear dynamic run.

use plantwide::analysis::linear::Linearization;
use plantwide::flowsheet::{Override, Plant, load_with};
use plantwide::solve::{StrategySettings, converge};

use crate::harness::{flowsheet, plantwide, value};

const R: f64 = 8.314_462_618;
/// The reactor's data, as in the files: k(420 K) = 0.04 1/s (k0 chosen for it), Ea, adiabatic
/// rise −Δh/c_p, τ = M/F = 1 kmol / 10 mol/s, feed at 300 K.
const K: f64 = 0.04;
const EA: f64 = 150e3;
const DT_AD: f64 = 5625.0 / 150.0;
const TAU: f64 = 100.0;
const T0: f64 = 300.0;

/// A converged plant: its variables `x` and inputs `u`.
struct Steady {
    x: Vec<f64>,
    u: Vec<f64>,
}

fn load(name: &str, sets: &[(&str, &str)]) -> (Plant, Steady) {
    let overrides: Vec<Override> = sets.iter().map(|(p, v)| Override::new(*p, *v)).collect();
    let plant = load_with(std::path::Path::new(&flowsheet(name)), &overrides).unwrap_or_else(|e| panic!("{e}"));
    let sol = converge(&plant, &StrategySettings::default()).unwrap_or_else(|e| panic!("{e}"));
    (plant, Steady { x: sol.x, u: sol.u })
}

fn eigenvalues(plant: &Plant, ss: &Steady) -> Vec<(f64, f64)> {
    let lin = Linearization::new(plant, &ss.x, &ss.u);
    let model = lin.state_space(&[plant.input("feed_T").unwrap()], &[plant.var("effluent.T").unwrap()]).unwrap();
    model.eigenvalues().unwrap().iter().map(|l| (l.re, l.im)).collect()
}

/// `dk/dT = k Ea/(R T²)` [1/(s K)] at 420 K.
fn k_prime() -> f64 {
    K * EA / (R * 420.0 * 420.0)
}

/// `ΔT_ad dX/dT = ΔT_ad X (1 − X) Ea/(R T²)`, `X = 1 − x`: the rise of the adiabatic reactor's
/// steady outlet per degree of its inlet, the reactor's own positive feedback.
fn generation_slope(x: f64) -> f64 {
    DT_AD * x * (1.0 - x) * EA / (R * 420.0 * 420.0)
}

#[test]
fn the_steady_state_is_the_adiabatic_cstr_closed_form() {
    for name in ["fehe_reactor.json", "fehe_reactor_without_fehe.json"] {
        let (plant, ss) = load(name, &[]);
        let v = |p: &str| value(&plant, &ss.x, p);
        let (t, x) = (v("effluent.T"), v("effluent.x[A]"));
        // X = kτ/(1 + kτ) at 420 K; the adiabatic rise ΔT_ad X (equal c_p: exact).
        assert!((t - 420.0).abs() < 1e-6, "{name}: T = {t}");
        assert!((x - 1.0 / (1.0 + K * TAU)).abs() < 1e-8, "{name}: x_A = {x}");
        assert!((t - v("heated.T") - DT_AD * (1.0 - x)).abs() < 1e-7, "{name}");
        let f = v("feed.F");
        // The trim heater's duty (its controller's output) is its stream's enthalpy rise, F c_p ΔT.
        let inlet = if name.contains("without") { "feed.T" } else { "preheated.T" };
        let duty = v("trim.Q");
        assert!((duty - f * 150.0 * (v("heated.T") - v(inlet))).abs() < 1e-9 * duty, "{name}: duty {duty}");
        assert!((v("temperature_control.op") - duty).abs() < 1e-9 * duty);
        if !name.contains("without") {
            // The exchanger gives the feed what it takes from the effluent.
            let (cold, hot) = (v("preheated.T") - T0, t - v("cooled.T"));
            assert!((cold - hot).abs() < 1e-8 && (v("fehe.Q") - f * 150.0 * cold).abs() < 1e-6 * v("fehe.Q"));
        }
    }
}

/// Without the exchanger, the adiabatic CSTR's linearization has the two closed-form eigenvalues
/// `−1/τ` (the invariant `T + ΔT_ad x`) and `−1/τ − k + ΔT_ad k' x`, both stable; with it and the
/// temperature loop in manual, one real positive eigenvalue, as the static criterion `1 − ε <
/// ΔT_ad X (1 − X) Ea/(R T²)` predicts; in auto, none.
#[test]
fn the_exchanger_makes_the_open_loop_unstable_and_the_loop_stabilizes_it() {
    let manual = [("temperature_control.auto", "0")];
    let (plant, ss) = load("fehe_reactor_without_fehe.json", &manual);
    let ev = eigenvalues(&plant, &ss);
    let x = value(&plant, &ss.x, "effluent.x[A]");
    let second = -1.0 / TAU - K + DT_AD * k_prime() * x;
    for target in [-1.0 / TAU, second] {
        let near = ev.iter().map(|l| (l.0 - target).abs() + l.1.abs()).fold(f64::INFINITY, f64::min);
        assert!(near < 1e-6 * target.abs(), "eigenvalue {target} not among {ev:?}");
    }
    assert!(ev.iter().all(|l| l.0 < 0.0) && 1.0 > generation_slope(x), "stable without the exchanger");

    let (plant, ss) = load("fehe_reactor.json", &manual);
    let eps = (value(&plant, &ss.x, "preheated.T") - T0) / (420.0 - T0);
    assert!(1.0 - eps < generation_slope(x), "the static criterion says unstable: ε = {eps}");
    let unstable: Vec<_> = eigenvalues(&plant, &ss).into_iter().filter(|l| l.0 > 0.0).collect();
    assert_eq!(unstable.len(), 1, "{unstable:?}");
    assert!(unstable[0].1 == 0.0, "a real eigenvalue (a saddle, not a Hopf): {unstable:?}");

    let (plant, ss) = load("fehe_reactor.json", &[]);
    assert!(eigenvalues(&plant, &ss).iter().all(|l| l.0 < 0.0), "the temperature loop stabilizes it");
}

/// As the exchanger's holdups vanish, its cells become algebraic and the unstable eigenvalue
/// tends to the two-state reactor model's with the exchanger's steady effectiveness ε:
/// `[[−1/τ − k, −k' x], [ΔT_ad k, −(1 − ε)/τ + ΔT_ad k' x]]` — first order in the holdup.
#[test]
fn vanishing_exchanger_holdups_recover_the_two_state_closed_form() {
    let mut errors = Vec::new();
    for m in ["50 mol", "5 mol", "0.5 mol"] {
        let sets = [
            ("temperature_control.auto", "0"),
            ("fehe.holdup_hot", m),
            ("fehe.holdup_cold", m),
            (
                "fehe.wall_heat_capacity",
                if m == "50 mol" {
                    "50 J/K"
                } else if m == "5 mol" {
                    "5 J/K"
                } else {
                    "0.5 J/K"
                },
            ),
        ];
        let (plant, ss) = load("fehe_reactor.json", &sets);
        let x = value(&plant, &ss.x, "effluent.x[A]");
        let eps = (value(&plant, &ss.x, "preheated.T") - T0) / (420.0 - T0);
        let kp = k_prime();
        let (a, b, c, d) = (-1.0 / TAU - K, -kp * x, DT_AD * K, -(1.0 - eps) / TAU + DT_AD * kp * x);
        let (tr, det) = (a + d, a * d - b * c);
        let closed = (tr + (tr * tr - 4.0 * det).sqrt()) / 2.0;
        let top = eigenvalues(&plant, &ss).iter().map(|l| l.0).fold(f64::NEG_INFINITY, f64::max);
        errors.push((top - closed).abs() / closed);
    }
    assert!(errors[2] < 1e-3, "{errors:?}");
    assert!(errors.windows(2).all(|w| w[1] < 0.2 * w[0]), "first order: {errors:?}");
}

/// The nonlinear run with the loop in manual: a 0.01 K feed step grows as `e^{λt}`; the ratio of
/// successive differences (which cancels the step's constant part and, after 300 s, the decayed
/// stable modes) gives λ within 2 % of the linearization's unstable eigenvalue while the
/// deviation is small; in auto the reactor returns to its setpoint.
#[test]
fn the_dynamic_run_diverges_at_the_unstable_eigenvalue() {
    let dir = std::env::temp_dir().join(format!("plantwide_fehe_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = std::fs::read_to_string(flowsheet("scenarios/fehe_reactor_feed_temperature.json")).unwrap();
    let small = scenario.replace("\"300.2 K\"", "\"300.01 K\"").replace("1e-8", "1e-9").replace("\"10 s\"", "\"50 s\"");
    let sc = dir.join("small.json");
    std::fs::write(&sc, small).unwrap();
    let run = |extra: &[&str], csv: &str| {
        let csv = dir.join(csv);
        let mut args =
            vec!["run", &flowsheet("fehe_reactor.json")[..]].into_iter().map(String::from).collect::<Vec<_>>();
        args.extend(["--scenario", sc.to_str().unwrap(), "--csv", csv.to_str().unwrap()].map(String::from));
        args.extend(extra.iter().map(|s| s.to_string()));
        let out = plantwide(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(csv).unwrap();
        text.lines()
            .skip(1)
            .map(|l| {
                let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
                (f[0], f[1] - 420.0)
            })
            .collect::<Vec<(f64, f64)>>()
    };
    let (plant, ss) = load("fehe_reactor.json", &[("temperature_control.auto", "0")]);
    let predicted = eigenvalues(&plant, &ss).iter().map(|l| l.0).fold(f64::NEG_INFINITY, f64::max);
    let open = run(&["--set", "temperature_control.auto=0"], "open.csv");
    let at = |t: f64| open.iter().find(|p| (p.0 - t).abs() < 1e-6).map(|p| p.1).unwrap();
    let (a, b, c) = (at(300.0), at(500.0), at(700.0));
    let lambda = ((c - b) / (b - a)).ln() / 200.0;
    assert!(
        (lambda - predicted).abs() < 0.02 * predicted && c > 0.0,
        "λ: run {lambda:.4e}, linearization {predicted:.4e}"
    );
    assert!(open.last().unwrap().1 > 1.0, "the reactor runs away: {:?}", open.last());
    let closed = run(&[], "closed.csv");
    assert!(closed.last().unwrap().1.abs() < 1e-4 && closed.iter().all(|p| p.1.abs() < 0.01), "{:?}", closed.last());
    std::fs::remove_dir_all(&dir).ok();
}
