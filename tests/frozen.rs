//! Frozen-state cross-checks of the packing observers (src/workbench/frozen.rs): a small
//! shear cell run for 1500 steps, its contacts recorded, and the state they were computed
//! from evaluated without moving by LIGGGHTS 3.8.0 (`run 0`) and YADE 2023.02a (one step
//! of 1e-200 s), committed under reference/frozen/<case>/ by `scripts/regen-frozen` (CI
//! re-runs them with `--check`). The engine must still write the committed state, and
//! its contacts, stress, coordination and fabric must be the reference codes'.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use grainlab::workbench::frozen::{Frozen, freeze};

fn case(name: &str) -> (PathBuf, Frozen) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("reference/frozen").join(name);
    let scene = grainlab::scene::Scene::from_json(&std::fs::read_to_string(dir.join("scene.json")).unwrap()).unwrap();
    let info: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("case.json")).unwrap()).unwrap();
    let f = freeze(&scene, info["steps"].as_u64().unwrap()).unwrap();
    (dir, f)
}

/// A contact table (`i j cx cy nx ny dn Fnx Fny Ftx Fty`): (i, j) -> the nine numbers.
fn table(text: &str) -> BTreeMap<(u32, String), [f64; 9]> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            let v: Vec<f64> = w[2..].iter().map(|x| x.parse().unwrap()).collect();
            ((w[0].parse().unwrap(), w[1].to_string()), v.try_into().unwrap())
        })
        .collect()
}

/// Stress times volume (contact part, tension positive: the sum over contacts of
/// (x_c - x_i) F_i, and for a pair also (x_c - x_j) (-F_i) = -(x_i - x_j) F_i), the
/// coordination (contact ends per grain) and the fabric (mean n n) of a table, with the
/// grains' centres and radii.
fn measures(t: &BTreeMap<(u32, String), [f64; 9]>, grains: &BTreeMap<u32, [f64; 3]>) -> ([f64; 4], f64, [f64; 3]) {
    let (mut s, mut ends, mut fab) = ([0.0; 4], 0.0, [0.0; 3]);
    for ((i, j), v) in t {
        let (n, f) = ([v[2], v[3]], [v[5] + v[7], v[6] + v[8]]);
        let gi = grains[i];
        let arm = match j.parse::<u32>() {
            // x_j - x_i along n: the centres' distance r_i + r_j - dn.
            Ok(j) => [n[0] * (gi[2] + grains[&j][2] - v[4]), n[1] * (gi[2] + grains[&j][2] - v[4])],
            Err(_) => [v[0] - gi[0], v[1] - gi[1]],
        };
        s[0] += arm[0] * f[0];
        s[1] += arm[0] * f[1];
        s[2] += arm[1] * f[0];
        s[3] += arm[1] * f[1];
        ends += if j.parse::<u32>().is_ok() { 2.0 } else { 1.0 };
        fab[0] += n[0] * n[0];
        fab[1] += n[0] * n[1];
        fab[2] += n[1] * n[1];
    }
    let m = t.len() as f64;
    (s, ends / grains.len() as f64, [fab[0] / m, fab[1] / m, fab[2] / m])
}

fn grains(text: &str) -> BTreeMap<u32, [f64; 3]> {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let w: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (w[0] as u32, [w[1], w[2], w[3]])
        })
        .collect()
}

/// The committed state is what the engine writes now (else the reference evaluated
/// another state), and each contact of `code` is the engine's: the same pairs, normals
/// to 1e-12, overlaps to 1e-16 m, forces within `tol` of the largest contact force.
fn same_contacts(dir: &Path, f: &Frozen, code: &str, tol: f64) -> (BTreeMap<(u32, String), [f64; 9]>, BTreeMap<(u32, String), [f64; 9]>) {
    for (name, text) in [("scene.txt", &f.scene_txt), ("grains.txt", &f.grains_txt), ("history.txt", &f.history_txt), ("contacts.txt", &f.contacts_txt)] {
        assert_eq!(&std::fs::read_to_string(dir.join("state").join(name)).unwrap(), text, "state/{name}: the engine no longer writes the state the reference evaluated (scripts/regen-frozen)");
    }
    let ours = table(&f.contacts_txt);
    let theirs = table(&std::fs::read_to_string(dir.join("expected").join(code).join("contacts.txt")).unwrap());
    assert_eq!(ours.keys().collect::<Vec<_>>(), theirs.keys().collect::<Vec<_>>(), "{code} finds the same contacts");
    let fmax = ours.values().map(|v| v[5].hypot(v[6])).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for (k, a) in &ours {
        let b = theirs[k];
        for q in 2..4 {
            assert!((a[q] - b[q]).abs() <= 1e-12, "{k:?}: normal {a:?} vs {b:?}");
        }
        assert!((a[4] - b[4]).abs() <= 1e-16, "{k:?}: overlap {} vs {}", a[4], b[4]);
        for q in 5..9 {
            worst = worst.max((a[q] - b[q]).abs() / fmax);
            assert!((a[q] - b[q]).abs() <= tol * fmax, "{k:?}: force component {q}: {} vs {code} {} ({:.1e} of the largest)", a[q], b[q], (a[q] - b[q]).abs() / fmax);
        }
    }
    eprintln!("{code}: {} contacts, worst force difference {worst:.1e} of the largest contact force", ours.len());
    assert!(ours.len() > 100 && f.history_txt.lines().filter(|l| l.ends_with(" 1")).count() > 20, "a state with many contacts, some sliding");
    (ours, theirs)
}

