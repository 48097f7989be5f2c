//! Wall stresses of the shear cell.
//!
//! 2D stress convention: a wall force F (N) on a wall of length L_x becomes a stress
//! F / (L_x t) in Pa, with t the out-of-plane depth of the scene (the disk thickness, or
//! the mean grain diameter for spheres in the plane; `walls.thickness` overrides).
//! Shear stress tau = (F_bottom,x - F_top,x) / (2 L_x t), normal stress
//! sigma = (F_top,y - F_bottom,y) / (2 L_x t), both positive in a sheared, compressed cell.
//! In space t is the cell's length along z, so the stresses are F / (L_x L_z); the rows
//! carry the walls' z forces too (friction across the shear, zero on average in a cell
//! periodic in z), which the plane's rows leave out.
//! Their ratio is undefined (written as an empty cell, `null` in JSON) while sigma is zero,
//! e.g. before any grain touches a wall.

use serde::{Deserialize, Serialize};

use crate::engine::world::View;
use crate::observe::stats::{BLOCK_TAUS, Blocking, Estimate, estimate};
use crate::scene::StatisticsSpec;
use crate::physics::dim::{Dim, Vec2};

/// One row of the wall time series (forces averaged over the sample interval).
/// Serialised by hand (below): a text format (walls.csv) leaves the plane's absent z
/// forces out, a binary one (the checkpoint, which is read by position) keeps every field.
#[derive(Clone, Copy, Debug, Default, serde::Deserialize)]
pub struct WallRow {
    pub time_s: f64,
    pub bottom_fx_n: f64,
    pub bottom_fy_n: f64,
    pub top_fx_n: f64,
    pub top_fy_n: f64,
    /// In space only: the z forces on the bottom and top walls, N (absent in the plane's
    /// rows, so a 2D walls.csv keeps its columns).
    #[serde(default)]
    pub bottom_fz_n: Option<f64>,
    #[serde(default)]
    pub top_fz_n: Option<f64>,
    pub gap_m: f64,
    pub shear_stress_pa: f64,
    pub normal_stress_pa: f64,
    /// tau/sigma; undefined (an empty cell) while the normal stress is zero.
    pub stress_ratio: Option<f64>,
}

impl Serialize for WallRow {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        // In text the plane's rows have no z columns; in binary every field, in order.
        let z = self.bottom_fz_n.is_some() || self.top_fz_n.is_some() || !s.is_human_readable();
        let mut st = s.serialize_struct("WallRow", if z { 11 } else { 9 })?;
        st.serialize_field("time_s", &self.time_s)?;
        st.serialize_field("bottom_fx_n", &self.bottom_fx_n)?;
        st.serialize_field("bottom_fy_n", &self.bottom_fy_n)?;
        st.serialize_field("top_fx_n", &self.top_fx_n)?;
        st.serialize_field("top_fy_n", &self.top_fy_n)?;
        if z {
            st.serialize_field("bottom_fz_n", &self.bottom_fz_n)?;
            st.serialize_field("top_fz_n", &self.top_fz_n)?;
        } else {
            st.skip_field("bottom_fz_n")?;
            st.skip_field("top_fz_n")?;
        }
        st.serialize_field("gap_m", &self.gap_m)?;
        st.serialize_field("shear_stress_pa", &self.shear_stress_pa)?;
        st.serialize_field("normal_stress_pa", &self.normal_stress_pa)?;
        st.serialize_field("stress_ratio", &self.stress_ratio)?;
        st.end()
    }
}

/// Averages the wall forces over every step of a sample interval: the run loop's walls
/// ([`WallAverager::accumulate`], [`WallAverager::row`]) and a reference code's rows of
/// every step (the digest's protocols, [`WallAverager::add`], [`WallAverager::take`]).
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct WallAverager {
    /// The bottom and top walls' force sums, N: x, y and in space z (zero in the plane).
    sum: [[f64; 3]; 2],
    n: u64,
}

impl WallAverager {
    /// Add one step's forces of the grains on the bottom (`b`) and top (`t`) walls, N:
    /// x, y and in space z.
    pub fn add(&mut self, b: &[f64], t: &[f64]) {
        for (sum, f) in self.sum.iter_mut().zip([b, t]) {
            sum.iter_mut().zip(f).for_each(|(s, f)| *s += f);
        }
        self.n += 1;
    }
    /// The row of the steps added since the last row, at `time` (s) with the gap (m), of
    /// `d` force components (2 in the plane, 3 in space); restarts the averages. None if
    /// no step was added.
    pub fn take(&mut self, d: usize, time: f64, gap: f64, length: f64, depth: f64) -> Option<WallRow> {
        if self.n == 0 {
            return None;
        }
        let [b, t] = self.sum.map(|s| s.map(|f| f / self.n as f64));
        *self = WallAverager::default();
        Some(WallRow::of_forces(time, &b[..d], &t[..d], gap, length, depth))
    }
    /// Add the step's forces on the cell's two walls (none without them).
    pub fn accumulate<D: Dim>(&mut self, e: &View<D>) {
        let w = e.walls;
        if w.len() == 2 {
            let f = |k: usize| std::array::from_fn::<f64, 3, _>(|c| if c < D::D { w[k].force[c] } else { 0.0 });
            self.add(&f(0), &f(1));
        }
    }
    /// The row for the interval just finished; restarts the averages.
    pub fn row<D: Dim>(&mut self, e: &View<D>, length: f64, depth: f64) -> Option<WallRow> {
        let w = e.walls;
        if w.len() != 2 {
            return None;
        }
        self.take(D::D, e.time, w[1].y - w[0].y, length, depth)
    }
}

