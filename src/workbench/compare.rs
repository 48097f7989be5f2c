//! The comparison: the engine run on a case, its measurements held to each code's
//! committed numbers with stated tolerances (impacts) or confidence intervals and
//! Welch's test (shear).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::observe::impact::{CurvePoint, ImpactSummary};
use crate::observe::stats::Estimate;
use crate::observe::stress::{ShearSummary, WallRow};
use crate::scene::{Analysis, Scene};
use crate::study::run::{RunOptions, run_scene};
use crate::workbench::cases::read_info;
use crate::workbench::export::{Code, ExportInfo};

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
    /// |engine - reference| / |reference|; undefined (an empty cell) where the reference is
    /// 0 and the difference is not (a curve's difference, compared absolutely).
    pub rel_diff: Option<f64>,
    /// The bound it is held to, and whether that is absolute or relative.
    pub tolerance: f64,
    pub relative: bool,
    pub pass: bool,
}

impl Row {
    fn new(case: &str, code: Code, quantity: &str, engine: f64, reference: f64, tolerance: f64, relative: bool) -> Row {
        let abs_diff = (engine - reference).abs();
        // Equal values differ by nothing, relatively too (both 0: a frictionless pair's spin).
        let rel_diff = if abs_diff == 0.0 { 0.0 } else { abs_diff / reference.abs() };
        let d = if relative { rel_diff } else { abs_diff };
        Row { case: case.into(), code, quantity: quantity.into(), engine, reference, abs_diff, rel_diff: rel_diff.is_finite().then_some(rel_diff), tolerance, relative, pass: d <= tolerance }
    }

