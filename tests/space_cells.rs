//! The neighbour search in space (issue 30): the cell list written once for the plane
//! and space finds, among spheres in a box periodic in x, in z, in both or in neither,
//! exactly the pairs brute force finds (a grid of 27-cell neighbourhoods, dense or sorted
//! by cell for far-flung spheres); its largest and mean overlaps are brute force's; and
//! the periodic cell's minimum image and wrap act in z as in x.

use grainlab::kernels::cells::{brute_force_pairs, cell_pairs, largest_overlap, mean_overlap};
use grainlab::kernels::threads::Threads;
use grainlab::physics::boundary::Boundary;
use grainlab::physics::dim::{Plane, Space, Vec2};
use nalgebra::Vector3;
use proptest::prelude::*;

type Vec3 = Vector3<f64>;

/// Spheres of radius 0.01 to 0.01 ratio at random in a cube about the size of a dense
/// packing of them (some overlap, some touch across the periodic faces); the last
/// `n - n_free` are wall grains; periodic in x and in z or not.
fn packing() -> impl Strategy<Value = (Vec<Vec3>, Vec<f64>, usize, (bool, bool), f64)> {
    (2usize..300, 1.0f64..10.0, any::<(bool, bool)>(), 0.0f64..0.5).prop_flat_map(|(n, ratio, periodic, skin)| {
        let grains = prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), n);
        (grains, Just(ratio), Just(periodic), Just(skin), 0..=n).prop_map(|(g, ratio, periodic, skin, n_free)| {
            let r: Vec<f64> = g.iter().map(|t| 0.01 * (1.0 + (ratio - 1.0) * t.3)).collect();
            let side = r.iter().map(|r| 8.0 * r * r * r).sum::<f64>().cbrt() * 1.2;
            let x = g.iter().map(|t| Vec3::new(t.0, t.1, t.2) * side).collect();
            (x, r, n_free, periodic, skin * 0.01)
        })
    })
}

/// The box's periodic cell along x and z as asked: from 0 to just past the farthest centre.
fn boundary(x: &[Vec3], (px, pz): (bool, bool)) -> Boundary<Space> {
    let side = |a: usize| x.iter().map(|p| p[a]).fold(0.0, f64::max) + 1e-9;
    Boundary::<Space>::periodic(px.then(|| (0.0, side(0))), pz.then(|| (0.0, side(2))))
}