/// tau/sigma where it is defined: sigma non-zero and the quotient finite.
pub fn ratio(tau: f64, sigma: f64) -> Option<f64> {
    let r = tau / sigma;
    (sigma != 0.0 && r.is_finite()).then_some(r)
}

impl WallRow {
    /// A row from the forces of the grains on the bottom (`b`) and top (`t`) walls, N,
    /// the gap, m, the cell length and depth, m.
    pub fn new(time_s: f64, b: Vec2, t: Vec2, gap_m: f64, length: f64, depth: f64) -> WallRow {
        let area = length * depth;
        let tau = (b.x - t.x) / (2.0 * area);
        let sigma = (t.y - b.y) / (2.0 * area);
        WallRow {
            time_s,
            bottom_fx_n: b.x,
            bottom_fy_n: b.y,
            top_fx_n: t.x,
            top_fy_n: t.y,
            bottom_fz_n: None,
            top_fz_n: None,
            gap_m,
            shear_stress_pa: tau,
            normal_stress_pa: sigma,
            stress_ratio: ratio(tau, sigma),
        }
    }
    /// The row in space: the z forces on the bottom and top walls, N.
    pub fn with_z(self, [bottom, top]: [f64; 2]) -> WallRow {
        WallRow { bottom_fz_n: Some(bottom), top_fz_n: Some(top), ..self }
    }
    /// A row from the bottom (`b`) and top (`t`) walls' forces, N: x and y in the plane,
    /// x, y and z in space; the gap, the cell length and depth as [`WallRow::new`].
    pub fn of_forces(time_s: f64, b: &[f64], t: &[f64], gap_m: f64, length: f64, depth: f64) -> WallRow {
        let row = WallRow::new(time_s, Vec2::new(b[0], b[1]), Vec2::new(t[0], t[1]), gap_m, length, depth);
        if b.len() == 3 { row.with_z([b[2], t[2]]) } else { row }
    }
}

/// The time averages of a shear run's wall stresses.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ShearSummary {
    /// Time from which averages are taken (`statistics.average_from` of the stretch), s.
    pub averaged_from_s: f64,
    pub shear_stress_pa: Estimate,
    pub normal_stress_pa: Estimate,
    /// Effective friction tau/sigma (block averages of the ratio series, over the rows
    /// where it is defined); `null` when fewer than two rows have a normal stress.
    pub stress_ratio: Option<Estimate>,
    /// 2D packing fraction at the end (free grains' disk area over the gap area); not
    /// known for a reference code's wall output.
    pub packing_fraction: Option<f64>,
    /// Mean overlap of the touching grain pairs over their mean radius at the end of the
    /// run (`kernels::cells::mean_overlap`), the price of soft grains; absent for an
    /// earlier stage, a reference code's output, or a packing with no contact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_overlap_rel: Option<f64>,
    /// The packing's time averages over the same window (the scene's `output.contacts`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub packing: Option<crate::observe::packing::PackingSummary>,
    /// Why an interval is less than it says: the averaged rows too short for two
    /// automatic blocks of a quantity (its interval then comes from 2 blocks shorter than
    /// 8 autocorrelation times: wide, and still maybe too narrow). None when all hold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
}

