//! Inside the packing: the contacts a step records, and what the packing observer makes
//! of them (src/observe/packing.rs).

use grainlab::engine::world::View;
use grainlab::observe::packing::packing_row;
use grainlab::observe::stress::WallAverager;
use grainlab::physics::contact::Partner;
use grainlab::physics::dim::Vec2;

fn cell(grains: usize) -> grainlab::engine::build::Built {
    let mut scene = grainlab::scene::builtin::shear_cell(grains, 0.012);
    scene.output.contacts = true;
    grainlab::study::accuracy::build(&scene).unwrap()
}

#[test]
fn the_recorded_contacts_add_up_to_every_grains_force_and_every_walls() {
    // Newton's third law and the stage's own sums: the recorded forces on each free
    // grain add up to the force the step left on it, and the forces of the contacts
    // with each wall's glued grains to minus the wall's force; only the order of the
    // sums differs, so they agree to rounding (1e-12 of the largest contact force).
    let mut b = cell(300);
    let e = &mut b.engine;
    for _ in 0..3000 {
        e.step().unwrap();
    }
    assert!(e.view().contacts.is_empty(), "nothing recorded unless wanted");
    e.want_contacts();
    e.step().unwrap();
    let v = e.view();
    let p = v.particles;
    assert!(v.contacts.len() > 100, "{} contacts", v.contacts.len());
    let mut sum = vec![Vec2::zeros(); p.len()];
    let mut on_wall = [Vec2::zeros(); 2];
    let scale = v.contacts.iter().map(|c| c.force().norm()).fold(0.0, f64::max);
    for c in v.contacts {
        let (i, f) = (c.i as usize, c.force());
        sum[i] += f;
        match c.partner {
            Partner::Grain(j) if (j as usize) < p.n_free => sum[j as usize] -= f,
            Partner::Grain(j) => {
                let k = if (p.x[j as usize].y - v.walls[0].y).abs() < (p.x[j as usize].y - v.walls[1].y).abs() { 0 } else { 1 };
                on_wall[k] -= f;
            }
            Partner::Wall(k) => on_wall[k as usize] -= f,
        }
        assert!(c.overlap > 0.0 && c.normal.norm() > 0.0);
    }
    for i in 0..p.n_free {
        assert!((sum[i] - p.f[i]).norm() <= 1e-12 * scale, "grain {i}: recorded {:?}, applied {:?}", sum[i], p.f[i]);
    }
    for k in 0..2 {
        assert!((on_wall[k] - v.walls[k].force).norm() <= 1e-11 * scale, "wall {k}: recorded {:?}, applied {:?}", on_wall[k], v.walls[k].force);
    }
    // The next step records nothing new, and the view no longer shows the old ones.
    e.step().unwrap();
    assert!(e.view().contacts.is_empty());
}

#[test]
fn the_packings_stress_balances_the_walls_in_steady_shear() {
    // Momentum balance across the gap: on time average the free grains' mean stress
    // (Love-Weber contact part plus kinetic part, over L t H) has sigma_yy = -sigma and
    // sigma_yx = tau of the walls. The two series are sampled alike (every 200 steps,
    // the walls' forces averaged over each interval, the packing at its end); the
    // tolerance is the 95% interval of the mean difference over the samples (Student's
    // t of the per-sample differences: the identity holds exactly only on average, the
    // rate of change of the grains' moment sum y m v_x being what differs per sample).
    let mut b = cell(300);
    let (length, depth) = (b.length, b.depth);
    let e = &mut b.engine;
    let mut walls = WallAverager::default();
    let (mut dyy, mut dyx, mut taus, mut sigmas) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (every, settle, samples) = (200, 20_000, 150);
    for k in 1..=(settle + every * samples) {
        if k > settle && k % every == 0 {
            e.want_contacts();
        }
        e.step().unwrap();
        walls.accumulate(&e.view());
        if k > settle && k % every == 0 {
            let v: View = e.view();
            let row = packing_row(&v, length, depth).expect("contacts on both walls");
            let w = walls.row(&v, length, depth).unwrap();
            dyy.push(row.sigma_yy_pa + w.normal_stress_pa);
            dyx.push(row.sigma_yx_pa - w.shear_stress_pa);
            taus.push(w.shear_stress_pa);
            sigmas.push(w.normal_stress_pa);
        } else if k == settle {
            walls = WallAverager::default();
        }
    }
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let half = |x: &[f64]| {
        let m = mean(x);
        let sd = (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64).sqrt();
        1.98 * sd / (x.len() as f64).sqrt()
    };
    let (sigma, tau) = (mean(&sigmas), mean(&taus));
    eprintln!("sigma {sigma:.1} Pa, tau {tau:.1} Pa; sigma_yy + sigma: {:.1} +- {:.1}; sigma_yx - tau: {:.1} +- {:.1}", mean(&dyy), half(&dyy), mean(&dyx), half(&dyx));
    assert!(sigma > 5e4 && tau > 0.1 * sigma, "a sheared, loaded cell: sigma {sigma}, tau {tau}");
    assert!(mean(&dyy).abs() <= half(&dyy) && half(&dyy) < 0.05 * sigma);
    assert!(mean(&dyx).abs() <= half(&dyx) && half(&dyx) < 0.05 * sigma);
}
