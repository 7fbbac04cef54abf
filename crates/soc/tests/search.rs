//! Independent checks of the exact local method and the branch and bound on random local models:
//! the closed form against the loss matrix's definition, the optimality of its `H`, and the branch
//! and bound against the enumeration of every subset.

use faer::Mat;
use plantwide_soc::{
    Criterion, LocalModel, Parts, Search, branch_and_bound, enumerate, exact_local, losses_of, null_space,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A random model in the manner of Yi Cao's `randcase.m`, with a full (not diagonal) `Juu`.
fn random_model(seed: u64, nu: usize, nd: usize, ny: usize) -> LocalModel {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let mut m = |rows: usize, cols: usize, lo: f64| Mat::from_fn(rows, cols, |_, _| r.random_range(lo..1.0));
    let a = m(nu, nu + 2, -1.0);
    let juu = &a * a.transpose() + Mat::<f64>::identity(nu, nu) * 0.1;
    let (gy, gyd, jud) = (m(ny, nu, -1.0), m(ny, nd, 0.0), m(nu, nd, 0.0));
    let (wd, wn) = (m(nd, 1, 0.1), m(ny, 1, 0.1));
    let diag = |v: &Mat<f64>| Mat::from_fn(v.nrows(), v.nrows(), |i, j| if i == j { v[(i, 0)] } else { 0.0 });
    let names = |p: &str, n: usize| (0..n).map(|k| format!("{p}{k}")).collect();
    LocalModel::new(Parts {
        inputs: names("u", nu),
        disturbances: names("d", nd),
        measurements: names("y", ny),
        gy,
        gyd,
        juu,
        jud,
        wd: diag(&wd),
        wn: diag(&wn),
    })
    .unwrap()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs()
}

#[test]
fn the_closed_form_losses_are_those_of_the_loss_matrix_of_their_h() {
    for seed in 0..20 {
        let (nu, nd, ny) = (1 + seed as usize % 3, 1 + seed as usize % 2, 8);
        let model = random_model(seed, nu, nd, ny);
        for n in nu..=ny {
            let subset: Vec<usize> = (0..n)
                .map(|k| (k * 3 + seed as usize) % ny)
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            let c = exact_local(&model, &subset).unwrap().unwrap();
            // The definition M = −Juu^{1/2} (H Gy)⁻¹ H Y with the returned H.
            let direct = losses_of(&model, &subset, c.h.as_ref()).unwrap();
            assert!(close(direct.worst_case, c.losses.worst_case, 1e-9), "{seed} {subset:?}");
            assert!(close(direct.average, c.losses.average, 1e-9), "{seed} {subset:?}");
            // H is scaled so that H Gy_s = Juu^{1/2}.
            let gys = Mat::from_fn(subset.len(), nu, |i, j| model.parts().gy[(subset[i], j)]);
            let hg = &c.h * &gys;
            let juu_half = model.juu_half();
            assert!((0..nu).all(|i| (0..nu).all(|j| (hg[(i, j)] - juu_half[(i, j)]).abs() < 1e-9)));
        }
    }
}

#[test]
fn no_other_combination_of_the_subset_loses_less() {
    let mut r = ChaCha8Rng::seed_from_u64(7);
    for seed in 0..10 {
        let model = random_model(100 + seed, 2, 2, 9);
        let subset = [0, 2, 3, 5, 8];
        let best = exact_local(&model, &subset).unwrap().unwrap();
        let null = null_space(&model, &subset).unwrap();
        assert!(null.losses.worst_case >= best.losses.worst_case * (1.0 - 1e-12));
        for _ in 0..50 {
            let h = Mat::from_fn(2, 5, |i, j| best.h[(i, j)] * (1.0 + 0.2 * r.random_range(-1.0..1.0)));
            let other = losses_of(&model, &subset, h.as_ref()).unwrap();
            assert!(other.worst_case >= best.losses.worst_case * (1.0 - 1e-12));
            assert!(other.average >= best.losses.average * (1.0 - 1e-12));
        }
    }
}

#[test]
fn the_null_space_combination_cancels_every_disturbance() {
    // With n ≥ nu + nd measurements H [Gy Gyd] = [Juu^{1/2}, Juu^{-1/2} Jud], so H F = 0 (Alstad &
    // Skogestad 2007; Alstad et al. 2009, eq. 41): held constant, c moves with the noise alone.
    for seed in 0..5 {
        let model = random_model(200 + seed, 2, 2, 8);
        let subset = [0, 1, 2, 3, 4, 6];
        let c = null_space(&model, &subset).unwrap();
        let p = model.parts();
        let f = &p.gyd - &p.gy * model.juu_inv_jud();
        let fs = Mat::from_fn(subset.len(), 2, |i, j| f[(subset[i], j)]);
        let hf = &c.h * &fs;
        let scale = c.h.norm_l2() * fs.norm_l2();
        assert!(hf.norm_l2() < 1e-12 * scale, "{seed}: |H F| = {:e}", hf.norm_l2());
    }
}

#[test]
fn branch_and_bound_finds_the_subsets_enumeration_finds() {
    let mut cases = 0;
    for seed in 0..12 {
        let (nu, nd, ny) = (1 + seed as usize % 4, 1 + seed as usize % 3, 9 + seed as usize % 4);
        let model = random_model(1000 + seed, nu, nd, ny);
        for size in nu..=ny {
            for best in [1, 3, 10] {
                for criterion in [Criterion::Worst, Criterion::Average] {
                    let search = Search { size, best, criterion, max_nodes: 1_000_000 };
                    let (a, b) = (branch_and_bound(&model, &search).unwrap(), enumerate(&model, &search).unwrap());
                    let sets = |r: &plantwide_soc::Ranking| {
                        r.subsets.iter().map(|c| c.measurements.clone()).collect::<Vec<_>>()
                    };
                    assert_eq!(sets(&a), sets(&b), "seed {seed}, size {size}, best {best}, {criterion:?}");
                    cases += 1;
                }
            }
        }
    }
    assert!(cases > 500);
}
