//! Impact measurements: grain 0 against grain 1, or grain 0 against a flat wall.
//!
//! Tangential components are along `t = (n_y, -n_x)`, the normal turned clockwise: +x
//! for a grain above a bottom wall. Watched every step. Contact start and end times are interpolated linearly between
//! steps, and the peaks of overlap and force by a parabola through the three samples
//! around the largest, so that the measurement error is far below one time step.

use serde::{Deserialize, Serialize};

use crate::engine::world::View;
use crate::physics::dim::Vec2;

/// The most points the force-overlap curve keeps (a cap of the scene's limits, which the
/// build's memory estimate counts too).
pub use crate::scene::limits::MAX_CURVE_POINTS;

/// One sample of the force-overlap curve.
#[derive(Clone, Copy, Debug, Serialize, serde::Deserialize)]
pub struct CurvePoint {
    pub time_s: f64,
    pub overlap_m: f64,
    pub normal_force_n: f64,
}

/// What one impact did.
#[derive(Clone, Copy, Debug, Default, Serialize, serde::Deserialize)]
pub struct ImpactSummary {
    /// Normal relative speed before contact, m/s (positive).
    pub impact_speed_m_s: f64,
    /// Realised normal restitution, -vn_after / vn_before.
    pub restitution_normal: f64,
    /// Tangential restitution of the contact points, -vt_after / vt_before; undefined
    /// (empty, `null`) for a head-on impact.
    pub restitution_tangential: Option<f64>,
    /// Tangential velocity of grain 0's centre after the impact, m/s.
    pub rebound_tangential_velocity_m_s: f64,
    /// Normal velocity of grain 0's centre after the impact, m/s.
    pub rebound_normal_velocity_m_s: f64,
    /// Spin of grain 0 after the impact, rad/s.
    pub rebound_spin_rad_s: f64,
    /// Largest overlap, m.
    pub max_overlap_m: f64,
    /// Largest normal force, N.
    pub peak_force_n: f64,
    /// Contact duration, s.
    pub contact_time_s: f64,
    /// Largest |momentum change| of the two grains over the run relative to the initial momentum scale.
    pub momentum_error_rel: f64,
}

#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct Contact {
    n: Vec2,
    overlap: f64,
    vn: f64,
    vt: f64,
    force: f64,
}

/// The impact observer.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct ImpactObserver {
    before: Option<Contact>,
    prev: Option<(f64, Contact)>,
    t_start: Option<f64>,
    t_end: Option<f64>,
    after: Option<(Contact, Vec2, f64)>,
    pub curve: Vec<CurvePoint>,
    p0: Vec2,
    p_scale: f64,
    max_dp: f64,
}

/// What the impact observer needs of one step: grain 0, and grain 1 or a flat wall.
/// Built from a running engine, or from a reference code's output (`grainlab digest`),
/// so that both are measured by the same code.
#[derive(Clone, Copy, Debug)]
pub struct ImpactState {
    pub time: f64,
    pub x: [Vec2; 2],
    pub v: [Vec2; 2],
    pub omega: [f64; 2],
    pub r: [f64; 2],
    /// Force on grain 0, N.
    pub f0: Vec2,
    /// Grain 0 against a flat wall `(y, side, velocity)` instead of grain 1.
    pub wall: Option<(f64, f64, Vec2)>,
    /// Periodicity, for the pair's separation vector.
    pub boundary: crate::physics::boundary::Boundary,
    /// Total momentum of the free grains, kg m/s (two-grain impacts).
    pub momentum: Vec2,
    /// Sum of m |v| over the free grains, kg m/s.
    pub momentum_scale: f64,
}

impl ImpactState {
    /// The state of a running engine.
    pub fn of(e: &View) -> ImpactState {
        let p = e.particles;
        let two = p.n_free >= 2;
        let j = if two { 1 } else { 0 };
        let wall = (!two).then(|| {
            let w = e.walls.iter().find(|w| w.is_flat()).expect("an impact scene has two grains or a flat wall");
            (w.y, w.side, w.v)
        });
        ImpactState {
            time: e.time,
            x: [p.x[0], p.x[j]],
            v: [p.v[0], p.v[j]],
            omega: [p.omega[0], p.omega[j]],
            r: [p.r[0], p.r[j]],
            f0: p.f[0],
            wall,
            boundary: e.boundary,
            momentum: p.momentum(),
            momentum_scale: (0..p.n_free).map(|i| p.m[i] * p.v[i].norm()).sum::<f64>(),
        }
    }

