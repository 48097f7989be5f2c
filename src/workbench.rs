//! The reference workbench: the cases grainlab is checked on, the reading of the
//! reference codes' output, and the comparison.
//!
//! A case is a scene plus the codes it is compared with. `grainlab cases` writes every
//! case under `reference/cases/<case>/`: `scene.json`, `case.json`, and what `grainlab
//! export` writes for each code (the deck, `grainlab.data`, `export.json`).
//! `scripts/regen-reference` runs each deck and hands its raw output to `grainlab
//! digest`, which measures it with the engine's own observers (the same estimator on
//! both sides) into `expected/<code>/`. `grainlab compare` and `tests/workbench.rs` run
//! the engine on each case and hold it to the committed numbers.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::boundary::Boundary;
use crate::contact::LeverArm;
use crate::dim::Vec2;
use crate::error::Error;
use crate::export::{Code, ExportInfo, export};
use crate::material::Material;
use crate::observe::impact::{CurvePoint, ImpactObserver, ImpactState, ImpactSummary};
use crate::observe::stress::WallRow;
use crate::output::csv::CsvSeries;
use crate::run::{RunOptions, ShearSummary, run_scene, stress_estimates};
use crate::scene::{Analysis, Scene, TangentialSpec};
use crate::scenes;

/// The restitution grid.
pub const GRID_E: [f64; 6] = [0.1, 0.3, 0.5, 0.7, 0.9, 0.99];
pub const GRID_V: [f64; 4] = [0.01, 0.1, 1.0, 10.0];
pub const GRID_STEPS: [f64; 2] = [50.0, 500.0];
/// Oblique impact angles from the normal, degrees.
pub const ANGLES: [f64; 7] = [5.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0];

/// What a case is for, stored as `case.json` beside its scene.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CaseInfo {
    /// Folder under reference/cases, e.g. `restitution/e0.5-v1-n50-clamp`.
    pub name: String,
    pub description: String,
    /// The codes that compute the same model.
    pub codes: Vec<Code>,
    /// Part of `regen-reference --quick` (and of CI's check that the data are real).
    pub quick: bool,
    /// Keep the force-overlap curve.
    pub curve: bool,
}

#[derive(Clone, Debug)]
pub struct Case {
    pub info: CaseInfo,
    pub scene: Scene,
}

fn glass(restitution: f64) -> Material {
    Material { restitution, ..Material::default() }
}

/// `1`, `0.1`, `10`: a number as it appears in case names.
fn num(v: f64) -> String {
    format!("{v}")
}

/// Every case of the workbench.
pub fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    for &e in &GRID_E {
        for &v in &GRID_V {
            for &n in &GRID_STEPS {
                for clamp in [false, true] {
                    let mut s = scenes::head_on(glass(e), 1e-3, v, n);
                    s.model.limit_force = clamp;
                    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
                    let name = format!("restitution/e{}-v{}-n{}-{}", num(e), num(v), num(n), if clamp { "clamp" } else { "free" });
                    s.name = name.replace('/', "-");
                    s.description = format!("head-on glass beads r = 1 mm, e = {e}, v = {v} m/s, dt = t_c/{n}, Fn clamp {}", if clamp { "on" } else { "off" });
                    let codes = if clamp { vec![Code::Liggghts, Code::Yade] } else { vec![Code::Liggghts] };
                    let curve = n == 500.0 && v == 1.0 && [0.1, 0.5, 0.9].contains(&e);
                    out.push(Case { info: CaseInfo { name, description: s.description.clone(), codes, quick: v == 1.0, curve }, scene: s });
                }
            }
        }
    }
    for &a in &ANGLES {
        for (target, builder) in [("wall", oblique_wall as fn(f64, TangentialSpec) -> Scene), ("pair", oblique_pair)] {
            for (form, code) in [(TangentialSpec::TotalDisplacement, Code::Liggghts), (TangentialSpec::IncrementalForce, Code::Yade)] {
                let mut s = builder(a, form);
                let tag = if code == Code::Liggghts { "history" } else { "incremental" };
                let name = format!("oblique-{target}/{tag}-a{}", num(a));
                s.name = name.replace('/', "-");
                out.push(Case { info: CaseInfo { name, description: s.description.clone(), codes: vec![code], quick: a == 45.0, curve: false }, scene: s });
            }
        }
    }
    let mut s = scenes::shear();
    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
    s.name = "shear-liggghts".into();
    s.description = "the shear cell (built-in `shear`) with LIGGGHTS' lever arm".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "shear/liggghts".into(), description: s.description.clone(), codes: vec![Code::Liggghts], quick: false, curve: false }, scene: s });
    let mut s = scenes::shear();
    matched(&mut s, TangentialSpec::IncrementalForce);
    s.name = "shear-yade".into();
    s.description = "the shear cell (built-in `shear`) with YADE's incremental tangential force, kinematics and clamp".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "shear/yade".into(), description: s.description.clone(), codes: vec![Code::Yade], quick: false, curve: false }, scene: s });
    out
}

