//! Results do not depend on the thread count, whoever calls (issue 55). faer is built without its
//! `rayon` feature, so every dense decomposition (eigenvalues, SVD, LU of the plant models and the
//! gains) runs sequentially in any caller's process, with no process-global switch to set; the
//! studies' own parallelism is over candidates, schemes and runs (rayon), each a pure function of
//! the plant and the request. `screen_pairings` and `compare`, called as a library in rayon pools
//! of 1 and 4 threads, give the same results bit for bit.

use plantwide::analysis::linear::Linearization;
use plantwide::analysis::shard::Share;
use plantwide::flowsheet::{Plant, load_file};
use plantwide::solve::{StrategySettings, converge};
use plantwide::studies::compare::{CompareSettings, Prices, compare};
use plantwide::studies::screen::pairings::{Disturbance, DynamicSettings, PairingRequest, screen_pairings};
use plantwide::studies::tune::loops::Measurement;

use crate::harness::{fixture, flowsheet};

fn plant(name: &str) -> Plant {
    load_file(std::path::Path::new(&fixture(name))).unwrap_or_else(|e| panic!("{e}"))
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

fn steps() -> Vec<Disturbance> {
    vec!["feed_source.F=+10%".parse().unwrap(), "feed_source.z[benzene]=-0.02".parse().unwrap()]
}

fn dynamic() -> DynamicSettings {
    DynamicSettings { candidates: 2, duration: Some(4.0 * 3600.0), measurement: Measurement::default() }
}

#[test]
fn screen_pairings_gives_the_same_digits_on_1_and_4_threads() {
    let p = plant("data/newcomer3/bt_column_lv.json");
    let request = PairingRequest {
        cvs: vec!["distillate.x[benzene]".into(), "bottoms.x[benzene]".into()],
        mvs: vec!["column.reflux".into(), "column.reboiler_duty".into()],
        throughput: Vec::new(),
        disturbances: steps(),
        watch: Vec::new(),
        dynamic: dynamic(),
        record: Vec::new(),
        mpc: None,
        share: Share::All,
    };
    let run = |threads| {
        let screen = in_pool(threads, || screen_pairings(&p, &request)).unwrap_or_else(|e| panic!("{e}"));
        serde_json::to_string(&screen).unwrap()
    };
    let (one, four) = (run(1), run(4));
    assert!(one.contains("\"dynamic\":{"), "the dynamic test ran: {one}");
    assert_eq!(one, four);
}

#[test]
fn compare_gives_the_same_digits_on_1_and_4_threads() {
    let plants = [plant("data/newcomer3/bt_column_lv.json"), plant("data/newcomer3/bt_column_lv_blt.json")];
    let request = CompareSettings {
        disturbances: steps(),
        outputs: vec!["bottoms.x[benzene]".into()],
        loops: Vec::new(),
        dynamic: dynamic(),
        file_tuning: false,
        prices: Prices::default(),
    };
    let run = |threads| {
        let c = in_pool(threads, || compare(&plants, &request)).unwrap_or_else(|e| panic!("{e}"));
        serde_json::to_string(&c).unwrap()
    };
    let (one, four) = (run(1), run(4));
    assert!(one.contains("\"runs\":["), "the closed-loop runs ran: {one}");
    assert_eq!(one, four);
}

/// The dense decompositions themselves, at a size where faer's parallel kernels differ from its
/// sequential ones: the eigenvalues of the two-column plant's 269-state model (`linearize`), in
/// pools of 1 and 4 threads. (With faer's `rayon` feature on, nearly every one of them differs in
/// its last bits; the two studies above are too small to show it.)
#[test]
fn the_eigenvalues_of_a_plant_model_are_the_same_on_1_and_4_threads() {
    let plant = load_file(std::path::Path::new(&flowsheet("two_column_plant.json"))).unwrap();
    let ss = converge(&plant, &StrategySettings::default()).unwrap_or_else(|e| panic!("{e}"));
    let (input, output) = (plant.input("fresh_A.F").unwrap(), plant.var("product.x[S]").unwrap());
    let eigenvalues = |threads| {
        in_pool(threads, || {
            let model = Linearization::new(&plant, &ss.x, &ss.u).state_space(&[input], &[output]);
            let ev = model.unwrap().eigenvalues().unwrap();
            ev.iter().map(|l| (l.re.to_bits(), l.im.to_bits())).collect::<Vec<_>>()
        })
    };
    let (one, four) = (eigenvalues(1), eigenvalues(4));
    assert!(one.len() > 200, "{} states", one.len());
    let differ = one.iter().zip(&four).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{differ} of {} eigenvalues differ in their bits", one.len());
}