    /// The difference the bound applies to: relative (infinite where undefined) or absolute.
    pub fn diff(&self) -> f64 {
        if self.relative { self.rel_diff.unwrap_or(f64::INFINITY) } else { self.abs_diff }
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
    /// A protocol's rows recorded at every step, before chaos: the wall forces as a
    /// fraction of the top wall's load, and the gap, relative. The same model at the same
    /// steps computes the same trajectory up to the order of its sums, which the contacts
    /// amplify: 6e-13 of the load at worst over the workbench protocol's 1381 steps. The
    /// first contact that opens and touches again before a neighbour-list rebuild ends
    /// that (LIGGGHTS keeps its stale tangential history, docs/fidelity.md), with jumps
    /// of 1e-5 to 1e-3 of the load; 1e-9 lies between.
    pub const STEPS: f64 = 1e-9;
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
    // In space, grain 0's velocity out of the impact's plane and its spin about the two
    // other axes, as fractions of the impact speed and of the largest spin component
    // (each of them may be 0 where the other is not: compared absolutely on that scale).
    if let (Some(vb), Some(st), Some(sn)) = (reference.rebound_binormal_velocity_m_s, reference.rebound_spin_tangential_rad_s, reference.rebound_spin_normal_rad_s) {
        let (ev, et, en) = (engine.rebound_binormal_velocity_m_s.unwrap_or(f64::NAN), engine.rebound_spin_tangential_rad_s.unwrap_or(f64::NAN), engine.rebound_spin_normal_rad_s.unwrap_or(f64::NAN));
        let v = reference.impact_speed_m_s.abs().max(f64::MIN_POSITIVE);
        let w = reference.rebound_spin_rad_s.abs().max(st.abs()).max(sn.abs()).max(f64::MIN_POSITIVE);
        rows.push(Row::new(case, code, "rebound_binormal_velocity_over_impact_speed", ev / v, vb / v, tolerance::SPIN, false));
        rows.push(Row::new(case, code, "rebound_spin_tangential_over_largest_spin", et / w, st / w, tolerance::SPIN, false));
        rows.push(Row::new(case, code, "rebound_spin_normal_over_largest_spin", en / w, sn / w, tolerance::SPIN, false));
    }
    rows
}

/// Compare shear estimates: the difference of the means must lie inside the combined 95%
/// interval `sqrt(ci_a^2 + ci_b^2)` (a Welch-type bound on two independent estimates).
pub fn compare_shear(case: &str, code: Code, engine: &ShearSummary, reference: &ShearSummary) -> Vec<Row> {
    // tau/sigma is undefined without a normal stress: then it cannot agree.
    let undefined = Estimate { mean: f64::NAN, ci95: f64::NAN, blocks: 0, autocorrelation_time_s: None };
    let of = |s: &ShearSummary| [s.shear_stress_pa, s.normal_stress_pa, s.stress_ratio.unwrap_or(undefined)];
    compare_stresses(case, code, "", of(engine), of(reference))
}

/// The shear comparison's rows of tau, sigma and tau/sigma (`engine` and `reference` in
/// that order, each quantity named with `suffix`): each mean within the combined 95%
/// interval, and Welch's t test on tau/sigma.
fn compare_stresses(case: &str, code: Code, suffix: &str, engine: [Estimate; 3], reference: [Estimate; 3]) -> Vec<Row> {
    let names = ["shear_stress_pa", "normal_stress_pa", "stress_ratio"];
    let mut rows: Vec<Row> = (0..3)
        .map(|k| {
            let (a, b) = (&engine[k], &reference[k]);
            Row::new(case, code, &format!("{}{suffix}", names[k]), a.mean, b.mean, (a.ci95 * a.ci95 + b.ci95 * b.ci95).sqrt(), false)
        })
        .collect();
    // Welch's t test on tau/sigma: the two estimates have equal means unless p < 0.05. The
    // row carries p as its "difference" from 1 so that the same pass rule (difference <=
    // bound) reads p >= 0.05.
    let p = welch_p(&engine[2], &reference[2]);
    let mut r = Row::new(case, code, &format!("stress_ratio{suffix}_welch_p_value"), p, 1.0, 0.95, false);
    r.pass = p >= 0.05;
    rows.push(r);
    rows
}

/// Two-sided p-value of Welch's t test for two block-average estimates (mean, 95% half
/// width, number of blocks), with the Welch-Satterthwaite degrees of freedom (statrs).
pub fn welch_p(a: &Estimate, b: &Estimate) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let (sa, sb) = (a.standard_error(), b.standard_error());
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
    let (case, info) = read_info(case_dir)?;
    if case.ensemble.is_some() {
        // Compared with its ensemble's other members: compare_ensemble.
        return Ok(Vec::new());
    }
    let scene = read_scene(case_dir)?;
    let mut rows = Vec::new();
    let codes = codes_with_data(&case, case_dir);
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
            // Tangential outcomes too where the impact has a tangential part.
            let oblique = case.name.contains("oblique") || case.name.starts_with("chung-ooi") || case.name.starts_with("rolling/") || case.name.starts_with("space-spin/");
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
            // A protocol that records stages at every step: the engine's rows too, from a
            // run with an output folder (removed after).
            let stepped = info.stages.iter().any(|st| st.sample_every == 1);
            let folder = stepped.then(|| std::env::temp_dir().join(format!("grainlab-compare-{}-{}", std::process::id(), case.name.replace('/', "-"))));
            let run = run_scene(&scene, &RunOptions { out: folder.clone(), overwrite: true, ..RunOptions::default() });
            let engine_rows = folder.as_ref().map(|f| read_wall_rows(&f.join("walls.csv")));
            if let Some(f) = &folder {
                let _ = std::fs::remove_dir_all(f);
            }
            let s = run?.shear.ok_or_else(|| Error::Other("no shear summary".into()))?;
            for code in codes {
                rows.extend(compare_shear(&case.name, code, &s, &expected_shear(case_dir, code)?));
                if let Some(engine_rows) = &engine_rows {
                    let engine_rows = engine_rows.as_ref().map_err(|e| Error::Other(e.to_string()))?;
                    let reference = read_wall_rows(&case_dir.join("expected").join(code.name()).join("stress.csv"))?;
                    rows.extend(compare_steps(&case.name, code, &info, load_of(&scene, &info), engine_rows, &reference)?);
                }
            }
        }
        Analysis::None => {}
    }
    Ok(rows)
}

/// The codes of a case that have committed data (`expected/<code>/`).
fn codes_with_data(case: &crate::workbench::cases::CaseInfo, case_dir: &Path) -> Vec<Code> {
    case.codes.iter().copied().filter(|c| case_dir.join("expected").join(c.name()).exists()).collect()
}

fn read_scene(case_dir: &Path) -> Result<Scene, Error> {
    let text = std::fs::read_to_string(case_dir.join("scene.json")).map_err(|e| Error::io(case_dir.join("scene.json").display(), e))?;
    Scene::from_json(&text)
}