/// Settings matched to the code that uses each tangential formulation: LIGGGHTS' lever
/// arm r - dn/2 and no clamp (its defaults); YADE's ratcheting-free kinematics and the
/// clamp it always applies.
fn matched(s: &mut Scene, form: TangentialSpec) {
    s.model.tangential = form;
    let yade = form == TangentialSpec::IncrementalForce;
    s.model.limit_force = yade;
    s.model.lever_arm = if yade { LeverArm::Yade } else { LeverArm::RadiusMinusHalfOverlap };
}

/// A glass bead (r = 1 mm, e = 0.9, mu = 0.5) hitting a flat glass wall at 1 m/s, `a` degrees from the normal.
pub fn oblique_wall(a: f64, form: TangentialSpec) -> Scene {
    let mut s = scenes::oblique(glass(0.9), 1e-3, 1.0, a, form, 200.0);
    matched(&mut s, form);
    s.description = format!("glass bead on a flat glass wall at 1 m/s, {a} deg from the normal, e = 0.9, mu = 0.5, t_c/200");
    s
}

/// A glass bead hitting a resting one at 1 m/s, `a` degrees between the approach and the
/// line of centres at contact.
pub fn oblique_pair(a: f64, form: TangentialSpec) -> Scene {
    let mut s = scenes::oblique_pair(glass(0.9), 1e-3, 1.0, a, form, 200.0);
    matched(&mut s, form);
    s.description = format!("glass bead on a resting one at 1 m/s, {a} deg from the line of centres, e = 0.9, mu = 0.5, t_c/200");
    s
}

/// Write every case (scene.json, case.json and each code's export) under `root`.
pub fn write_cases(root: &Path, filter: Option<&str>) -> Result<usize, Error> {
    let mut n = 0;
    for c in cases() {
        if filter.is_some_and(|f| !c.info.name.contains(f)) {
            continue;
        }
        write_case(&root.join(&c.info.name), &c)?;
        n += 1;
    }
    Ok(n)
}

pub fn write_case(dir: &Path, c: &Case) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display(), e))?;
    let w = |name: &str, text: String| std::fs::write(dir.join(name), text).map_err(|e| Error::io(dir.join(name).display(), e));
    w("scene.json", c.scene.to_json() + "\n")?;
    w("case.json", serde_json::to_string_pretty(&c.info).expect("serialisable") + "\n")?;
    for &code in &c.info.codes {
        export(&c.scene, code, dir)?;
    }
    Ok(())
}

/// Read a whitespace table with a header line (series.txt, walls.txt).
fn read_table(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), Error> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path.display(), e))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<String> = lines.next().ok_or_else(|| Error::Other(format!("{}: empty", path.display())))?.split_whitespace().map(String::from).collect();
    let mut rows = Vec::new();
    for (k, l) in lines.enumerate() {
        let row: Result<Vec<f64>, _> = l.split_whitespace().map(str::parse::<f64>).collect();
        let row = row.map_err(|_| Error::Other(format!("{}:{}: not a row of numbers: `{l}`", path.display(), k + 2)))?;
        if row.len() != header.len() {
            return Err(Error::Other(format!("{}:{}: {} values for {} columns", path.display(), k + 2, row.len(), header.len())));
        }
        rows.push(row);
    }
    Ok((header, rows))
}

