//! Impact measurements: grain 0 against grain 1, or grain 0 against a flat wall.
//!
//! Tangential components are along `t = (n_y, -n_x)`, the normal turned clockwise: +x
//! for a grain above a bottom wall; spins are about z. In space the tangent is the
//! direction of the contact points' tangential velocity before contact and spins are
//! about `t x n` ([`Impacts`]): the same numbers for an impact in the x-y plane, and an
//! impact in any other plane measured in its own. Watched every step. Contact start and end times are interpolated linearly between
//! steps, and the peaks of overlap and force by a parabola through the three samples
//! around the largest, so that the measurement error is far below one time step.

use std::fmt::Debug;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::engine::world::View;
use crate::physics::dim::{Dim, Plane, Space, Vec2};

type Vec3 = nalgebra::Vector3<f64>;

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
    /// In space, grain 0's velocity after the impact out of the impact's plane (along
    /// `b = t x n`), m/s; absent in the plane.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rebound_binormal_velocity_m_s: Option<f64>,
    /// In space, grain 0's spin after the impact about its tangent `t`, rad/s (a spin
    /// about a second axis); absent in the plane.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rebound_spin_tangential_rad_s: Option<f64>,
    /// In space, grain 0's spin after the impact about the normal `n` (twist), rad/s;
    /// absent in the plane.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rebound_spin_normal_rad_s: Option<f64>,
}

/// A contact as the observer keeps it from one step to the next: its normal (grain 1 to
/// grain 0, or out of the wall), overlap, m, normal and tangential velocities of the
/// contact points, m/s, and the normal force on grain 0, N.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Contact<D: Impacts = Plane> {
    n: D::Stored,
    overlap: f64,
    vn: f64,
    vt: D::Tangential,
    force: f64,
}

/// What the impact observer does differently in the plane and in space: the contact's
/// geometry, and the impact's tangent direction.
///
/// The plane measures along `t = (n_y, -n_x)` at every normal, spins about z. In space
/// the impact's plane is the one its normal and the contact points' tangential velocity
/// span before contact: `t` is that velocity's direction (the plane's `n x z` when that
/// lies along it, either sign, so that a plane impact lifted into space is measured as in
/// the plane; `n x z`, or `n x x` for a normal along z, when the impact is head-on), spins
/// are measured about `b = t x n` (z in the plane) and after contact `t = n x b`.
pub trait Impacts: Dim {
    /// A vector kept between steps (normal, velocity, momentum).
    type Stored: Copy + Debug + Default + Serialize + DeserializeOwned;
    /// A contact's tangential velocity as kept: the plane's component along its `t`, m/s;
    /// space's vector, m/s.
    type Tangential: Copy + Debug + Default + Serialize + DeserializeOwned;
    /// A spin as kept, rad/s.
    type StoredSpin: Copy + Debug + Default + Serialize + DeserializeOwned;
    /// The contact between grain 0 and its partner in `s`.
    fn contact(s: &ImpactState<Self>) -> Contact<Self>;
    fn stored(v: Self::Vector<f64>) -> Self::Stored;
    fn stored_spin(w: Self::Spin<f64>) -> Self::StoredSpin;
    /// |p - p0|, kg m/s, without overflowing its squares.
    fn momentum_change(p: Self::Vector<f64>, p0: Self::Stored) -> f64;
    /// The impact measured along its tangent: the contact points' tangential velocity
    /// before and after, grain 0's tangential and normal velocity and spin after.
    fn rebound(before: &Contact<Self>, after: &Contact<Self>, v0: Self::Stored, w0: Self::StoredSpin) -> Rebound;
}

/// An impact's velocities along its tangent ([`Impacts::rebound`]).
pub struct Rebound {
    pub vt_before: f64,
    pub vt_after: f64,
    pub tangential: f64,
    pub normal: f64,
    pub spin: f64,
    /// In space: grain 0's velocity along `b`, its spin about `t` and about `n` after.
    pub out_of_plane: Option<[f64; 3]>,
}