/// Every comparison under `root` (cases whose folder contains `filter`, if given): each
/// case on its own ([`compare_case`]), then each ensemble with all its members
/// ([`compare_ensemble`]).
pub fn compare_all(root: &Path, filter: Option<&str>) -> Result<Vec<Row>, Error> {
    let mut rows = Vec::new();
    let mut ensembles: std::collections::BTreeMap<String, Vec<std::path::PathBuf>> = Default::default();
    for dir in crate::workbench::cases::case_dirs(root) {
        if filter.is_some_and(|f| !dir.to_string_lossy().contains(f)) {
            continue;
        }
        let (case, _) = read_info(&dir)?;
        match case.ensemble {
            Some(group) => ensembles.entry(group).or_default().push(dir),
            None => rows.extend(compare_case(&dir)?),
        }
    }
    for (group, members) in ensembles {
        rows.extend(compare_ensemble(&group, &members)?);
    }
    Ok(rows)
}

/// Compare an ensemble (`members`: case folders that differ by their packing's seed):
/// the engine runs every member's scene, and each side's tau, sigma and tau/sigma are the
/// mean over the members of their time averages, with a 95% interval from the
/// member-to-member spread (Student t, members - 1 degrees of freedom). The means must
/// differ by less than the combined interval sqrt(ci_engine^2 + ci_reference^2), and
/// Welch's test on tau/sigma must not reject equal means at 5%: the comparison of
/// [`compare_shear`] with the run-to-run interval in place of a run's block interval,
/// which understates what another packing gives (docs/statistics.md). Members without
/// the code's data are left out on both sides.
pub fn compare_ensemble(group: &str, members: &[std::path::PathBuf]) -> Result<Vec<Row>, Error> {
    use crate::study::ensemble::ensemble_stat;
    // The members with data, then their engine runs, as many at once as the machine has
    // cores (each run on one thread, so the results do not depend on how many run at once).
    let mut todo = Vec::new();
    for dir in members {
        let (case, _) = read_info(dir)?;
        let codes = codes_with_data(&case, dir);
        if !codes.is_empty() {
            todo.push((dir, case.name, read_scene(dir)?, codes));
        }
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).min(todo.len()).max(1);
    let mut engine: Vec<Option<Result<ShearSummary, Error>>> = (0..todo.len()).map(|_| None).collect();
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some((_, name, scene, _)) = todo.get(k) else { break };
                        let run = run_scene(scene, &RunOptions::default()).and_then(|s| s.shear.ok_or_else(|| Error::Other(format!("{name}: no shear summary"))));
                        done.push((k, run));
                    }
                    done
                })
            })
            .collect();
        for h in handles {
            for (k, run) in h.join().expect("an ensemble member's run panicked") {
                engine[k] = Some(run);
            }
        }
    });
    let mut by_code: std::collections::BTreeMap<Code, (Vec<ShearSummary>, Vec<ShearSummary>)> = Default::default();
    for ((dir, _, _, codes), run) in todo.iter().zip(engine) {
        let run = run.expect("every member ran")?;
        for &code in codes {
            let e = by_code.entry(code).or_default();
            e.0.push(run.clone());
            e.1.push(expected_shear(dir, code)?);
        }
    }
    let mut rows = Vec::new();
    for (code, (engine, reference)) in by_code {
        let n = engine.len();
        // Each quantity's ensemble estimate over the members (all of them must have it).
        let of = |runs: &[ShearSummary]| -> Result<[Estimate; 3], Error> {
            let quantities: [fn(&ShearSummary) -> Option<f64>; 3] = [|s| Some(s.shear_stress_pa.mean), |s| Some(s.normal_stress_pa.mean), |s| s.stress_ratio.map(|r| r.mean)];
            let mut out = Vec::with_capacity(3);
            for q in quantities {
                let values: Vec<f64> = runs.iter().filter_map(q).collect();
                if values.len() != n {
                    return Err(Error::Other(format!("{group}: a member without the quantity (tau/sigma needs a normal stress)")));
                }
                out.push(ensemble_stat(&values).map(|s| s.as_estimate()).ok_or_else(|| Error::Other(format!("{group}: fewer than two members with data")))?);
            }
            Ok(out.try_into().expect("three quantities"))
        };
        rows.extend(compare_stresses(group, code, &format!("_mean_of_{n}"), of(&engine)?, of(&reference)?));
    }
    Ok(rows)
}