fn read_info(case_dir: &Path) -> Result<(CaseInfo, ExportInfo), Error> {
    let read = |name: &str| std::fs::read_to_string(case_dir.join(name)).map_err(|e| Error::io(case_dir.join(name).display(), e));
    let case: CaseInfo = serde_json::from_str(&read("case.json")?).map_err(|e| Error::Other(format!("case.json: {e}")))?;
    let info: ExportInfo = serde_json::from_str(&read("export.json")?).map_err(|e| Error::Other(format!("export.json: {e}")))?;
    Ok((case, info))
}

/// Measure a reference code's raw output (in `run_dir`) with the engine's observers and
/// write `expected/<code>/` in `case_dir`.
pub fn digest(case_dir: &Path, code: Code, run_dir: &Path) -> Result<PathBuf, Error> {
    let (case, info) = read_info(case_dir)?;
    let out = case_dir.join("expected").join(code.name());
    std::fs::create_dir_all(&out).map_err(|e| Error::io(out.display(), e))?;
    match info.analysis {
        Analysis::Impact => {
            let (obs, summary) = impact_of_series(&info, &run_dir.join("series.txt"))?;
            CsvSeries::create(&out.join("impact.csv"))?.row(&summary)?;
            if case.curve {
                let mut w = CsvSeries::create(&out.join("force_overlap.csv"))?;
                for p in &obs.curve {
                    w.row(p)?;
                }
            }
        }
        Analysis::Shear => {
            let (_, rows) = read_table(&run_dir.join("walls.txt"))?;
            let series: Vec<WallRow> = rows
                .iter()
                .map(|r| WallRow::new(r[0] * info.time_step_s, Vec2::new(r[1], r[2]), Vec2::new(r[3], r[4]), r[5], info.length_m, info.depth_m))
                .collect();
            if series.len() < 4 {
                return Err(Error::Other(format!("{}: fewer than 4 rows", run_dir.join("walls.txt").display())));
            }
            let mut w = CsvSeries::create(&out.join("stress.csv"))?;
            for r in &series {
                w.row(r)?;
            }
            std::fs::write(out.join("shear.json"), serde_json::to_string_pretty(&stress_estimates(&series, None)).expect("serialisable") + "\n")
                .map_err(|e| Error::io(out.display(), e))?;
        }
        Analysis::None => return Err(Error::Other("export.json: analysis none".into())),
    }
    Ok(out)
}

/// Run the impact observer over a series.txt.
pub fn impact_of_series(info: &ExportInfo, path: &Path) -> Result<(ImpactObserver, ImpactSummary), Error> {
    let (header, rows) = read_table(path)?;
    if header != info.columns {
        return Err(Error::Other(format!("{}: columns {:?}, expected {:?}", path.display(), header, info.columns)));
    }
    let two = info.radii_m.len() == 2;
    let j = if two { 1 } else { 0 };
    let state = |r: &[f64]| {
        let g = |k: usize| (Vec2::new(r[1 + 7 * k], r[2 + 7 * k]), Vec2::new(r[3 + 7 * k], r[4 + 7 * k]), r[5 + 7 * k]);
        let (x0, v0, w0) = g(0);
        let (x1, v1, w1) = g(j);
        let m = &info.masses_kg;
        let momentum = if two { m[0] * v0 + m[1] * v1 } else { m[0] * v0 };
        let scale = m[0] * v0.norm() + if two { m[1] * v1.norm() } else { 0.0 };
        ImpactState {
            time: r[0] * info.time_step_s,
            x: [x0, x1],
            v: [v0, v1],
            omega: [w0, w1],
            r: [info.radii_m[0], info.radii_m[j]],
            f0: Vec2::new(r[6], r[7]),
            wall: info.flat_wall.map(|[y, side, vx]| (y, side, Vec2::new(vx, 0.0))),
            boundary: Boundary::open(),
            momentum,
            momentum_scale: scale,
        }
    };
    let mut obs = ImpactObserver::default();
    let mut it = rows.iter();
    let first = it.next().ok_or_else(|| Error::Other(format!("{}: no rows", path.display())))?;
    obs.start_state(&state(first));
    for r in it {
        obs.observe_state(&state(r));
    }
    let s = obs.summary().ok_or_else(|| Error::Other(format!("{}: the grains did not touch and separate", path.display())))?;
    Ok((obs, s))
}

