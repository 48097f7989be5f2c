//! Property tests: the cell list finds exactly the pairs brute force finds.

use grainlab::boundary::Boundary;
use grainlab::dim::Vec2;
use grainlab::neighbor::{brute_force_pairs, cell_pairs};
use proptest::prelude::*;

fn packing() -> impl Strategy<Value = (Vec<Vec2>, Vec<f64>, usize, bool, f64)> {
    (2usize..250, 1.0f64..10.0, any::<bool>(), 0.0f64..0.5, any::<u64>()).prop_flat_map(|(n, ratio, periodic, skin, _)| {
        let grains = prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), n);
        (grains, Just(ratio), Just(periodic), Just(skin), 0..=n)
            .prop_map(|(g, ratio, periodic, skin, n_free)| {
                // A box about the right size for a dense packing of n grains of radius
                // 0.01..0.01*ratio; some overlap, some touch across the periodic edge.
                let r: Vec<f64> = g.iter().map(|t| 0.01 * (1.0 + (ratio - 1.0) * t.2)).collect();
                let side = (r.iter().map(|r| 4.0 * r * r).sum::<f64>()).sqrt() * 1.2;
                let x = g.iter().map(|t| Vec2::new(t.0 * side, t.1 * side)).collect();
                (x, r, n_free, periodic, skin * 0.01)
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn cell_list_equals_brute_force((x, r, n_free, periodic, skin) in packing()) {
        let side = x.iter().map(|p| p.x).fold(0.0, f64::max) + 1e-9;
        let b = if periodic { Boundary::periodic_x(0.0, side) } else { Boundary::open() };
        let brute = brute_force_pairs(&x, &r, n_free, &b, skin);
        let cells = cell_pairs(&x, &r, n_free, &b, skin, &mut Vec::new(), &mut Vec::new());
        prop_assert_eq!(cells, brute);
    }
}
