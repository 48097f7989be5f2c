//! Tangential contact force: none, LIGGGHTS' total displacement, or YADE's increments.
//!
//! Every formulation gets the relative velocity of the contact points `vt` (tangential
//! part, m/s, of grain i relative to grain j), the tangential stiffness `kt` (N/m), the
//! damping coefficient `gt` (kg/s), the Coulomb cap `mu |Fn|` (N) and the time step, and
//! returns the elastic and the damping part of the tangential force on grain i.

use crate::dim::{Vec2, cross};

/// What a tangential formulation needs of one contact at one step.
#[derive(Clone, Copy, Debug)]
pub struct TangentialInput {
    /// Unit normal, from j to i.
    pub n: Vec2,
    /// Tangential relative velocity of the contact points (i relative to j), m/s.
    pub vt: Vec2,
    /// Tangential stiffness, N/m.
    pub kt: f64,
    /// Tangential damping coefficient, kg/s.
    pub gt: f64,
    /// Coulomb cap mu |Fn|, N.
    pub cap: f64,
    /// Time step, s.
    pub dt: f64,
}

/// The tangential force on grain i, split for the energy balance.
#[derive(Clone, Copy, Debug, Default)]
pub struct TangentialForce {
    /// Elastic (spring) part, N.
    pub elastic: Vec2,
    /// Viscous part, N.
    pub damping: Vec2,
    /// Elastic energy removed from the spring by sliding at this step, J.
    pub slip_energy: f64,
}

/// A tangential formulation.
pub trait Tangential: Copy + Default + Send + Sync + 'static {
    const NAME: &'static str;
    /// False for frictionless contacts: no tangential force, no torque, no spin.
    const FRICTION: bool;
    /// The state a contact carries from step to step.
    type History: Copy + Default + Send + Sync + std::fmt::Debug;
    fn force(h: &mut Self::History, inp: &TangentialInput) -> TangentialForce;
}

/// No tangential force at all.
#[derive(Clone, Copy, Debug, Default)]
pub struct Frictionless;

impl Tangential for Frictionless {
    const NAME: &'static str = "Frictionless";
    const FRICTION: bool = false;
    type History = ();
    #[inline(always)]
    fn force(_: &mut (), _: &TangentialInput) -> TangentialForce {
        TangentialForce::default()
    }
}

/// LIGGGHTS `tangential history`: a total tangential displacement `xi`, advanced by
/// `vt dt` and projected onto the current tangent line each step; `Ft = -kt xi - gt vt`
/// while sticking. When `|kt xi| > mu |Fn|` the contact slides: the force is the
/// elastic force scaled down to the cap, `xi = -Ft/kt`, and there is no damping.
#[derive(Clone, Copy, Debug, Default)]
pub struct TotalDisplacement;

impl Tangential for TotalDisplacement {
    const NAME: &'static str = "TotalDisplacementHistory";
    const FRICTION: bool = true;
    /// The tangential displacement xi, m.
    type History = Vec2;
    #[inline(always)]
    fn force(xi: &mut Vec2, inp: &TangentialInput) -> TangentialForce {
        let n = inp.n;
        *xi += inp.vt * inp.dt;
        let along_n = xi.dot(&n);
        *xi -= along_n * n;
        let elastic = -inp.kt * *xi;
        let f_el = elastic.norm();
        // Branch-free: whether a contact slides is data, not control flow (about as often
        // one way as the other in a sheared packing). cap >= 0, so sliding means f_el > 0.
        let slide = f_el > inp.cap;
        let scale = if slide { inp.cap / f_el } else { 1.0 };
        let scaled = elastic * scale;
        let before = 0.5 * inp.kt * xi.norm_squared();
        let xi_slid = -scaled / inp.kt;
        let after = 0.5 * inp.kt * xi_slid.norm_squared();
        *xi = if slide { xi_slid } else { *xi };
        let damping = -inp.gt * inp.vt;
        TangentialForce { elastic: scaled, damping: if slide { Vec2::zeros() } else { damping }, slip_energy: if slide { before - after } else { 0.0 } }
    }
}

/// State of a YADE-style incremental contact.
#[derive(Clone, Copy, Debug, Default)]
pub struct IncrementalState {
    /// Elastic tangential force on grain i, N.
    pub force: Vec2,
    /// The normal at the previous step (zero before the first step of a contact).
    pub n_prev: Vec2,
}

/// YADE `Law2_ScGeom_MindlinPhys_Mindlin`: the elastic tangential force is rotated with
/// the contact frame (to first order, as YADE's `ScGeom::rotate`) and incremented by
/// `-kt vt dt` with `kt` at the current overlap; Coulomb caps the elastic part; the
/// viscous part `-gt vt` is added on top while sticking.
#[derive(Clone, Copy, Debug, Default)]
pub struct IncrementalForce;

impl Tangential for IncrementalForce {
    const NAME: &'static str = "IncrementalForce";
    const FRICTION: bool = true;
    type History = IncrementalState;
    #[inline(always)]
    fn force(h: &mut IncrementalState, inp: &TangentialInput) -> TangentialForce {
        let n = inp.n;
        // Rotate with the normal: in the plane the axis n_prev x n is along z and the
        // first-order rotation adds (axis x F).
        let s = cross(h.n_prev, n);
        let f = h.force;
        let rotated = f + s * Vec2::new(-f.y, f.x);
        h.n_prev = n;
        let trial = rotated - inp.kt * inp.vt * inp.dt;
        let f_el = trial.norm();
        if f_el > inp.cap {
            let scaled = if f_el > 0.0 { trial * (inp.cap / f_el) } else { Vec2::zeros() };
            let slip_energy = if inp.kt > 0.0 { 0.5 * (trial.norm_squared() - scaled.norm_squared()) / inp.kt } else { 0.0 };
            h.force = scaled;
            TangentialForce { elastic: scaled, damping: Vec2::zeros(), slip_energy }
        } else {
            h.force = trial;
            TangentialForce { elastic: trial, damping: -inp.gt * inp.vt, slip_energy: 0.0 }
        }
    }
}
