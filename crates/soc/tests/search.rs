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

/// The principal square root of a symmetric positive definite matrix, by its eigenvectors.
fn square_root(a: &Mat<f64>) -> Mat<f64> {
    let e = a.self_adjoint_eigen(faer::Side::Lower).unwrap();
    let (u, n) = (e.U(), a.nrows());
    let s: Vec<f64> = e.S().column_vector().iter().map(|l| l.sqrt()).collect();
    Mat::from_fn(n, n, |i, j| (0..n).map(|k| u[(i, k)] * s[k] * u[(j, k)]).sum())
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
            let juu_half = square_root(&model.parts().juu);
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

fn evaporator() -> LocalModel {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/evaporator.json");
    plantwide_soc::matrices::read(&path).unwrap()
}

fn ranked(model: &LocalModel, size: usize, criterion: Criterion) -> Vec<(Vec<usize>, f64)> {
    let search = Search { size, best: 6, criterion, max_nodes: 100_000 };
    let r = branch_and_bound(model, &search).unwrap();
    r.subsets.iter().map(|c| (c.measurements.clone(), criterion.of(&c.losses))).collect()
}

/// A change of units (of the cost, of the measurements, of the disturbances) changes no ranking
/// and scales the losses exactly as it should, however far it goes: found by a hostile test,
/// where a cost in units 1e200 times larger ranked the average loss wrongly, measurements in units
/// 1e155 times smaller overflowed Y Yᵀ, and disturbances 1e200 times larger failed the null space.
#[test]
fn the_rankings_do_not_depend_on_the_units_of_the_data() {
    let base = evaporator();
    let scaled = |f: &dyn Fn(&mut Parts)| {
        let mut p = base.parts().clone();
        f(&mut p);
        LocalModel::new(p).unwrap()
    };
    let cost = scaled(&|p| {
        p.juu = &p.juu * 1e200;
        p.jud = &p.jud * 1e200;
    });
    let units = scaled(&|p| {
        p.gy = &p.gy * 1e155;
        p.gyd = &p.gyd * 1e155;
        p.wn = &p.wn * 1e155;
    });
    let disturbances = scaled(&|p| {
        p.gyd = &p.gyd * 1e200;
        p.jud = &p.jud * 1e200;
        p.wd = &p.wd * 1e-200;
    });
    for criterion in [Criterion::Worst, Criterion::Average] {
        for size in [2, 3, 5] {
            let reference = ranked(&base, size, criterion);
            for (model, factor) in [(&cost, 1e200), (&units, 1.0), (&disturbances, 1.0)] {
                let other = ranked(model, size, criterion);
                for ((s, l), (t, m)) in reference.iter().zip(&other) {
                    assert_eq!(s, t, "{criterion:?} size {size}");
                    assert!(close(*m, l * factor, 1e-9), "{criterion:?} size {size}: {m:e} vs {:e}", l * factor);
                }
            }
        }
    }
    let (a, b) = (null_space(&base, &[0, 3, 4, 6, 8]).unwrap(), null_space(&disturbances, &[0, 3, 4, 6, 8]).unwrap());
    assert!(close(b.losses.worst_case, a.losses.worst_case, 1e-9));
}

/// Measurements that cannot tell the inputs apart: a subset of them is never ranked (it was listed
/// with a loss of 1e30 from round-off), and data whose every subset is such are refused by field.
#[test]
fn rank_deficient_measurements_are_never_ranked() {
    let base = random_model(77, 2, 1, 6);
    let mut p = base.parts().clone();
    // y0, y1 and y3 move only with u0 (y1 and y3 in exact multiples of y0): any pair of them,
    // and any triple of them, holds one input only.
    for (row, k) in [(1, 2.0), (3, -3.0)] {
        for j in 0..2 {
            p.gy[(row, j)] = k * p.gy[(0, j)];
        }
    }
    p.gy[(0, 1)] = 0.0;
    p.gy[(1, 1)] = 0.0;
    p.gy[(3, 1)] = 0.0;
    let model = LocalModel::new(p.clone()).unwrap();
    for size in [2, 3] {
        let search = Search { size, best: 50, criterion: Criterion::Worst, max_nodes: 100_000 };
        let r = branch_and_bound(&model, &search).unwrap();
        let e = enumerate(&model, &search).unwrap();
        assert!(r.subsets.iter().all(|c| !c.measurements.iter().all(|m| [0, 1, 3].contains(m))), "size {size}");
        assert_eq!(r.subsets.len(), e.subsets.len());
        assert!(e.rank_deficient > 0);
    }
    // Every measurement independent of u1: the data cannot hold two inputs.
    for row in 0..6 {
        p.gy[(row, 1)] = 0.5 * p.gy[(row, 0)];
    }
    let err = LocalModel::new(p).unwrap_err();
    assert!(err.to_string().contains("`Gy`: has rank 1 but there are 2 inputs"), "{err}");
}