impl Impacts for Plane {
    type Stored = Vec2;
    type Tangential = f64;
    type StoredSpin = f64;
    fn contact(s: &ImpactState) -> Contact {
        let (n, overlap, vrel, spin) = match s.wall {
            None => {
                let d = s.boundary.image(s.x[0] - s.x[1]);
                let n = d / d.norm();
                (n, s.r[0] + s.r[1] - d.norm(), s.v[0] - s.v[1], s.r[0] * s.omega[0] + s.r[1] * s.omega[1])
            }
            Some((y, side, vw)) => {
                let n = Vec2::new(0.0, side);
                (n, s.r[0] - side * (s.x[0].y - y), s.v[0] - vw, s.r[0] * s.omega[0])
            }
        };
        let t = Vec2::new(n.y, -n.x);
        let vc = vrel + spin * t;
        Contact { n, overlap, vn: vrel.dot(&n), vt: vc.dot(&t), force: s.f0.dot(&n) }
    }
    fn stored(v: Vec2) -> Vec2 {
        v
    }
    fn stored_spin(w: f64) -> f64 {
        w
    }
    fn momentum_change(p: Vec2, p0: Vec2) -> f64 {
        // hypot: the squares of a heavy pair's momentum overflow (a fuzzed 1e300 kg/m^3
        // grain made norm() infinite), the length itself does not.
        let dp = p - p0;
        dp.x.hypot(dp.y)
    }
    fn rebound(before: &Contact, after: &Contact, v0: Vec2, w0: f64) -> Rebound {
        let n = after.n;
        let t = Vec2::new(n.y, -n.x);
        Rebound { vt_before: before.vt, vt_after: after.vt, tangential: v0.dot(&t), normal: v0.dot(&n), spin: w0, out_of_plane: None }
    }
}

impl Impacts for Space {
    type Stored = Vec3;
    type Tangential = Vec3;
    type StoredSpin = Vec3;
    fn contact(s: &ImpactState<Space>) -> Contact<Space> {
        let (n, overlap, vrel, spin) = match s.wall {
            None => {
                let d = s.boundary.image(s.x[0] - s.x[1]);
                let n = d / d.norm();
                (n, s.r[0] + s.r[1] - d.norm(), s.v[0] - s.v[1], s.omega[0] * s.r[0] + s.omega[1] * s.r[1])
            }
            Some((y, side, vw)) => (Vec3::new(0.0, side, 0.0), s.r[0] - side * (s.x[0].y - y), s.v[0] - vw, s.omega[0] * s.r[0]),
        };
        // Grain 0's contact point is at -r0 n from its centre, the partner's at +r1 n.
        let vc = vrel - spin.cross(&n);
        let vn = vrel.dot(&n);
        Contact { n, overlap, vn, vt: vc - n * vc.dot(&n), force: s.f0.dot(&n) }
    }
    fn stored(v: Vec3) -> Vec3 {
        v
    }
    fn stored_spin(w: Vec3) -> Vec3 {
        w
    }
    fn momentum_change(p: Vec3, p0: Vec3) -> f64 {
        let dp = p - p0;
        dp.x.hypot(dp.y).hypot(dp.z)
    }
    fn rebound(before: &Contact<Space>, after: &Contact<Space>, v0: Vec3, w0: Vec3) -> Rebound {
        let nb = before.n;
        let plane_t = nb.cross(&Vec3::z());
        let t = if before.vt.norm() > 1e-12 * before.vn.abs() {
            let t = before.vt.normalize();
            if t.dot(&plane_t) < 0.0 { -t } else { t }
        } else if plane_t.norm() > 0.5 {
            plane_t.normalize()
        } else {
            nb.cross(&Vec3::x()).normalize()
        };
        let b = t.cross(&nb);
        let ta = after.n.cross(&b);
        Rebound {
            vt_before: before.vt.dot(&t),
            vt_after: after.vt.dot(&ta),
            tangential: v0.dot(&ta),
            normal: v0.dot(&after.n),
            spin: w0.dot(&b),
            out_of_plane: Some([v0.dot(&b), w0.dot(&ta), w0.dot(&after.n)]),
        }
    }
}

