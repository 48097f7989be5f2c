//! Inside the packing: the contacts a step records, and what the packing observer makes
//! of them (src/observe/packing.rs).

mod common;

use common::read_vtp;
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

#[test]
fn the_frames_contacts_are_the_steps_forces_in_both_files() {
    // A run with output.contacts and frames writes, per frame after the first, the
    // contacts as VTK lines and as CSV; read back from the files, each free grain's
    // contacts sum to the force its frame holds (Newton's third law; the files keep
    // every digit: 1e-12 of the largest force for the order of the sums), and the CSV
    // holds the same contacts as the VTK file.
    let mut scene = grainlab::scene::builtin::shear_cell(200, 0.012);
    scene.output.contacts = true;
    scene.output.frames = 2;
    scene.duration = 4e-4;
    let tmp = tempfile::tempdir().unwrap();
    let opts = grainlab::study::run::RunOptions { out: Some(tmp.path().to_path_buf()), ..Default::default() };
    grainlab::study::run::run_scene(&scene, &opts).unwrap();
    let pvd = std::fs::read_to_string(tmp.path().join("contacts.pvd")).unwrap();
    assert!(pvd.contains("frames/contacts_00002.vtp") && !pvd.contains("contacts_00000"), "{pvd}");
    assert!(!tmp.path().join("frames/contacts_00000.vtp").exists(), "step 0 computed no contacts");
    let g = read_vtp(&tmp.path().join("frames/grains_00002.vtp"));
    let c = read_vtp(&tmp.path().join("frames/contacts_00002.vtp"));
    let n = g["radius_m"].len();
    let m = c["grain"].len();
    assert!(m > 100, "{m} contacts");
    assert_eq!(c["position_m"].len(), 6 * m, "two points per line");
    let mut sum = vec![[0.0f64; 2]; n];
    let mut count = vec![0.0; n];
    for k in 0..m {
        let (i, j) = (c["grain"][k] as usize, c["partner"][k]);
        let f = [c["force_n"][3 * k], c["force_n"][3 * k + 1]];
        sum[i][0] += f[0];
        sum[i][1] += f[1];
        count[i] += 1.0;
        if j >= 0.0 {
            sum[j as usize][0] -= f[0];
            sum[j as usize][1] -= f[1];
            count[j as usize] += 1.0;
        }
        // The normal and tangential parts add up to the force.
        let fn_ = c["normal_force_n"][k];
        for a in 0..2 {
            let parts = c["normal"][3 * k + a] * fn_ + c["tangential_force_n"][3 * k + a];
            assert!((parts - f[a]).abs() <= 1e-15 * fn_.abs().max(1.0));
        }
    }
    let scale = (0..m).map(|k| c["normal_force_n"][k].abs()).fold(0.0, f64::max);
    for i in (0..n).filter(|&i| g["wall_grain"][i] == 0.0) {
        for a in 0..2 {
            assert!((sum[i][a] - g["force_n"][3 * i + a]).abs() <= 1e-12 * scale, "grain {i}: contacts {:?}, frame {}", sum[i], g["force_n"][3 * i + a]);
        }
    }
    assert_eq!(count, g["contacts"], "each grain's contact count");
    assert_eq!(g["id"], (0..n).map(|i| i as f64).collect::<Vec<_>>());
    // The per-grain stress: each free grain's is (x_c - x_p) f summed over its contacts,
    // whose trace for a grain pressed from all sides is negative (tension positive).
    let s = &g["stress_volume_n_m"];
    assert_eq!(s.len(), 9 * n);
    let pressed = (0..n).filter(|&i| count[i] >= 2.0 && g["wall_grain"][i] == 0.0).filter(|&i| s[9 * i] + s[9 * i + 4] < 0.0).count();
    assert!(pressed * 10 >= 9 * (0..n).filter(|&i| count[i] >= 2.0 && g["wall_grain"][i] == 0.0).count());
    // The CSV: one row per contact, the same numbers.
    let csv = std::fs::read_to_string(tmp.path().join("frames/contacts_00002.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), m);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!([r[0], r[1], r[2], r[3], r[6], r[7], r[8], r[9], r[10]], [c["grain"][k], c["partner"][k], c["contact_point_m"][3 * k], c["contact_point_m"][3 * k + 1], c["overlap_m"][k], c["normal_force_n"][k], c["tangential_force_n"][3 * k], c["tangential_force_n"][3 * k + 1], c["sliding"][k]]);
    }
}

#[test]
fn the_summary_and_the_profiles_balance_the_walls_across_the_gap() {
    // A run with output.contacts: summary.json's time-averaged packing stress equals the
    // walls' stresses (momentum balance), and so does every layer's in profiles.csv: in
    // steady shear without gravity d sigma_yx / dy = d sigma_yy / dy = 0 across the gap.
    // Tolerances: the run's own 95% intervals, combined in quadrature, for the whole cell
    // (both means from the same window, blocks as the summary makes them); per layer
    // three times that (26 layers tested at once, and a layer one diameter thick
    // assigns a grain's whole stress to the layer of its centre).
    let mut scene = grainlab::scene::builtin::shear_cell(300, 0.012);
    scene.output.contacts = true;
    scene.output.frames = 0;
    scene.duration = 0.012;
    let tmp = tempfile::tempdir().unwrap();
    let opts = grainlab::study::run::RunOptions { out: Some(tmp.path().to_path_buf()), ..Default::default() };
    let s = grainlab::study::run::run_scene(&scene, &opts).unwrap();
    let shear = s.shear.unwrap();
    let pk = shear.packing.expect("the packing's averages");
    let (tau, sigma) = (shear.shear_stress_pa, shear.normal_stress_pa);
    let within = |a: f64, b: f64, ca: f64, cb: f64, k: f64| (a - b).abs() <= k * (ca * ca + cb * cb).sqrt();
    eprintln!("tau {:.0} +- {:.0}, sigma_yx {:.0} +- {:.0}; sigma {:.0} +- {:.0}, sigma_yy {:.0} +- {:.0}", tau.mean, tau.ci95, pk.sigma_yx_pa.mean, pk.sigma_yx_pa.ci95, sigma.mean, sigma.ci95, pk.sigma_yy_pa.mean, pk.sigma_yy_pa.ci95);
    assert!(sigma.mean > 5e4 && tau.mean > 0.1 * sigma.mean);
    assert!(within(pk.sigma_yx_pa.mean, tau.mean, pk.sigma_yx_pa.ci95, tau.ci95, 1.0));
    assert!(within(-pk.sigma_yy_pa.mean, sigma.mean, pk.sigma_yy_pa.ci95, sigma.ci95, 1.0));
    assert!(pk.coordination.mean > 2.0 && pk.coordination_without_rattlers.mean >= pk.coordination.mean);
    let csv = std::fs::read_to_string(tmp.path().join("profiles.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap_or(f64::NAN)).collect()).collect();
    assert!(rows.len() >= 10, "{} layers", rows.len());
    for r in &rows {
        let (syx, syy) = (r[col("sigma_yx_pa")], r[col("sigma_yy_pa")]);
        assert!(within(syx, tau.mean, r[col("sigma_yx_pa_ci95")], tau.ci95, 3.0), "layer {}: sigma_yx {syx:.0} +- {:.0}, tau {:.0}", r[0], r[col("sigma_yx_pa_ci95")], tau.mean);
        assert!(within(-syy, sigma.mean, r[col("sigma_yy_pa_ci95")], sigma.ci95, 3.0), "layer {}: sigma_yy {syy:.0}, sigma {:.0}", r[0], sigma.mean);
        let phi = r[col("solid_fraction")];
        assert!(phi > 0.6 && phi < 0.91, "layer {}: solid fraction {phi}", r[0]);
    }
    // The mean x velocity goes from the bottom wall's side (-V) to the top's (+V); where
    // in between the shear localises is the packing's choice (here mostly at one wall).
    let vx: Vec<f64> = rows.iter().map(|r| r[col("velocity_x_m_s")]).collect();
    assert!(vx[0] < 0.0 && vx[vx.len() - 1] > 0.0 && vx.iter().all(|v| v.abs() < 0.5), "{vx:?}");
}

#[test]
fn the_packing_observers_memory_is_estimated_before_anything_runs() {
    // Each kept sample holds a profile of up to MAX_PROFILE_LAYERS layers: a scene that
    // asks for contacts at very many samples is refused by the budget, naming the field
    // (before the engine is built), and runs with the observers off.
    let mut scene = grainlab::scene::builtin::shear_cell(300, 0.012);
    scene.output.samples = 100_000;
    let limits = grainlab::scene::limits::Limits::with_memory(1 << 30);
    assert!(grainlab::study::accuracy::build_limited(&scene, 1, &limits).is_ok());
    scene.output.contacts = true;
    let msg = grainlab::study::accuracy::build_limited(&scene, 1, &limits).err().expect("over budget").to_string();
    assert!(msg.contains("output.contacts") && msg.contains("packing observers"), "{msg}");
}