    fn contact(&self) -> Contact {
        let (n, overlap, vrel, spin) = match self.wall {
            None => {
                let d = self.boundary.image(self.x[0] - self.x[1]);
                let n = d / d.norm();
                (n, self.r[0] + self.r[1] - d.norm(), self.v[0] - self.v[1], self.r[0] * self.omega[0] + self.r[1] * self.omega[1])
            }
            Some((y, side, vw)) => {
                let n = Vec2::new(0.0, side);
                (n, self.r[0] - side * (self.x[0].y - y), self.v[0] - vw, self.r[0] * self.omega[0])
            }
        };
        let t = Vec2::new(n.y, -n.x);
        let vc = vrel + spin * t;
        Contact { n, overlap, vn: vrel.dot(&n), vt: vc.dot(&t), force: self.f0.dot(&n) }
    }
}

impl ImpactObserver {
    /// Call once before the first step.
    pub fn start(&mut self, e: &View) {
        self.start_state(&ImpactState::of(e));
    }

    pub fn start_state(&mut self, s: &ImpactState) {
        self.p0 = s.momentum;
        self.p_scale = s.momentum_scale.max(f64::MIN_POSITIVE);
        self.prev = Some((s.time, s.contact()));
    }

    /// Call after every step.
    pub fn observe(&mut self, e: &View) {
        self.observe_state(&ImpactState::of(e));
    }

    pub fn observe_state(&mut self, s: &ImpactState) {
        let t = s.time;
        let c = s.contact();
        let (tp, cp) = self.prev.expect("start() was called");
        if s.wall.is_none() {
            // hypot: the squares of a heavy pair's momentum overflow (a fuzzed 1e300 kg/m^3
            // grain made norm() infinite), the length itself does not.
            let dp = s.momentum - self.p0;
            self.max_dp = self.max_dp.max(dp.x.hypot(dp.y) / self.p_scale);
        }
        if c.overlap > 0.0 {
            if self.t_start.is_none() {
                self.before = Some(cp);
                self.t_start = Some(tp + (t - tp) * (-cp.overlap) / (c.overlap - cp.overlap));
            }
            if self.t_end.is_none() {
                // At most MAX_CURVE_POINTS: a contact longer than that is a grain at rest
                // on its partner, not an impact, and its first part holds the peaks.
                if self.curve.len() < MAX_CURVE_POINTS {
                    self.curve.push(CurvePoint { time_s: t, overlap_m: c.overlap, normal_force_n: c.force });
                }
            }
        } else if cp.overlap > 0.0 && self.t_end.is_none() {
            self.t_end = Some(tp + (t - tp) * cp.overlap / (cp.overlap - c.overlap));
        }
        if self.t_end.is_some() && self.after.is_none() {
            self.after = Some((c, s.v[0], s.omega[0]));
        }
        self.prev = Some((t, c));
    }

    /// True once the grains have separated after touching.
    pub fn finished(&self) -> bool {
        self.t_end.is_some()
    }

    /// Why there is no rebound to measure, if there is none: the bodies never touched,
    /// or they were still in contact when the run ended.
    pub fn unfinished(&self) -> Option<&'static str> {
        match (self.t_start, self.t_end) {
            (_, Some(_)) => None,
            (None, None) => Some("the bodies never touched within the run: no impact to measure"),
            (Some(_), None) => Some("the bodies were still in contact when the run ended: stuck together (cohesion below its sticking speed) or a run too short for the contact; no rebound to measure"),
        }
    }

    fn peak(&self, f: impl Fn(&CurvePoint) -> f64) -> f64 {
        let v: Vec<f64> = self.curve.iter().map(f).collect();
        let Some((k, &m)) = v.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)) else { return f64::NAN };
        if k == 0 || k + 1 >= v.len() {
            return m;
        }
        // Vertex of the parabola through three equally spaced samples.
        let (a, b, c) = (v[k - 1], v[k], v[k + 1]);
        let den = a - 2.0 * b + c;
        if den >= 0.0 { m } else { b - 0.125 * (c - a) * (c - a) / den }
    }

    pub fn summary(&self) -> Option<ImpactSummary> {
        let (before, (after, v0, w0)) = (self.before?, self.after?);
        let n = after.n;
        let t = Vec2::new(n.y, -n.x);
        Some(ImpactSummary {
            impact_speed_m_s: -before.vn,
            restitution_normal: -after.vn / before.vn,
            restitution_tangential: (before.vt.abs() > 1e-12 * before.vn.abs()).then(|| -after.vt / before.vt),
            rebound_tangential_velocity_m_s: v0.dot(&t),
            rebound_normal_velocity_m_s: v0.dot(&n),
            rebound_spin_rad_s: w0,
            max_overlap_m: self.peak(|c| c.overlap_m),
            peak_force_n: self.peak(|c| c.normal_force_n),
            contact_time_s: self.t_end? - self.t_start?,
            momentum_error_rel: self.max_dp,
        })
    }
}