/// One compared quantity.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub case: String,
    pub code: Code,
    pub quantity: String,
    pub engine: f64,
    pub reference: f64,
    /// |engine - reference|.
    pub abs_diff: f64,
    /// |engine - reference| / |reference|.
    pub rel_diff: f64,
    /// The bound it is held to, and whether that is absolute or relative.
    pub tolerance: f64,
    pub relative: bool,
    pub pass: bool,
}

impl Row {
    fn new(case: &str, code: Code, quantity: &str, engine: f64, reference: f64, tolerance: f64, relative: bool) -> Row {
        let abs_diff = (engine - reference).abs();
        let rel_diff = abs_diff / reference.abs();
        let d = if relative { rel_diff } else { abs_diff };
        Row { case: case.into(), code, quantity: quantity.into(), engine, reference, abs_diff, rel_diff, tolerance, relative, pass: d <= tolerance }
    }
}

/// The tolerances, with their reasons (docs/fidelity.md repeats them).
pub mod tolerance {
    /// Realised restitution, absolute: the same model at the same dt reproduces the
    /// reference trajectory to rounding; 1e-5 is the bound.
    pub const RESTITUTION: f64 = 1e-5;
    /// Peak force and largest overlap, relative (issue bound).
    pub const PEAK: f64 = 1e-4;
    /// Rebound spin and tangential velocity, relative (issue bound).
    pub const SPIN: f64 = 1e-3;
}

/// The engine's impact summary for a case's scene.
pub fn engine_impact(scene: &Scene) -> Result<ImpactSummary, Error> {
    run_scene(scene, &RunOptions::default())?.impact.ok_or_else(|| Error::Other(format!("{}: no impact", scene.name)))
}

fn read_csv_row<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, Error> {
    let mut r = ::csv::Reader::from_path(path).map_err(|e| Error::Other(format!("{}: {e}", path.display())))?;
    r.deserialize().next().ok_or_else(|| Error::Other(format!("{}: no row", path.display())))?.map_err(|e| Error::Other(format!("{}: {e}", path.display())))
}

/// The committed reference impact summary of a case.
pub fn expected_impact(case_dir: &Path, code: Code) -> Result<ImpactSummary, Error> {
    read_csv_row(&case_dir.join("expected").join(code.name()).join("impact.csv"))
}

/// The committed reference force-overlap curve of a case.
pub fn expected_curve(case_dir: &Path, code: Code) -> Result<Vec<CurvePoint>, Error> {
    let path = case_dir.join("expected").join(code.name()).join("force_overlap.csv");
    let mut r = ::csv::Reader::from_path(&path).map_err(|e| Error::Other(format!("{}: {e}", path.display())))?;
    r.deserialize().collect::<Result<Vec<CurvePoint>, _>>().map_err(|e| Error::Other(format!("{}: {e}", path.display())))
}

/// The committed reference shear estimates of a case.
pub fn expected_shear(case_dir: &Path, code: Code) -> Result<ShearSummary, Error> {
    let path = case_dir.join("expected").join(code.name()).join("shear.json");
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(path.display(), e))?;
    serde_json::from_str(&text).map_err(|e| Error::Other(format!("{}: {e}", path.display())))
}

/// Compare the engine's impact measurements with a reference's.
pub fn compare_impact(case: &str, code: Code, engine: &ImpactSummary, reference: &ImpactSummary, oblique: bool) -> Vec<Row> {
    let mut rows = vec![
        Row::new(case, code, "restitution_normal", engine.restitution_normal, reference.restitution_normal, tolerance::RESTITUTION, false),
        Row::new(case, code, "max_overlap_m", engine.max_overlap_m, reference.max_overlap_m, tolerance::PEAK, true),
        Row::new(case, code, "peak_force_n", engine.peak_force_n, reference.peak_force_n, tolerance::PEAK, true),
    ];
    if oblique {
        rows.push(Row::new(case, code, "rebound_spin_rad_s", engine.rebound_spin_rad_s, reference.rebound_spin_rad_s, tolerance::SPIN, true));
        rows.push(Row::new(
            case,
            code,
            "rebound_tangential_velocity_m_s",
            engine.rebound_tangential_velocity_m_s,
            reference.rebound_tangential_velocity_m_s,
            tolerance::SPIN,
            true,
        ));
    }
    rows
}