/// Time averages of the wall stresses of a stretch of wall rows (a run, or an averaged
/// stage) from `statistics.average_from` of its rows on, each quantity's 95% interval
/// from blocks as `statistics.blocks` says (the same estimator for the engine and for
/// the reference codes' output). The rows must be at least 4.
pub fn stress_estimates(rows: &[WallRow], packing_fraction: Option<f64>, statistics: &StatisticsSpec) -> ShearSummary {
    let from = ((rows.len() as f64 * statistics.average_from) as usize).min(rows.len().saturating_sub(4));
    let kept = &rows[from..];
    let col = |f: fn(&WallRow) -> f64| kept.iter().map(f).collect::<Vec<f64>>();
    // The rows of a stretch are evenly spaced (a stage's rate is its own).
    let interval = if kept.len() >= 2 { (kept[kept.len() - 1].time_s - kept[0].time_s) / (kept.len() - 1) as f64 } else { 0.0 };
    let blocking = Blocking::from(statistics.blocks);
    let shear_stress_pa = estimate(&col(|r| r.shear_stress_pa), blocking, interval);
    let normal_stress_pa = estimate(&col(|r| r.normal_stress_pa), blocking, interval);
    let stress_ratio = {
        let defined: Vec<f64> = kept.iter().filter_map(|r| r.stress_ratio).collect();
        (defined.len() >= 4).then(|| estimate(&defined, blocking, interval))
    };
    // With automatic blocks: a quantity whose rows hold fewer than two blocks of
    // BLOCK_TAUS autocorrelation times (or whose time is not known) is named.
    let span = kept.len() as f64 * interval;
    let short = |e: &Estimate| blocking == Blocking::Auto && e.autocorrelation_time_s.is_none_or(|t| 2.0 * BLOCK_TAUS * t > span);
    let named: Vec<String> = [("shear stress", Some(&shear_stress_pa)), ("normal stress", Some(&normal_stress_pa)), ("tau/sigma", stress_ratio.as_ref())]
        .into_iter()
        .filter_map(|(name, e)| e.filter(|e| short(e)).map(|e| format!("{name} (autocorrelation time {})", e.autocorrelation_time_s.map_or("not measured".into(), |t| format!("{t:.3e} s")))))
        .collect();
    let warning = (!named.is_empty()).then(|| {
        format!(
            "the averaged rows ({span:.3e} s) hold fewer than two blocks of {BLOCK_TAUS} autocorrelation times of {}: their intervals come from 2 shorter blocks, wide and still maybe too narrow; run longer",
            named.join(", ")
        )
    });
    ShearSummary { averaged_from_s: kept[0].time_s, shear_stress_pa, normal_stress_pa, stress_ratio, packing_fraction, mean_overlap_rel: None, packing: None, warning }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plane row and a space row come back from the checkpoint's binary form field for
    /// field (postcard reads by position: a skipped field would shift every later one),
    /// and in CSV the plane's row has no z columns, the space row both.
    #[test]
    fn rows_keep_every_field_in_binary_and_the_plane_s_columns_in_text() {
        let plane = WallRow::new(1e-3, Vec2::new(1.0, -2.0), Vec2::new(-1.5, 2.5), 0.01, 0.04, 1e-3);
        let space = plane.with_z([0.25, -0.125]);
        for row in [plane, space] {
            let back: WallRow = postcard::from_bytes(&postcard::to_stdvec(&(row, 7u8)).unwrap()).map(|(r, k): (WallRow, u8)| {
                assert_eq!(k, 7, "the byte after the row");
                r
            }).unwrap();
            assert_eq!(format!("{back:?}"), format!("{row:?}"));
        }
        let header = |row: WallRow| {
            let mut w = csv::Writer::from_writer(Vec::new());
            w.serialize(row).unwrap();
            String::from_utf8(w.into_inner().unwrap()).unwrap().lines().next().unwrap().to_string()
        };
        assert_eq!(header(plane), "time_s,bottom_fx_n,bottom_fy_n,top_fx_n,top_fy_n,gap_m,shear_stress_pa,normal_stress_pa,stress_ratio");
        assert_eq!(header(space), "time_s,bottom_fx_n,bottom_fy_n,top_fx_n,top_fy_n,bottom_fz_n,top_fz_n,gap_m,shear_stress_pa,normal_stress_pa,stress_ratio");
    }

    /// Rows of a given tau/sigma series (sigma 1e5 Pa, tau = ratio x sigma), 1 ms apart.
    fn rows(ratio: impl Iterator<Item = f64>) -> Vec<WallRow> {
        ratio
            .enumerate()
            .map(|(k, x)| {
                let (tau, sigma) = (x * 1e5, 1e5);
                // Forces of the grains on the walls for these stresses on a 1 m x 1 m wall.
                WallRow::new(k as f64 * 1e-3, Vec2::new(tau, -sigma), Vec2::new(-tau, sigma), 0.01, 1.0, 1.0)
            })
            .collect()
    }

    /// Rows that alternate about their mean decorrelate at once: automatic blocks, no
    /// warning. A slow drift (a ramp over the whole run, autocorrelated across it) leaves
    /// fewer than two blocks of 8 autocorrelation times: the summary says so, naming the
    /// quantities.
    #[test]
    fn a_run_too_short_for_its_autocorrelation_is_named() {
        let spec = StatisticsSpec::default();
        let quick = stress_estimates(&rows((0..400).map(|k| 0.3 + if k % 2 == 0 { 0.01 } else { -0.01 })), None, &spec);
        assert!(quick.warning.is_none(), "{:?}", quick.warning);
        assert!(quick.stress_ratio.unwrap().blocks > 2);
        let drift = stress_estimates(&rows((0..400).map(|k| 0.2 + 1e-3 * k as f64)), None, &spec);
        let w = drift.warning.expect("a drift over the whole run");
        assert!(w.contains("tau/sigma") && w.contains("shear stress") && w.contains("run longer"), "{w}");
        assert_eq!(drift.stress_ratio.unwrap().blocks, 2);
        // Fixed blocks: the scene asked for them, no warning.
        let fixed = StatisticsSpec { blocks: crate::scene::BlocksSpec::Count(10), ..spec };
        assert!(stress_estimates(&rows((0..400).map(|k| 0.2 + 1e-3 * k as f64)), None, &fixed).warning.is_none());
    }
}