/// Brute force's largest overlap over the smaller radius (first pair in (i, j) order
/// among equals) and mean overlap over the mean radius.
fn brute_overlaps(x: &[Vec3], r: &[f64], n_free: usize, b: &Boundary<Space>) -> (Option<(usize, usize, f64)>, Option<(f64, usize)>) {
    let (mut worst, mut sum, mut count) = (None::<(usize, usize, f64)>, 0.0, 0);
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            if i >= n_free && j >= n_free {
                continue;
            }
            let dn = r[i] + r[j] - b.image(x[i] - x[j]).norm();
            if dn > 0.0 {
                let ratio = dn / r[i].min(r[j]);
                if worst.is_none_or(|w| ratio > w.2) {
                    worst = Some((i, j, ratio));
                }
                sum += dn / (0.5 * (r[i] + r[j]));
                count += 1;
            }
        }
    }
    (worst, (count > 0).then(|| (sum / count as f64, count)))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn cell_list_in_space_equals_brute_force((x, r, n_free, periodic, skin) in packing()) {
        let b = boundary(&x, periodic);
        let brute = brute_force_pairs(&x, &r, n_free, &b, skin);
        let cells = cell_pairs(&x, &r, n_free, &b, skin, &mut Vec::new(), &mut Vec::new(), &Threads::serial());
        prop_assert_eq!(&cells, &brute);
        // The test means something: a dense box of free spheres has pairs.
        if n_free > 100 {
            prop_assert!(!brute.is_empty());
        }
        let (worst, mean) = brute_overlaps(&x, &r, n_free, &b);
        let found = largest_overlap(&x, &r, n_free, &b, f64::INFINITY);
        prop_assert_eq!(found.map(|w| w.2), worst.map(|w| w.2));
        let m = mean_overlap(&x, &r, n_free, &b);
        // The same overlaps summed in another order: to rounding.
        prop_assert_eq!(m.map(|m| m.1), mean.map(|m| m.1));
        if let (Some(a), Some(c)) = (m, mean) {
            prop_assert!((a.0 - c.0).abs() <= 1e-12 * c.0, "{} {}", a.0, c.0);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// A few spheres flung far away (up to 1e6 box sizes along every axis): the grid would
    /// need far more cells than spheres (more than a u64 counts, without the cap per
    /// axis), so the spheres are sorted by cell; the pairs are still brute force's.
    #[test]
    fn cell_list_in_space_with_spheres_far_apart((x, r, n_free, periodic, skin) in packing(), far in prop::collection::vec((0usize..300, -6.0f64..6.0, -6.0f64..6.0, -6.0f64..6.0), 1..4)) {
        let mut x = x;
        let b = boundary(&x, periodic);
        let side = x.iter().map(|p| p.amax()).fold(0.0, f64::max) + 1e-9;
        for (k, (i, ex, ey, ez)) in far.iter().enumerate() {
            let i = i % x.len();
            // Two flung spheres may land together: the second next to the first.
            x[i] = if k == 1 { x[far[0].0 % x.len()] + Vec3::new(0.0, r[i], 0.0) } else { Vec3::new(10f64.powf(*ex), 10f64.powf(*ey), 10f64.powf(*ez)) * side };
        }
        // The periodic axes wrap the flung spheres back into the cell, as a run would.
        x.iter_mut().for_each(|p| b.wrap(p));
        let brute = brute_force_pairs(&x, &r, n_free, &b, skin);
        let cells = cell_pairs(&x, &r, n_free, &b, skin, &mut Vec::new(), &mut Vec::new(), &Threads::serial());
        prop_assert_eq!(cells, brute);
    }
}

#[test]
fn space_restricted_to_the_plane_lists_the_plane_pairs() {
    // Grains of the plane at z = 0: the same pairs, in the same order, periodic in x or not.
    let n = 400;
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let r: Vec<f64> = (0..n).map(|_| 0.01 * (1.0 + next())).collect();
    let x2: Vec<Vec2> = (0..n).map(|_| Vec2::new(next(), next()) * 0.5).collect();
    let x3: Vec<Vec3> = x2.iter().map(|p| Vec3::new(p.x, p.y, 0.0)).collect();
    for periodic in [false, true] {
        let (b2, b3) = if periodic { (Boundary::<Plane>::periodic_x(0.0, 0.5), Boundary::<Space>::periodic(Some((0.0, 0.5)), None)) } else { (Boundary::open(), Boundary::open()) };
        let p2 = cell_pairs(&x2, &r, 350, &b2, 0.002, &mut Vec::new(), &mut Vec::new(), &Threads::serial());
        let p3 = cell_pairs(&x3, &r, 350, &b3, 0.002, &mut Vec::new(), &mut Vec::new(), &Threads::serial());
        assert!(p2.len() > 100 && p2 == p3, "periodic {periodic}: {} pairs in the plane, {} in space", p2.len(), p3.len());
        assert_eq!(largest_overlap(&x2, &r, 350, &b2, f64::INFINITY), largest_overlap(&x3, &r, 350, &b3, f64::INFINITY));
    }
}

#[test]
fn the_periodic_cell_in_z() {
    let b = Boundary::<Space>::periodic(Some((-1.0, 4.0)), Some((2.0, 0.5)));
    // The minimum image along x and z at once; y is never periodic.
    let d = b.image(Vec3::new(3.0, 7.0, 0.4));
    assert!((d - Vec3::new(-1.0, 7.0, -0.1)).norm() < 1e-15, "{d:?}");
    for (z, want) in [(2.0, 2.0), (2.49, 2.49), (2.5, 2.0), (1.9, 2.4), (-3.2, 2.3)] {
        let mut p = Vec3::new(0.0, 1.0, z);
        b.wrap(&mut p);
        assert!((p.z - want).abs() < 1e-12 && p.x == 0.0 && p.y == 1.0, "{z} -> {p:?} (want {want})");
    }
    assert!(b.any_outside(&[Vec3::new(0.0, 0.0, 2.6)]) && !b.any_outside(&[Vec3::new(2.9, -5.0, 2.4)]));
    // Only z periodic: x passes through untouched.
    let z_only = Boundary::<Space>::periodic(None, Some((0.0, 1.0)));
    assert_eq!(z_only.image(Vec3::new(5.0, 0.0, 0.75)), Vec3::new(5.0, 0.0, -0.25));
    assert!(!z_only.is_periodic() && z_only.is_periodic_z());
    // Moved beyond the skin through the periodic face: 0.1 apart, not 0.4.
    assert!(!b.any_moved_beyond(&[Vec3::new(0.0, 0.0, 2.45)], &[Vec3::new(0.0, 0.0, 2.05)], 0.02) && b.any_moved_beyond(&[Vec3::new(0.0, 0.0, 2.3)], &[Vec3::new(0.0, 0.0, 2.05)], 0.02));
}
