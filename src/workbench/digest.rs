//! The digest: a reference code's raw output (`series.txt`, `walls.txt`) measured with
//! the engine's own observers, the same estimators on both sides, into the case's
//! `expected/<code>/`.

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::observe::impact::{CurvePoint, ImpactObserver, ImpactState, ImpactSummary, Impacts};
use crate::observe::stress::{WallAverager, WallRow, stress_estimates};
use crate::output::csv::CsvSeries;
use crate::physics::boundary::Boundary;
use crate::physics::dim::{Plane, Space, Vec2};

type Vec3 = nalgebra::Vector3<f64>;
use crate::scene::Analysis;
use crate::workbench::cases::read_info;
use crate::workbench::export::{Code, ExportInfo};

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

/// Measure a reference code's raw output (in `run_dir`) with the engine's observers and
/// write `expected/<code>/` in `case_dir`.
pub fn digest(case_dir: &Path, code: Code, run_dir: &Path) -> Result<PathBuf, Error> {
    let (case, info) = read_info(case_dir)?;
    let out = case_dir.join("expected").join(code.name());
    std::fs::create_dir_all(&out).map_err(|e| Error::io(out.display(), e))?;
    match info.analysis {
        Analysis::Impact => {
            let (curve, summary) = impact_of_series(&info, &run_dir.join("series.txt"))?;
            CsvSeries::create(&out.join("impact.csv"))?.row(&summary)?;
            if case.curve {
                let mut w = CsvSeries::create(&out.join("force_overlap.csv"))?;
                for p in &curve {
                    w.row(p)?;
                }
            }
        }
        Analysis::Shear => {
            let walls = run_dir.join("walls.txt");
            let (header, rows) = read_table(&walls)?;
            // Each row: the step, the bottom and top walls' forces (x, y and in space z),
            // the gap.
            let d = if info.dimension.is_two() { 2 } else { 3 };
            if header.len() != 2 * d + 2 {
                return Err(Error::Other(format!("{}: {} columns, a {d}D deck writes {}", walls.display(), header.len(), 2 * d + 2)));
            }
            let series = if info.stages.is_empty() {
                rows.iter().map(|r| WallRow::of_forces(r[0] * info.time_step_s, &r[1..=d], &r[1 + d..=2 * d], r[2 * d + 1], info.length_m, info.depth_m)).collect()
            } else {
                protocol_rows(&info, &rows, d).map_err(|e| Error::Other(format!("{}: {e}", walls.display())))?
            };
            if series.len() < 4 {
                return Err(Error::Other(format!("{}: fewer than 4 rows", walls.display())));
            }
            let mut w = CsvSeries::create(&out.join("stress.csv"))?;
            for r in &series {
                w.row(r)?;
            }
            // A protocol's averages are its last averaged stage's, as grainlab's summary.
            let averaged: Vec<WallRow> = match info.stages.iter().rev().find(|st| st.average) {
                Some(st) => series.iter().filter(|r| st.holds(r.time_s, info.time_step_s)).copied().collect(),
                None => series.clone(),
            };
            if averaged.len() < 4 {
                return Err(Error::Other(format!("{}: fewer than 4 rows in the averaged stage", walls.display())));
            }
            std::fs::write(out.join("shear.json"), serde_json::to_string_pretty(&stress_estimates(&averaged, None, &info.statistics)).expect("serialisable") + "\n")
                .map_err(|e| Error::io(out.display(), e))?;
        }
        Analysis::None => return Err(Error::Other("export.json: analysis none".into())),
    }
    Ok(out)
}

