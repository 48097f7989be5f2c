//! `grainlab ensemble`: one shear scene over several packing seeds, the ensemble mean with
//! a 95% interval from the run-to-run spread, beside each run's block interval.

use grainlab::scene::builtin::{builtin, shear_cell};
use grainlab::scene::limits::Limits;
use grainlab::study::ensemble::{ensemble, parse_seeds};

#[test]
fn three_seeds_give_three_packings_and_the_t_interval_of_their_spread() {
    // 300 grains over 1.5 ms: short runs, each with its blocks of tau/sigma.
    let scene = shear_cell(300, 0.012);
    let mut heard = Vec::new();
    let e = ensemble(&scene, &[1, 2, 3], Some(1.5e-3), 1, &Limits::machine(), |r| heard.push(r.seed)).unwrap();
    assert_eq!(heard, vec![1, 2, 3]);
    assert!(e.runs.iter().all(|r| r.status == "completed"), "{:?}", e.runs);
    let x: Vec<f64> = e.runs.iter().map(|r| r.stress_ratio.unwrap().mean).collect();
    // Different seeds, different packings, different histories.
    assert!(x[0] != x[1] && x[1] != x[2] && x[0] != x[2], "{x:?}");
    let s = e.stress_ratio.as_ref().unwrap();
    let mean = x.iter().sum::<f64>() / 3.0;
    let std = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
    assert_eq!(s.runs, 3);
    approx::assert_relative_eq!(s.mean, mean, max_relative = 1e-12);
    approx::assert_relative_eq!(s.std, std, max_relative = 1e-12);
    // t(0.975) with 2 degrees of freedom is 4.303 (any table of Student's t): the
    // interval from the spread of three runs, to the table's four digits.
    approx::assert_relative_eq!(s.ci95, 4.303 * std / 3f64.sqrt(), max_relative = 1e-3);
    let blocks = e.runs.iter().map(|r| r.stress_ratio.unwrap().ci95).sum::<f64>() / 3.0;
    approx::assert_relative_eq!(s.mean_block_ci95.unwrap(), blocks, max_relative = 1e-12);
    // A run's standard error is its half-width over t(0.975, blocks - 1); t from
    // statrs, checked against the table where the blocks allow (2 blocks: 12.706).
    let se = |r: &grainlab::study::ensemble::EnsembleRun| {
        let x = r.stress_ratio.unwrap();
        x.ci95 / statrs::distribution::ContinuousCDF::inverse_cdf(&statrs::distribution::StudentsT::new(0.0, 1.0, (x.blocks - 1) as f64).unwrap(), 0.975)
    };
    let mean_se = e.runs.iter().map(se).sum::<f64>() / 3.0;
    approx::assert_relative_eq!(s.mean_block_standard_error.unwrap(), mean_se, max_relative = 1e-12);
    approx::assert_relative_eq!(s.spread_over_standard_error.unwrap(), std / mean_se, max_relative = 1e-12);
    approx::assert_relative_eq!(statrs::distribution::ContinuousCDF::inverse_cdf(&statrs::distribution::StudentsT::new(0.0, 1.0, 1.0).unwrap(), 0.975), 12.706, max_relative = 1e-4);
    // The top wall carries the confining load (100 kPa): the ensemble's mean normal
    // stress is that within its own 95% interval (wide for so small and short a cell).
    let sigma = e.normal_stress_pa.as_ref().unwrap();
    assert!((sigma.mean - 1e5).abs() < sigma.ci95, "{sigma:?}");
    assert!(e.packing_fraction.as_ref().is_some_and(|p| p.mean > 0.5 && p.mean < 0.9 && p.mean_block_ci95.is_none()));
}

#[test]
fn an_ensemble_needs_a_packing_and_a_shear_analysis_and_sane_seeds() {
    let err = ensemble(&builtin("collision").unwrap(), &[1, 2], None, 1, &Limits::machine(), |_| {}).unwrap_err().to_string();
    assert!(err.contains("grains") && err.contains("grains.pack"), "{err}");
    let mut s = shear_cell(300, 0.012);
    s.analysis = grainlab::scene::Analysis::None;
    let err = ensemble(&s, &[1, 2], None, 1, &Limits::machine(), |_| {}).unwrap_err().to_string();
    assert!(err.contains("analysis") && err.contains("shear"), "{err}");
    assert_eq!(parse_seeds("1..8").unwrap(), (1..=8).collect::<Vec<u64>>());
    assert_eq!(parse_seeds("4, 9,2").unwrap(), vec![4, 9, 2]);
    for bad in ["5", "1,1", "3..1", "0..1000", "a..b", "1..", ""] {
        let err = parse_seeds(bad).unwrap_err().to_string();
        assert!(err.contains("--seeds"), "{bad}: {err}");
    }
}