/// Compare shear estimates: the difference of the means must lie inside the combined 95%
/// interval `sqrt(ci_a^2 + ci_b^2)` (a Welch-type bound on two independent estimates).
pub fn compare_shear(case: &str, code: Code, engine: &ShearSummary, reference: &ShearSummary) -> Vec<Row> {
    // tau/sigma is undefined without a normal stress: then it cannot agree.
    let undefined = crate::stats::Estimate { mean: f64::NAN, ci95: f64::NAN, blocks: 0 };
    let (ratio_a, ratio_b) = (engine.stress_ratio.unwrap_or(undefined), reference.stress_ratio.unwrap_or(undefined));
    let pairs = [
        ("shear_stress_pa", engine.shear_stress_pa, reference.shear_stress_pa),
        ("normal_stress_pa", engine.normal_stress_pa, reference.normal_stress_pa),
        ("stress_ratio", ratio_a, ratio_b),
    ];
    let mut rows: Vec<Row> = pairs.iter().map(|(q, a, b)| Row::new(case, code, q, a.mean, b.mean, (a.ci95 * a.ci95 + b.ci95 * b.ci95).sqrt(), false)).collect();
    // Welch's t test on tau/sigma: the two block-average estimates have equal means unless
    // p < 0.05. The row carries p as its "difference" from 1 so that the same pass rule
    // (difference <= bound) reads p >= 0.05.
    let p = welch_p(&ratio_a, &ratio_b);
    let mut r = Row::new(case, code, "stress_ratio_welch_p_value", p, 1.0, 0.95, false);
    r.pass = p >= 0.05;
    rows.push(r);
    rows
}

/// Two-sided p-value of Welch's t test for two block-average estimates (mean, 95% half
/// width, number of blocks), with the Welch-Satterthwaite degrees of freedom (statrs).
pub fn welch_p(a: &crate::stats::Estimate, b: &crate::stats::Estimate) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let se = |e: &crate::stats::Estimate| {
        let t = StudentsT::new(0.0, 1.0, (e.blocks.max(2) - 1) as f64).expect("dof >= 1").inverse_cdf(0.975);
        e.ci95 / t
    };
    let (sa, sb) = (se(a), se(b));
    let (va, vb) = (sa * sa, sb * sb);
    if va + vb == 0.0 {
        return if a.mean == b.mean { 1.0 } else { 0.0 };
    }
    let t = (a.mean - b.mean) / (va + vb).sqrt();
    let (na, nb) = ((a.blocks.max(2) - 1) as f64, (b.blocks.max(2) - 1) as f64);
    let dof = (va + vb).powi(2) / (va * va / na + vb * vb / nb);
    let dist = StudentsT::new(0.0, 1.0, dof).expect("dof > 0");
    2.0 * (1.0 - dist.cdf(t.abs()))
}