/// The packing observer's stress (contact part, times its volume), coordination and
/// fabric against those of the reference's contact table, to 1e-9 relative.
fn same_measures(f: &Frozen, theirs: &BTreeMap<(u32, String), [f64; 9]>, g: &BTreeMap<u32, [f64; 3]>) {
    let row = f.packing.expect("contacts on both walls");
    let contact = [row.sigma_xx_pa - row.kinetic_xx_pa, row.sigma_xy_pa - row.kinetic_xy_pa, row.sigma_yx_pa - row.kinetic_xy_pa, row.sigma_yy_pa - row.kinetic_yy_pa].map(|s| s * f.volume_m3);
    let (s, z, fab) = measures(theirs, g);
    let scale = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for q in 0..4 {
        assert!((contact[q] - s[q]).abs() <= 1e-9 * scale, "stress component {q}: observer {} vs reference contacts {}", contact[q], s[q]);
    }
    assert!((row.coordination - z).abs() <= 1e-12 * z, "Z {} vs {z}", row.coordination);
    for (a, b) in [row.fabric_xx, row.fabric_xy, row.fabric_yy].into_iter().zip(fab) {
        assert!((a - b).abs() <= 1e-9, "fabric {a} vs {b}");
    }
}

#[test]
fn liggghts_evaluates_the_frozen_state_as_the_engine_did() {
    // Per contact: the same arithmetic on the same inputs, but the overlap
    // r_i + r_j - |d| cancels ~5 digits (dn/r down to 1e-5), so a force may differ by
    // ~1e-11 of its own size; measured 6.5e-13 of the largest: 1e-10.
    let (dir, f) = case("liggghts");
    let (ours, theirs) = same_contacts(&dir, &f, "liggghts", 1e-10);
    let g = grains(&f.grains_txt);
    same_measures(&f, &theirs, &g);
    // LIGGGHTS' own computes: contact/atom per grain (grain-grain contacts), and the
    // sum over grains of stress/atom pair (minus the virial: -sum over pairs of
    // (x_i - x_j) F_i, the grain pairs' share of the contact stress times volume).
    let summary = std::fs::read_to_string(dir.join("expected/liggghts/summary.txt")).unwrap();
    let mut lig = [0.0f64; 3];
    let mut counts: BTreeMap<u32, f64> = BTreeMap::new();
    for l in summary.lines().filter(|l| !l.starts_with('#')) {
        let w: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
        counts.insert(w[0] as u32, w[1]);
        for q in 0..3 {
            lig[q] += w[2 + q];
        }
    }
    let pairs: BTreeMap<_, _> = ours.into_iter().filter(|(k, _)| k.1.parse::<u32>().is_ok()).collect();
    let (s, _, _) = measures(&pairs, &g);
    let scale = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (ours, theirs) in [(s[0], lig[0]), (s[3], lig[1]), (s[1], lig[2])] {
        assert!((ours - theirs).abs() <= 1e-9 * scale, "stress/atom pair: engine {ours} vs LIGGGHTS {theirs}");
    }
    let mut ends: BTreeMap<u32, f64> = BTreeMap::new();
    for (i, j) in pairs.keys() {
        *ends.entry(*i).or_default() += 1.0;
        *ends.entry(j.parse().unwrap()).or_default() += 1.0;
    }
    for (i, c) in counts {
        assert_eq!(ends.get(&i).copied().unwrap_or(0.0), c, "grain {i}'s contacts (contact/atom)");
    }
}

#[test]
fn yade_evaluates_the_frozen_state_as_the_engine_did() {
    // YADE's contact geometry and damping are its own code: normal forces agree to
    // ~1e-13 between grains and to ~5e-9 relative on a wall, the same for every radius
    // (not traced in YADE's source; measured 4.8e-9 of the largest force). 1e-8.
    let (dir, f) = case("yade");
    let (_, theirs) = same_contacts(&dir, &f, "yade", 1e-8);
    let g = grains(&f.grains_txt);
    same_measures(&f, &theirs, &g);
    // YADE's own: avgNumInteractions is 2 C over every body (the grains and the two
    // walls); fabricTensor the mean n n over the grain pairs (walls left out).
    let summary = std::fs::read_to_string(dir.join("expected/yade/summary.txt")).unwrap();
    let value = |key: &str| -> Vec<f64> { summary.lines().find(|l| l.starts_with(key)).unwrap().split_whitespace().filter_map(|w| w.parse().ok()).collect() };
    let c = theirs.len() as f64;
    let z = value("avgNumInteractions")[0];
    assert!((z - 2.0 * c / (g.len() + 2) as f64).abs() <= 1e-12 * z, "avgNumInteractions {z} vs 2 C / (N + 2)");
    let pairs: BTreeMap<_, _> = theirs.iter().filter(|(k, _)| k.1.parse::<u32>().is_ok()).map(|(k, v)| (k.clone(), *v)).collect();
    let (_, _, fab) = measures(&pairs, &g);
    let yf = value("fabricTensor");
    for (a, b) in [(yf[0], fab[0]), (yf[1], fab[2]), (yf[2], fab[1])] {
        assert!((a - b).abs() <= 1e-9, "fabricTensor {a} vs the grain pairs' mean n n {b}");
    }
}