/// The impact observer.
#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct ImpactObserver<D: Impacts = Plane> {
    before: Option<Contact<D>>,
    prev: Option<(f64, Contact<D>)>,
    t_start: Option<f64>,
    t_end: Option<f64>,
    after: Option<(Contact<D>, D::Stored, D::StoredSpin)>,
    pub curve: Vec<CurvePoint>,
    p0: D::Stored,
    p_scale: f64,
    max_dp: f64,
}

/// What the impact observer needs of one step: grain 0, and grain 1 or a flat wall.
/// Built from a running engine, or from a reference code's output (`grainlab digest`),
/// so that both are measured by the same code.
#[derive(Clone, Copy, Debug)]
pub struct ImpactState<D: Dim = Plane> {
    pub time: f64,
    pub x: [D::Vector<f64>; 2],
    pub v: [D::Vector<f64>; 2],
    pub omega: [D::Spin<f64>; 2],
    pub r: [f64; 2],
    /// Force on grain 0, N.
    pub f0: D::Vector<f64>,
    /// Grain 0 against a flat wall `(y, side, velocity)` instead of grain 1.
    pub wall: Option<(f64, f64, D::Vector<f64>)>,
    /// Periodicity, for the pair's separation vector.
    pub boundary: crate::physics::boundary::Boundary<D>,
    /// Total momentum of the free grains, kg m/s (two-grain impacts).
    pub momentum: D::Vector<f64>,
    /// Sum of m |v| over the free grains, kg m/s.
    pub momentum_scale: f64,
}

impl<D: Impacts> ImpactState<D> {
    /// The state of a running engine.
    pub fn of(e: &View<D>) -> ImpactState<D> {
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
            momentum_scale: (0..p.n_free).map(|i| p.m[i] * D::norm(p.v[i])).sum::<f64>(),
        }
    }
}

impl<D: Impacts> ImpactObserver<D> {
    /// Call once before the first step.
    pub fn start(&mut self, e: &View<D>) {
        self.start_state(&ImpactState::of(e));
    }

    pub fn start_state(&mut self, s: &ImpactState<D>) {
        self.p0 = D::stored(s.momentum);
        self.p_scale = s.momentum_scale.max(f64::MIN_POSITIVE);
        self.prev = Some((s.time, D::contact(s)));
    }

    /// Call after every step.
    pub fn observe(&mut self, e: &View<D>) {
        self.observe_state(&ImpactState::of(e));
    }

    pub fn observe_state(&mut self, s: &ImpactState<D>) {
        let t = s.time;
        let c = D::contact(s);
        let (tp, cp) = self.prev.expect("start() was called");
        if s.wall.is_none() {
            self.max_dp = self.max_dp.max(D::momentum_change(s.momentum, self.p0) / self.p_scale);
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
            self.after = Some((c, D::stored(s.v[0]), D::stored_spin(s.omega[0])));
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
        let r = D::rebound(&before, &after, v0, w0);
        Some(ImpactSummary {
            impact_speed_m_s: -before.vn,
            restitution_normal: -after.vn / before.vn,
            restitution_tangential: (r.vt_before.abs() > 1e-12 * before.vn.abs()).then(|| -r.vt_after / r.vt_before),
            rebound_tangential_velocity_m_s: r.tangential,
            rebound_normal_velocity_m_s: r.normal,
            rebound_spin_rad_s: r.spin,
            max_overlap_m: self.peak(|c| c.overlap_m),
            peak_force_n: self.peak(|c| c.normal_force_n),
            contact_time_s: self.t_end? - self.t_start?,
            momentum_error_rel: self.max_dp,
            rebound_binormal_velocity_m_s: r.out_of_plane.map(|o| o[0]),
            rebound_spin_tangential_rad_s: r.out_of_plane.map(|o| o[1]),
            rebound_spin_normal_rad_s: r.out_of_plane.map(|o| o[2]),
        })
    }
}