/// Run the engine on a committed case and compare it with every code that has data.
pub fn compare_case(case_dir: &Path) -> Result<Vec<Row>, Error> {
    let (case, _) = read_info(case_dir)?;
    let text = std::fs::read_to_string(case_dir.join("scene.json")).map_err(|e| Error::io(case_dir.join("scene.json").display(), e))?;
    let scene = Scene::from_json(&text)?;
    let mut rows = Vec::new();
    let codes: Vec<Code> = case.codes.iter().copied().filter(|c| case_dir.join("expected").join(c.name()).exists()).collect();
    if codes.is_empty() {
        return Ok(rows);
    }
    match scene.analysis {
        Analysis::Impact => {
            // One engine run gives the summary, and the curve when the case keeps one.
            let (e, curve) = if case.curve {
                let (s, c) = engine_impact_curve(&scene)?;
                (s, Some(c))
            } else {
                (engine_impact(&scene)?, None)
            };
            let oblique = case.name.starts_with("oblique");
            for code in codes {
                rows.extend(compare_impact(&case.name, code, &e, &expected_impact(case_dir, code)?, oblique));
                // The force-overlap curve on a common normalised grid (50 overlaps per
                // branch), its largest difference as a fraction of the peak force.
                if let Some(c) = &curve {
                    let d = curve_difference(c, &expected_curve(case_dir, code)?, 50);
                    rows.push(Row::new(&case.name, code, "force_overlap_curve_diff_of_peak", d, 0.0, tolerance::PEAK, false));
                }
            }
        }
        Analysis::Shear => {
            let s = run_scene(&scene, &RunOptions::default())?.shear.ok_or_else(|| Error::Other("no shear summary".into()))?;
            for code in codes {
                rows.extend(compare_shear(&case.name, code, &s, &expected_shear(case_dir, code)?));
            }
        }
        Analysis::None => {}
    }
    Ok(rows)
}

/// Every case folder (holding a case.json) under `root`, sorted.
pub fn case_dirs(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        if d.join("case.json").exists() {
            out.push(d);
            continue;
        }
        if let Ok(rd) = std::fs::read_dir(&d) {
            for e in rd.flatten() {
                if e.path().is_dir() {
                    stack.push(e.path());
                }
            }
        }
    }
    out.sort();
    out
}

/// The engine's impact summary and force-overlap curve for a scene.
pub fn engine_impact_curve(scene: &Scene) -> Result<(ImpactSummary, Vec<CurvePoint>), Error> {
    let mut built = crate::build::build(scene)?;
    let e = built.engine.as_mut();
    let (total, _) = crate::run::schedule(scene.duration, e.dt(), scene.output.samples);
    let mut obs = ImpactObserver::default();
    obs.start(e);
    for _ in 0..total {
        e.step()?;
        obs.observe(e);
        if obs.finished() {
            break;
        }
    }
    let s = obs.summary().ok_or_else(|| Error::Other(format!("{}: no impact", scene.name)))?;
    Ok((s, obs.curve))
}

/// Largest difference of two force-overlap curves on a common normalised grid: overlap
/// over the reference's largest overlap, force over its peak force, compared at `points`
/// overlaps on the loading branch and on the unloading branch (linear interpolation), as
/// a fraction of the peak force.
pub fn curve_difference(engine: &[CurvePoint], reference: &[CurvePoint], points: usize) -> f64 {
    let peak = |c: &[CurvePoint]| c.iter().enumerate().max_by(|a, b| a.1.overlap_m.total_cmp(&b.1.overlap_m)).map(|(k, _)| k).unwrap_or(0);
    let dmax = reference.iter().map(|c| c.overlap_m).fold(0.0, f64::max);
    let fmax = reference.iter().map(|c| c.normal_force_n).fold(0.0, f64::max);
    // Force at overlap `d` on one branch (overlaps monotonic along it).
    let at = |branch: &[CurvePoint], d: f64| -> Option<f64> {
        branch.windows(2).find_map(|w| {
            let (a, b) = (w[0], w[1]);
            let (lo, hi) = (a.overlap_m.min(b.overlap_m), a.overlap_m.max(b.overlap_m));
            (d >= lo && d <= hi && hi > lo).then(|| a.normal_force_n + (b.normal_force_n - a.normal_force_n) * (d - a.overlap_m) / (b.overlap_m - a.overlap_m))
        })
    };
    let (ke, kr) = (peak(engine), peak(reference));
    let mut worst: f64 = 0.0;
    for (be, br) in [(&engine[..=ke], &reference[..=kr]), (&engine[ke..], &reference[kr..])] {
        for k in 1..points {
            let d = dmax * k as f64 / points as f64;
            if let (Some(a), Some(b)) = (at(be, d), at(br, d)) {
                worst = worst.max((a - b).abs() / fmax);
            }
        }
    }
    worst
}
