//! Impact measurements: grain 0 against grain 1, or grain 0 against a flat wall.
//!
//! Tangential components are along `t = (n_y, -n_x)`, the normal turned clockwise: +x
//! for a grain above a bottom wall. Watched every step. Contact start and end times are interpolated linearly between
//! steps, and the peaks of overlap and force by a parabola through the three samples
//! around the largest, so that the measurement error is far below one time step.

use serde::Serialize;

use crate::build::Engine;
use crate::dim::{Vec2, cross};

/// One sample of the force-overlap curve.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct CurvePoint {
    pub time_s: f64,
    pub overlap_m: f64,
    pub normal_force_n: f64,
}

/// What one impact did.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct ImpactSummary {
    /// Normal relative speed before contact, m/s (positive).
    pub impact_speed_m_s: f64,
    /// Realised normal restitution, -vn_after / vn_before.
    pub restitution_normal: f64,
    /// Tangential restitution of the contact points, -vt_after / vt_before (NaN if head-on).
    pub restitution_tangential: f64,
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

#[derive(Clone, Copy, Debug, Default)]
struct Contact {
    n: Vec2,
    overlap: f64,
    vn: f64,
    vt: f64,
    force: f64,
}

/// The impact observer.
#[derive(Debug, Default)]
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

impl ImpactObserver {
    fn contact(e: &dyn Engine) -> Contact {
        let p = e.particles();
        let (n, overlap, vrel, spin) = if p.n_free >= 2 {
            let d = e.boundary().image(p.x[0] - p.x[1]);
            let n = d / d.norm();
            (n, p.r[0] + p.r[1] - d.norm(), p.v[0] - p.v[1], p.r[0] * p.omega[0] + p.r[1] * p.omega[1])
        } else {
            let w = e.walls().iter().find(|w| w.is_flat()).expect("an impact scene has two grains or a flat wall");
            let n = Vec2::new(0.0, w.side);
            (n, p.r[0] - w.side * (p.x[0].y - w.y), p.v[0] - w.v, p.r[0] * p.omega[0])
        };
        let vc = vrel + spin * Vec2::new(n.y, -n.x);
        let t = Vec2::new(n.y, -n.x);
        Contact { n, overlap, vn: vrel.dot(&n), vt: vc.dot(&t), force: p.f[0].dot(&n) }
    }

    fn momentum(e: &dyn Engine) -> Vec2 {
        e.particles().momentum()
    }

    /// Call once before the first step.
    pub fn start(&mut self, e: &dyn Engine) {
        self.p0 = Self::momentum(e);
        let p = e.particles();
        self.p_scale = (0..p.n_free).map(|i| p.m[i] * p.v[i].norm()).sum::<f64>().max(f64::MIN_POSITIVE);
        self.prev = Some((e.time(), Self::contact(e)));
    }

    /// Call after every step.
    pub fn observe(&mut self, e: &dyn Engine) {
        let t = e.time();
        let c = Self::contact(e);
        let (tp, cp) = self.prev.expect("start() was called");
        if e.particles().n_free >= 2 {
            self.max_dp = self.max_dp.max((Self::momentum(e) - self.p0).norm() / self.p_scale);
        }
        if c.overlap > 0.0 {
            if self.t_start.is_none() {
                self.before = Some(cp);
                self.t_start = Some(tp + (t - tp) * (-cp.overlap) / (c.overlap - cp.overlap));
            }
            if self.t_end.is_none() {
                self.curve.push(CurvePoint { time_s: t, overlap_m: c.overlap, normal_force_n: c.force });
            }
        } else if cp.overlap > 0.0 && self.t_end.is_none() {
            self.t_end = Some(tp + (t - tp) * cp.overlap / (cp.overlap - c.overlap));
        }
        if self.t_end.is_some() {
            let p = e.particles();
            self.after = Some((c, p.v[0], p.omega[0]));
        }
        let _ = cross;
        self.prev = Some((t, c));
    }

    /// True once the grains have separated after touching.
    pub fn finished(&self) -> bool {
        self.t_end.is_some()
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
            restitution_tangential: if before.vt.abs() > 1e-12 * before.vn.abs() { -after.vt / before.vt } else { f64::NAN },
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