/// A protocol's rows as grainlab writes them, from a deck's row of every step (step,
/// the `d` force components on the bottom and top walls, gap): in each stage a row every
/// `sample_every` of its steps and at its last, the forces averaged over the row's steps,
/// the gap at its last: the run loop's [`WallAverager`].
fn protocol_rows(info: &ExportInfo, rows: &[Vec<f64>], d: usize) -> Result<Vec<WallRow>, String> {
    let total: u64 = info.stages.iter().map(|st| st.steps).sum();
    if rows.len() as u64 != total {
        return Err(format!("{} rows, but a protocol's deck records each of its {total} steps", rows.len()));
    }
    let mut out = Vec::new();
    let mut k = 0;
    for st in &info.stages {
        let mut avg = WallAverager::default();
        for j in 1..=st.steps {
            let r = &rows[k];
            k += 1;
            let step = st.first_step + j;
            if r[0] != step as f64 {
                return Err(format!("row {k} is step {}, expected step {step}", r[0]));
            }
            avg.add(&r[1..=d], &r[1 + d..=2 * d]);
            if j % st.sample_every == 0 || j == st.steps {
                out.extend(avg.take(d, step as f64 * info.time_step_s, r[2 * d + 1], info.length_m, info.depth_m));
            }
        }
    }
    Ok(out)
}

/// Run the impact observer over a series.txt: the force-overlap curve and the summary.
pub fn impact_of_series(info: &ExportInfo, path: &Path) -> Result<(Vec<CurvePoint>, ImpactSummary), Error> {
    let (header, rows) = read_table(path)?;
    if header != info.columns {
        return Err(Error::Other(format!("{}: columns {:?}, expected {:?}", path.display(), header, info.columns)));
    }
    if info.dimension.is_two() {
        // Per grain: x, y, vx, vy, the spin about z, fx, fy.
        return observe_series::<Plane>(info, path, &rows, |r, k| {
            let c = &r[1 + 7 * k..];
            (Vec2::new(c[0], c[1]), Vec2::new(c[2], c[3]), c[4], Vec2::new(c[5], c[6]))
        });
    }
    // Per grain: position, velocity, spin, force, three components each.
    observe_series::<Space>(info, path, &rows, |r, k| {
        let at = |q: usize| Vec3::from_column_slice(&r[1 + 12 * k + 3 * q..4 + 12 * k + 3 * q]);
        (at(0), at(1), at(2), at(3))
    })
}

/// The impact observer over the rows of `path`: `grain(row, k)` reads grain k's
/// position, velocity, spin and force from a row.
fn observe_series<D: Impacts>(
    info: &ExportInfo,
    path: &Path,
    rows: &[Vec<f64>],
    grain: impl Fn(&[f64], usize) -> (D::Vector<f64>, D::Vector<f64>, D::Spin<f64>, D::Vector<f64>),
) -> Result<(Vec<CurvePoint>, ImpactSummary), Error> {
    let two = info.radii_m.len() == 2;
    let j = if two { 1 } else { 0 };
    let m = &info.masses_kg;
    let state = |r: &[f64]| {
        let (x0, v0, w0, f0) = grain(r, 0);
        let (x1, v1, w1, _) = grain(r, j);
        ImpactState::<D> {
            time: r[0] * info.time_step_s,
            x: [x0, x1],
            v: [v0, v1],
            omega: [w0, w1],
            r: [info.radii_m[0], info.radii_m[j]],
            f0,
            // A flat wall moves along x only (ExportInfo::flat_wall).
            wall: info.flat_wall.map(|[y, side, vx]| {
                let mut v = D::zero();
                v[0] = vx;
                (y, side, v)
            }),
            boundary: Boundary::open(),
            momentum: if two { v0 * m[0] + v1 * m[1] } else { v0 * m[0] },
            momentum_scale: m[0] * D::norm(v0) + if two { m[1] * D::norm(v1) } else { 0.0 },
        }
    };
    let mut obs = ImpactObserver::<D>::default();
    let mut it = rows.iter();
    let first = it.next().ok_or_else(|| Error::Other(format!("{}: no rows", path.display())))?;
    obs.start_state(&state(first));
    for r in it {
        obs.observe_state(&state(r));
    }
    let s = obs.summary().ok_or_else(|| Error::Other(format!("{}: the grains did not touch and separate", path.display())))?;
    Ok((obs.curve, s))
}