/// A wall series (walls.csv, or a digest's stress.csv).
fn read_wall_rows(path: &Path) -> Result<Vec<WallRow>, Error> {
    let mut r = ::csv::Reader::from_path(path).map_err(|e| Error::Other(format!("{}: {e}", path.display())))?;
    r.deserialize().collect::<Result<Vec<WallRow>, _>>().map_err(|e| Error::Other(format!("{}: {e}", path.display())))
}

/// The load on the top wall, N (the scale of the wall forces): its pressure times the
/// walls' area L_x t; without one, the largest force of the rows compared is used instead.
fn load_of(scene: &Scene, info: &ExportInfo) -> Option<f64> {
    match scene.walls.as_ref().map(|w| &w.top.control) {
        Some(crate::scene::ControlSpec::Pressure(p)) => Some(p * info.length_m * info.depth_m),
        _ => None,
    }
}

/// Compare a protocol's rows of the stages recorded at every step, row by row: each wall
/// force's largest difference over them as a fraction of the top wall's load (`load`, N;
/// else of the largest force in those rows), and the gap's, relative
/// ([`tolerance::STEPS`]). Rows are matched by their step; a missing or extra row is an
/// error.
pub fn compare_steps(case: &str, code: Code, info: &ExportInfo, load: Option<f64>, engine: &[WallRow], reference: &[WallRow]) -> Result<Vec<Row>, Error> {
    if engine.len() != reference.len() {
        return Err(Error::Other(format!("{case}: the engine wrote {} rows, {} {}", engine.len(), code.name(), reference.len())));
    }
    let dt = info.time_step_s;
    let in_stepped = |t: f64| info.stages.iter().any(|st| st.sample_every == 1 && st.holds(t, dt));
    let mut pairs = Vec::new();
    for (k, (a, b)) in engine.iter().zip(reference).enumerate() {
        if (a.time_s - b.time_s).abs() > 1e-9 * dt {
            return Err(Error::Other(format!("{case}: row {} is at {} s in the engine, {} s in {}", k + 1, a.time_s, b.time_s, code.name())));
        }
        if in_stepped(b.time_s) {
            pairs.push((a, b));
        }
    }
    if pairs.is_empty() {
        return Ok(Vec::new());
    }
    let forces = |r: &WallRow| [r.bottom_fx_n, r.bottom_fy_n, r.top_fx_n, r.top_fy_n];
    let scale = load.unwrap_or_else(|| pairs.iter().flat_map(|(_, b)| forces(b)).fold(0.0, |m: f64, f| m.max(f.abs())));
    let names = ["bottom_fx_n", "bottom_fy_n", "top_fx_n", "top_fy_n"];
    let mut rows = Vec::new();
    for (j, name) in names.iter().enumerate() {
        // The row where the two differ most, its difference over the scale.
        let (a, b) = pairs.iter().map(|(a, b)| (forces(a)[j], forces(b)[j])).max_by(|x, y| (x.0 - x.1).abs().total_cmp(&(y.0 - y.1).abs())).expect("rows");
        let mut r = Row::new(case, code, &format!("{name}_each_step_of_{}_over_load", pairs.len()), a / scale, b / scale, tolerance::STEPS, false);
        r.rel_diff = None;
        rows.push(r);
    }
    let (a, b) = pairs.iter().map(|(a, b)| (a.gap_m, b.gap_m)).max_by(|x, y| (x.0 - x.1).abs().total_cmp(&(y.0 - y.1).abs())).expect("rows");
    rows.push(Row::new(case, code, &format!("gap_m_each_step_of_{}", pairs.len()), a, b, tolerance::STEPS, true));
    Ok(rows)
}

/// The engine's impact summary and force-overlap curve for a scene.
pub fn engine_impact_curve(scene: &Scene) -> Result<(ImpactSummary, Vec<CurvePoint>), Error> {
    fn stepped<D: crate::observe::impact::Impacts>(mut built: crate::engine::build::Built<D>, scene: &Scene) -> Result<(ImpactSummary, Vec<CurvePoint>), Error> {
        let obs = crate::study::accuracy::step_impact(&mut built, scene)?;
        let s = obs.summary().ok_or_else(|| Error::Other(format!("{}: no impact", scene.name)))?;
        Ok((s, obs.curve))
    }
    match scene.dimension {
        crate::scene::Dimension::Two => stepped(crate::study::build(scene)?, scene),
        crate::scene::Dimension::Three => stepped(crate::study::build_in::<crate::physics::dim::Space>(scene, 1, &crate::scene::limits::Limits::machine())?, scene),
    }
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
