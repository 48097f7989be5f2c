//! A contact model: a normal law (Hertz or the linear spring), a damping form, a
//! tangential formulation, a cohesion model and a rolling resistance, composed at
//! compile time. Each named combination is one monomorphized kernel.

use std::marker::PhantomData;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};


use super::cohesion::{Cohesion, Dmt, NoCohesion};
use super::rolling::{Cdt, Epsd2, InLanes, NoRolling, Rolling, RollingEnergy, RollingInput, Sds};
use super::damping::{Damping, LinearRestitution, TsujiFit, Undamped, Viscoelastic};
use super::normal::{Hertz, Hooke, Normal};
use super::tangential::{Frictionless, IncrementalForce, Tangential, TangentialForce, TangentialInput, TotalDisplacement, TotalForceCap, TotalForceCapSpringKept, MicroSlip};
use crate::physics::dim::{Dim, Plane};
use crate::physics::energy::{EnergyLedger, EnergySums};
use crate::physics::lanes::{Real, k, pick};
use crate::physics::material::PairMaterial;

/// Which distance from the grain centre the tangential force acts at (torque lever arm,
/// and the same arm in the contact-point velocity so that work and torque agree).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case")]
pub enum LeverArm {
    /// The grain radius a_i = r_i (the seed).
    #[default]
    Radius,
    /// r_i - dn/2 (LIGGGHTS 3.8).
    RadiusMinusHalfOverlap,
    /// YADE 2023's `ScGeom` kinematics with its granular-ratcheting correction: the
    /// tangential contact velocity uses the full radii for the spins and scales the
    /// translational part by `(r_i + r_j) / (r_i + r_j - dn)` (pairs); the torque arm is
    /// r - dn/2 for pairs and r - dn for flat walls (YADE applies a wall force at the
    /// centre projected onto the wall). Not energy-consistent by design: the work of the
    /// tangential force and its torque differ by O(dn/r).
    Yade,
    /// The distance from the centre to the contact point, in the contact velocity and the
    /// torque: r - dn/2 for pairs (the middle of the overlap) and r - dn on a flat wall
    /// (the centre projected onto the wall): YADE 2023's `Law2_ScGeom_ViscElPhys_Basic`,
    /// the linear spring's law there (no ratcheting correction).
    ContactPoint,
    /// LAMMPS 20220106's `pair granular` and `fix wall/gran granular`: the radius r in the
    /// contact velocity (pairs and walls), r - dn/2 in a pair's torque, r in a wall's.
    /// Not energy-consistent between grains: the work of the tangential force and of its
    /// torques differ by O(dn/r).
    Lammps,
}

impl LeverArm {
    /// The arm of the spin in the contact-point velocity, m.
    #[inline(always)]
    pub fn arm<R: Real>(self, r: R, dn: R) -> R {
        match self {
            LeverArm::Radius | LeverArm::Yade | LeverArm::Lammps => r,
            LeverArm::RadiusMinusHalfOverlap | LeverArm::ContactPoint => r - k::<R>(0.5) * dn,
        }
    }
    /// The arm of the spin in the contact-point velocity of a grain on a flat wall, m.
    #[inline(always)]
    pub fn wall_arm(self, r: f64, dn: f64) -> f64 {
        match self {
            LeverArm::ContactPoint => r - dn,
            _ => self.arm(r, dn),
        }
    }
    /// The torque arm of a grain-grain contact, m.
    #[inline(always)]
    pub fn torque_arm<R: Real>(self, r: R, dn: R) -> R {
        match self {
            LeverArm::Radius => r,
            LeverArm::RadiusMinusHalfOverlap | LeverArm::Yade | LeverArm::ContactPoint | LeverArm::Lammps => r - k::<R>(0.5) * dn,
        }
    }
    /// The torque arm of a grain on a flat wall, m.
    #[inline(always)]
    pub fn wall_torque_arm(self, r: f64, dn: f64) -> f64 {
        match self {
            LeverArm::Yade | LeverArm::ContactPoint => r - dn,
            LeverArm::Lammps => r,
            _ => self.torque_arm(r, dn),
        }
    }
    /// The factor on a grain's spin that the rolling laws see on a flat wall, for grain
    /// radius `r` (m) at overlap `dn` (m): grainlab's own (`Radius`) 1, as for a pair;
    /// LIGGGHTS 3.8 `(r - dn/2)/(r - dn)` (the contact radius over the distance to the
    /// wall: its `wr` of a wall contact, which EPSD2 integrates).
    #[inline(always)]
    pub fn wall_rolling(self, r: f64, dn: f64) -> f64 {
        match self {
            LeverArm::RadiusMinusHalfOverlap => (r - 0.5 * dn) / (r - dn),
            _ => 1.0,
        }
    }
    /// Factor on the translational part of the tangential velocity of a pair.
    #[inline(always)]
    pub fn translation_scale<R: Real>(self, radsum: R, dn: R) -> R {
        match self {
            LeverArm::Yade => radsum / (radsum - dn),
            _ => R::one(),
        }
    }
}

/// Runtime switches of a contact model that cost one predictable branch at most.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelOptions {
    /// Clamp Fn >= 0 (LIGGGHTS `limitForce on`; YADE always). Default off.
    pub limit_force: bool,
    pub lever_arm: LeverArm,
}

/// What the kernel needs of one touching pair (or grain and wall) at one step; with
/// `R = Lanes`, of four pairs; in the plane (the default) or in space.
#[derive(Clone, Copy, Debug)]
pub struct ContactInput<R: Real = f64, D: Dim = Plane> {
    /// Unit normal from j to i (from the wall into grain i).
    pub n: D::Vector<R>,
    /// Overlap dn > 0, m.
    pub dn: R,
    /// Reduced radius R*, m.
    pub r_star: R,
    /// Square root of the reduced mass m*, kg^1/2.
    pub sqrt_m_star: R,
    /// v_i - v_j at the centres, m/s.
    pub v_rel: D::Vector<R>,
    /// a_i w_i + a_j w_j (arms in m, spins in rad/s): the spins' part of the contact-point
    /// velocity is `n x` it, m/s.
    pub spin: D::Spin<R>,
    /// Time step, s.
    pub dt: R,
    /// Factor on the translational part of the tangential velocity (1, except for YADE's
    /// ratcheting correction, [`LeverArm::translation_scale`]).
    pub tangential_scale: R,
    /// Relative spin w_i - w_j, rad/s (0 unless a rolling resistance reads it).
    pub roll: D::Spin<R>,
    /// The rolling laws' factor on `roll` (1, except on LIGGGHTS' flat walls:
    /// [`LeverArm::wall_rolling`]).
    pub roll_scale: R,
    /// What turns the contact about its normal for YADE's increments: `w_i + w_j` in
    /// space (rad/s), `()` in the plane ([`crate::physics::dim::Dim::turn`]).
    pub twist: D::Twist<R>,
}

impl<R: Real, D: Dim> ContactInput<R, D> {
    /// Relative velocity of the contact points, i relative to j.
    #[inline(always)]
    pub fn contact_velocity(&self) -> D::Vector<R> {
        self.v_rel + D::cross_spin(self.n, self.spin)
    }
}

/// Everything one step of a touching contact computes: the force, and what the energy
/// accounting reads.
#[derive(Clone, Copy, Debug, Default)]
pub struct ContactState<R: Real = f64, D: Dim = Plane> {
    /// Total force on i, N.
    pub force: D::Vector<R>,
    /// Tangential force on i, elastic and viscous parts.
    pub tangential: TangentialForce<R, D>,
    /// Normal force along n (after the clamp, if any), N.
    pub normal: R,
    /// Elastic part of the normal force, kn dn, N.
    pub elastic_normal: R,
    /// Normal and tangential stiffness, N/m.
    pub kn: R,
    pub kt: R,
    /// Relative velocity of the contact points, m/s.
    pub vc: D::Vector<R>,
    /// Rolling torque on i (j gets the opposite), N m; 0 without rolling resistance.
    pub rolling: D::Spin<R>,
    /// The relative spin it acted against, w_i - w_j, rad/s (for the energy ledger).
    pub roll: D::Spin<R>,
}

/// The force of one contact on grain i (grain j gets the opposite).
#[derive(Clone, Copy, Debug, Default)]
pub struct ContactForce<D: Dim = Plane> {
    /// Total force on i, N.
    pub force: D::Vector<f64>,
    /// Tangential part of it, N (for the torques -a n x Ft).
    pub tangential: D::Vector<f64>,
    /// Normal force Fn along n (after the clamp, if any), N.
    pub normal: f64,
    /// Normal stiffness kn, N/m (for diagnostics).
    pub kn: f64,
    /// Rolling torque on i, N m (0 without rolling resistance).
    pub rolling: D::Spin<f64>,
}

/// What a contact remembers from step to step. Whether it is touching is kept beside
/// it, densely ([`crate::kernels::pairs::PairList::active`], `World::wall_active`): the sweep
/// that looks for contacts ending reads that flag for every listed pair. (The pair list
/// keeps the two parts in separate arrays, and the energy part only with the energy
/// ledger on: the force kernel reads and writes the tangential state alone.)
#[derive(Clone, Copy, Debug, Default)]
pub struct ContactHistory<H, X = (), D: Dim = Plane> {
    /// The contact law's state ([`Held`]: the tangential formulation's and the rolling
    /// resistance's).
    pub state: H,
    /// What the energy accounting carries over.
    pub energy: EnergyMemory<f64, X, D>,
}

/// What a contact's energy accounting carries from one step to the next: the previous
/// values of the terms it integrates by the trapezoid rule, and the contact's sums of
/// the ledger's terms since they were last taken ([`crate::physics::energy`]); `X` the
/// rolling torque's part ([`RollingEnergy`]: `()`, no room, without rolling resistance).
/// (`R = Lanes`: of four contacts; `D`: in the plane, the default, or in space.)
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
#[serde(bound(serialize = "R: Serialize, X: Serialize, D::Vector<R>: Serialize", deserialize = "R: Deserialize<'de>, X: Deserialize<'de>, D::Vector<R>: Deserialize<'de>"))]
pub struct EnergyMemory<R: Real = f64, X = (), D: Dim = Plane> {
    /// Previous normal damping force (for the trapezoidal energy integrals), N.
    pub fd_prev: R,
    /// Previous elastic tangential force, N.
    pub fte_prev: D::Vector<R>,
    /// Previous tangential damping force, N.
    pub ftd_prev: D::Vector<R>,
    /// The ledger's terms this contact added since they were last taken, J.
    pub sums: EnergySums<R>,
    /// The rolling torque's previous value and work.
    pub rolling: X,
}

impl<X: Copy + RollingEnergy<f64, D::Spin<f64>>, D: Dim> EnergyMemory<f64, X, D> {
    /// The memory of a contact that goes on after its sums were taken: its previous
    /// values, sums 0 (the rolling work included).
    pub fn restarted(&self) -> Self {
        let mut rolling = self.rolling;
        rolling.take();
        EnergyMemory { fd_prev: self.fd_prev, fte_prev: self.fte_prev, ftd_prev: self.ftd_prev, sums: EnergySums::default(), rolling }
    }
}

/// A contact's energy memory in lanes under a rolling law `Rr` in dimension `D`.
pub type MemoryLanes<Rr, D> = EnergyMemory<crate::physics::lanes::Lanes, <<Rr as Rolling<D>>::Energy as InLanes>::Lanes, D>;

impl<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim> ContactModel<N, Dm, T, C, Rr, D> {
    /// Four contacts' energy memories in lanes; with `friction` false only what a
    /// frictionless contact uses (the normal damping's previous force and sum), the rest 0.
    #[inline(always)]
    pub fn gather_energy(h: [&EnergyMemory<f64, Rr::Energy, D>; crate::physics::lanes::LANES], friction: bool) -> MemoryLanes<Rr, D> {
        use crate::physics::lanes::{Lanes, gather};
        use simba::simd::SimdValue;
        let rolling = InLanes::gather(h.map(|x| &x.rolling));
        if !friction {
            let z = Lanes::splat(0.0);
            let sums = EnergySums { normal_damping: gather(|l| h[l].sums.normal_damping), tangential_damping: z, friction: z, tangential_model: z };
            return EnergyMemory { fd_prev: gather(|l| h[l].fd_prev), fte_prev: D::zero(), ftd_prev: D::zero(), sums, rolling };
        }
        EnergyMemory {
            fd_prev: gather(|l| h[l].fd_prev),
            fte_prev: D::gather(|l| h[l].fte_prev),
            ftd_prev: D::gather(|l| h[l].ftd_prev),
            sums: EnergySums {
                normal_damping: gather(|l| h[l].sums.normal_damping),
                tangential_damping: gather(|l| h[l].sums.tangential_damping),
                friction: gather(|l| h[l].sums.friction),
                tangential_model: gather(|l| h[l].sums.tangential_model),
            },
            rolling,
        }
    }
    /// Write lane `l` of the memories `e` to `m` (with `friction` false, only what a
    /// frictionless contact uses).
    #[inline(always)]
    pub fn store_energy_lane(e: &MemoryLanes<Rr, D>, l: usize, m: &mut EnergyMemory<f64, Rr::Energy, D>, friction: bool) {
        use simba::simd::SimdValue;
        if friction {
            *m = Self::energy_lane(e, l);
        } else {
            m.fd_prev = e.fd_prev.extract(l);
            m.sums.normal_damping = e.sums.normal_damping.extract(l);
            m.rolling = InLanes::lane(&e.rolling, l);
        }
    }
    /// The memory in lane `l`.
    #[inline(always)]
    pub fn energy_lane(e: &MemoryLanes<Rr, D>, l: usize) -> EnergyMemory<f64, Rr::Energy, D> {
        use simba::simd::SimdValue;
        let s = &e.sums;
        EnergyMemory {
            fd_prev: e.fd_prev.extract(l),
            fte_prev: D::lane(&e.fte_prev, l),
            ftd_prev: D::lane(&e.ftd_prev, l),
            sums: EnergySums { normal_damping: s.normal_damping.extract(l), tangential_damping: s.tangential_damping.extract(l), friction: s.friction.extract(l), tangential_model: s.tangential_model.extract(l) },
            rolling: InLanes::lane(&e.rolling, l),
        }
    }
}

/// A contact's energy memory under law `L`.
pub type Memory<L> = EnergyMemory<f64, <<L as ContactLaw>::Roll as Rolling<<L as ContactLaw>::D>>::Energy, <L as ContactLaw>::D>;

/// A contact's state of law `L` as a checkpoint stores it.
pub type Saved<L> = (<<L as ContactLaw>::Tang as Tangential<<L as ContactLaw>::D>>::Saved, <<L as ContactLaw>::Roll as Rolling<<L as ContactLaw>::D>>::Saved);

/// A contact law: the trait the stages are generic over. Its dimension `D` is the
/// world's: a law of the plane runs in a world of the plane, one of space in space.
pub trait ContactLaw: Copy + Send + Sync + 'static {
    type D: Dim;
    type Damp: Damping;
    type Tang: Tangential<Self::D>;
    type Coh: Cohesion;
    type Roll: Rolling<Self::D>;
    fn options(&self) -> ModelOptions;
    /// The elastic energies, normal and tangential (J), a touching contact of materials
    /// `pm`, reduced radius `r_star` (m) and square root of the reduced mass
    /// `sqrt_m_star` (kg^1/2) stores at overlap `dn` (m) with elastic tangential force
    /// `fte` (N) (what the ledger adds for the pairs when it is read).
    fn stored_energy(&self, pm: &PairMaterial, r_star: f64, sqrt_m_star: f64, dn: f64, fte: <Self::D as Dim>::Vector<f64>) -> (f64, f64);
    /// The normal law's name and parameters, for `explain` and checkpoints.
    fn normal_label(&self) -> String;
    /// The rolling resistance's name and parameters ("" without).
    fn rolling_label(&self) -> String;
    /// A contact's state as a checkpoint stores it (the same numbers), and back.
    fn save_state(h: Held<Self::Tang, Self::Roll, f64, Self::D>) -> Saved<Self> {
        (Self::Tang::save(h.0), Self::Roll::save(h.1))
    }
    fn load_state(s: Saved<Self>) -> Held<Self::Tang, Self::Roll, f64, Self::D> {
        (Self::Tang::load(s.0), Self::Roll::load(s.1))
    }
    /// One line for `explain`.
    fn describe(&self) -> String {
        let o = self.options();
        format!(
            "Contacts<{}, {}, {}{}{}{}{}>",
            self.normal_label(),
            Self::Damp::NAME,
            Self::Tang::NAME,
            if Self::Coh::ON { format!(", {}", Self::Coh::NAME) } else { String::new() },
            if Self::Roll::ON { format!(", {}", self.rolling_label()) } else { String::new() },
            if o.limit_force { ", clamp Fn>=0" } else { "" },
            match (Self::Tang::FRICTION, o.lever_arm) {
                (true, LeverArm::RadiusMinusHalfOverlap) => ", arm r-dn/2",
                (true, LeverArm::Yade) => ", YADE ratcheting-free kinematics",
                (true, LeverArm::ContactPoint) => ", arm to the contact point",
                (true, LeverArm::Lammps) => ", LAMMPS' arms (r; r-dn/2 in a pair's torque)",
                _ => "",
            }
        )
    }
}

/// What a contact of tangential formulation `T` and rolling resistance `Rr` carries
/// from step to step (one per lane with `R = Lanes`): their two states. Without rolling
/// resistance the second is `()`, which takes no room.
pub type Held<T, Rr, R = f64, D = Plane> = (<T as Tangential<D>>::History<R>, <Rr as Rolling<D>>::History<R>);

/// A contact model, composed from a normal law, a damping form, a tangential
/// formulation, a cohesion model and a rolling resistance (none of the last two unless a
/// scene asks for them), in the plane (`D = Plane`, every engine today) or in space
/// (the force of one contact so far; issue 30).
#[derive(Clone, Copy, Debug)]
pub struct ContactModel<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion = NoCohesion, Rr: Rolling<D> = NoRolling, D: Dim = Plane> {
    pub options: ModelOptions,
    /// The normal law and its parameters (nothing for Hertz).
    pub normal: N,
    /// The rolling resistance and its parameters (nothing for most).
    pub rolling: Rr,
    _p: PhantomData<(Dm, T, C, D)>,
}

impl<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D> + Default, D: Dim> ContactModel<N, Dm, T, C, Rr, D> {
    pub fn new(options: ModelOptions, normal: N) -> Self {
        Self::with_rolling(options, normal, Rr::default())
    }
}

impl<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim> ContactModel<N, Dm, T, C, Rr, D> {
    /// A model whose rolling resistance has parameters.
    pub fn with_rolling(options: ModelOptions, normal: N, rolling: Rr) -> Self {
        ContactModel { options, normal, rolling, _p: PhantomData }
    }

    /// Four contacts' states in lanes, and one lane of them.
    #[inline(always)]
    pub fn gather(h: [&Held<T, Rr, f64, D>; crate::physics::lanes::LANES]) -> Held<T, Rr, crate::physics::lanes::Lanes, D> {
        (T::gather(h.map(|x| &x.0)), Rr::gather(h.map(|x| &x.1)))
    }
    #[inline(always)]
    pub fn lane(h: &Held<T, Rr, crate::physics::lanes::Lanes, D>, l: usize) -> Held<T, Rr, f64, D> {
        (T::lane(&h.0, l), Rr::lane(&h.1, l))
    }

    /// The force of a touching contact (of four, one per lane, with `R = Lanes`),
    /// advancing its tangential state. No branch on the data: the same bits per lane as
    /// for the contact alone.
    #[inline(always)]
    pub fn force<R: Real>(&self, c: &ContactInput<R, D>, pm: &PairMaterial<R>, h: &mut Held<T, Rr, R, D>) -> ContactState<R, D> {
        let st = self.normal.stiffness(pm, c.r_star, c.sqrt_m_star, c.dn);
        let (gn, gt) = Dm::coefficients(pm, c.sqrt_m_star, &st);
        let vc = c.contact_velocity();
        let vn = D::dot(vc, c.n);
        let mut elastic_n = st.kn * c.dn;
        // DMT: the pull-off force F0 = 2 pi w R* attracts while the bodies overlap.
        let pulloff = if C::ON { pm.pulloff * c.r_star } else { R::zero() };
        if C::ON {
            elastic_n -= pulloff;
        }
        let mut fnorm = elastic_n - gn * vn;
        if self.options.limit_force {
            fnorm = pick(fnorm.simd_lt(R::zero()), R::zero(), fnorm);
        }
        // The Coulomb cap: mu |Fn|, with cohesion mu |Fn + 2 F0| (the rule LAMMPS means
        // for dmt; its 20220106 release reads an unset value there, docs/fidelity.md).
        let cap_force = if C::ON { fnorm + k::<R>(2.0) * pulloff } else { fnorm };
        let mut force = c.n * fnorm;
        let mut tf = TangentialForce::default();
        if T::FRICTION {
            let mut vt = vc - c.n * vn;
            if self.options.lever_arm == LeverArm::Yade {
                vt += (c.v_rel - c.n * D::dot(c.v_rel, c.n)) * (c.tangential_scale - R::one());
            }
            let inp = TangentialInput { n: c.n, vt, kt: st.kt, gt, cap: pm.friction * cap_force.simd_abs(), dt: c.dt, twist: c.twist };
            tf = T::force(&mut h.0, &inp);
        }
        force += tf.elastic + tf.damping;
        let rolling = if Rr::ON {
            let inp = RollingInput { w: c.roll * c.roll_scale, r_star: c.r_star, kt: st.kt, elastic_normal: st.kn * c.dn, normal: fnorm, mu: pm.rolling_friction, dt: c.dt };
            self.rolling.torque(&mut h.1, &inp)
        } else {
            D::spin_zero()
        };
        ContactState { force, tangential: tf, normal: fnorm, elastic_normal: elastic_n, kn: st.kn, kt: st.kt, vc, rolling, roll: c.roll }
    }

}

impl<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim> ContactModel<N, Dm, T, C, Rr, D> {
    /// The force of a touching contact, updating its history; with `ENERGY`, this
    /// step's energy terms and stored energies go straight into `ledger` (the flat walls'
    /// contacts, which are few and run in one order).
    #[inline(always)]
    pub fn touch<const ENERGY: bool>(
        &self,
        c: &ContactInput<f64, D>,
        pm: &PairMaterial,
        h: &mut ContactHistory<Held<T, Rr, f64, D>, Rr::Energy, D>,
        ledger: &mut EnergyLedger,
    ) -> ContactForce<D> {
        let s = self.force(c, pm, &mut h.state);
        if ENERGY {
            self.energy_step(c.n, c.dt, &s, &mut h.energy);
            ledger.add(&std::mem::take(&mut h.energy.sums));
            ledger.rolling += h.energy.rolling.take();
            let pulloff = if C::ON { pm.pulloff * c.r_star } else { 0.0 };
            let (un, ut) = Self::elastic(s.kn, s.kt, pulloff, c.dn, s.tangential.elastic);
            ledger.elastic_normal += un;
            ledger.elastic_tangential += ut;
        }
        let tf = s.tangential;
        ContactForce { force: s.force, tangential: tf.elastic + tf.damping, normal: s.normal, kn: s.kn, rolling: s.rolling }
    }

    /// One step of a touching contact (of four, in lanes) in its energy memory `h`, from
    /// what [`ContactModel::force`] computed (normal `n`, time step `dt`, s): the
    /// trapezoidal work integrals of the step added to its sums, the previous-step
    /// values moved on. No branch on the data: the same bits per lane as alone.
    #[inline(always)]
    pub fn energy_step<R: Real, X: RollingEnergy<R, D::Spin<R>>>(&self, n: D::Vector<R>, dt: R, s: &ContactState<R, D>, h: &mut EnergyMemory<R, X, D>) {
        let dc = s.vc * dt;
        let fd = s.normal - s.elastic_normal;
        h.sums.normal_damping -= k::<R>(0.5) * (h.fd_prev + fd) * D::dot(dc, n);
        h.fd_prev = fd;
        if T::FRICTION {
            let tf = s.tangential;
            h.sums.tangential_damping -= k::<R>(0.5) * D::dot(h.ftd_prev + tf.damping, dc);
            h.sums.friction += tf.slip_energy;
            h.sums.tangential_model += tf.slip_energy + k::<R>(0.5) * D::dot(h.fte_prev + tf.elastic, dc);
            h.fte_prev = tf.elastic;
            h.ftd_prev = tf.damping;
        }
        if Rr::ON {
            h.rolling.step(s.rolling, s.roll, dt);
        }
    }

    /// The elastic energies, normal and tangential (J), a touching contact of stiffnesses
    /// `kn`, `kt` (N/m) and pull-off force `pulloff` (N; 0 without cohesion) stores at
    /// overlap `dn` (m) with elastic tangential force `fte` (N). Cohesion's potential is
    /// `-F0 dn`.
    #[inline(always)]
    fn elastic(kn: f64, kt: f64, pulloff: f64, dn: f64, fte: D::Vector<f64>) -> (f64, f64) {
        let ut = if T::FRICTION && kt > 0.0 { 0.5 * D::norm_squared(fte) / kt } else { 0.0 };
        let un = N::energy(kn, dn);
        (if C::ON { un - pulloff * dn } else { un }, ut)
    }

    /// A contact that was touching at the previous step and is not any more: close its
    /// energy integrals into its sums (the force fell to zero over this step) and forget
    /// its history: the law's state `t` and (with `ENERGY`) the previous-step values in
    /// `h` (`roll`: the relative spin w_i - w_j, rad/s, for the rolling torque's work). The sums stay, for the ledger to take.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn release<const ENERGY: bool>(&self, c_velocity: D::Vector<f64>, n: D::Vector<f64>, roll: D::Spin<f64>, dt: f64, t: &mut Held<T, Rr, f64, D>, h: &mut EnergyMemory<f64, Rr::Energy, D>) {
        if ENERGY {
            let dc = c_velocity * dt;
            h.sums.normal_damping -= 0.5 * h.fd_prev * D::dot(dc, n);
            if T::FRICTION {
                h.sums.tangential_damping -= 0.5 * D::dot(h.ftd_prev, dc);
                h.sums.tangential_model += 0.5 * D::dot(h.fte_prev, dc);
            }
            if Rr::ON {
                h.rolling.release(roll, dt);
            }
        }
        *t = Default::default();
        if ENERGY {
            *h = EnergyMemory { fd_prev: 0.0, fte_prev: D::zero(), ftd_prev: D::zero(), sums: h.sums, rolling: h.rolling };
        }
    }
}

impl<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim> ContactLaw for ContactModel<N, Dm, T, C, Rr, D> {
    type D = D;
    type Damp = Dm;
    type Tang = T;
    type Coh = C;
    type Roll = Rr;
    fn options(&self) -> ModelOptions {
        self.options
    }
    #[inline]
    fn stored_energy(&self, pm: &PairMaterial, r_star: f64, sqrt_m_star: f64, dn: f64, fte: D::Vector<f64>) -> (f64, f64) {
        let st = self.normal.stiffness(pm, r_star, sqrt_m_star, dn);
        Self::elastic(st.kn, st.kt, pm.pulloff * r_star, dn, fte)
    }
    fn normal_label(&self) -> String {
        self.normal.label()
    }
    fn rolling_label(&self) -> String {
        if Rr::ON { self.rolling.label() } else { String::new() }
    }
}

/// The named combinations grainlab compiles. A scene picks one of these; any other
/// combination is refused with this list.
pub type HertzFrictionless<D = Plane> = ContactModel<Hertz, Viscoelastic, Frictionless, NoCohesion, NoRolling, D>;
pub type HertzFrictionlessElastic<D = Plane> = ContactModel<Hertz, Undamped, Frictionless, NoCohesion, NoRolling, D>;
/// LIGGGHTS `pair_style gran model hertz tangential history`.
pub type LiggghtsHertzHistory<D = Plane> = ContactModel<Hertz, Viscoelastic, TotalDisplacement, NoCohesion, NoRolling, D>;
pub type LiggghtsHertzHistoryElastic<D = Plane> = ContactModel<Hertz, Undamped, TotalDisplacement, NoCohesion, NoRolling, D>;
/// YADE `Law2_ScGeom_MindlinPhys_Mindlin` (incremental tangential force).
pub type YadeMindlin<D = Plane> = ContactModel<Hertz, Viscoelastic, IncrementalForce, NoCohesion, NoRolling, D>;
pub type YadeMindlinElastic<D = Plane> = ContactModel<Hertz, Undamped, IncrementalForce, NoCohesion, NoRolling, D>;
/// The linear spring-dashpot without friction.
pub type HookeFrictionless<D = Plane> = ContactModel<Hooke, LinearRestitution, Frictionless, NoCohesion, NoRolling, D>;
pub type HookeFrictionlessElastic<D = Plane> = ContactModel<Hooke, Undamped, Frictionless, NoCohesion, NoRolling, D>;
/// LIGGGHTS `pair_style gran model hooke tangential history` (and `hooke/stiffness`).
pub type LiggghtsHookeHistory<D = Plane> = ContactModel<Hooke, LinearRestitution, TotalDisplacement, NoCohesion, NoRolling, D>;
pub type LiggghtsHookeHistoryElastic<D = Plane> = ContactModel<Hooke, Undamped, TotalDisplacement, NoCohesion, NoRolling, D>;
/// The linear spring with YADE's incremental tangential force (`Law2_ScGeom_FrictPhys_CundallStrack`'s history).
pub type HookeIncremental<D = Plane> = ContactModel<Hooke, LinearRestitution, IncrementalForce, NoCohesion, NoRolling, D>;
pub type HookeIncrementalElastic<D = Plane> = ContactModel<Hooke, Undamped, IncrementalForce, NoCohesion, NoRolling, D>;

/// LAMMPS `pair granular ... tangential mindlin` (Hertz) and `linear_history` (the
/// linear spring): the cap on the total tangential force (`model.tangential =
/// "total_force_cap"`), with the restitution damping, none, or Tsuji's.
pub type HertzForceCap<D = Plane> = ContactModel<Hertz, Viscoelastic, TotalForceCap, NoCohesion, NoRolling, D>;
pub type HertzForceCapElastic<D = Plane> = ContactModel<Hertz, Undamped, TotalForceCap, NoCohesion, NoRolling, D>;
pub type HertzTsujiForceCap<D = Plane> = ContactModel<Hertz, TsujiFit, TotalForceCap, NoCohesion, NoRolling, D>;
pub type HookeForceCap<D = Plane> = ContactModel<Hooke, LinearRestitution, TotalForceCap, NoCohesion, NoRolling, D>;
pub type HookeForceCapElastic<D = Plane> = ContactModel<Hooke, Undamped, TotalForceCap, NoCohesion, NoRolling, D>;
pub type HookeTsujiForceCap<D = Plane> = ContactModel<Hooke, TsujiFit, TotalForceCap, NoCohesion, NoRolling, D>;

/// The cap on the total tangential force with the spring kept (`model.tangential =
/// "total_force_cap_spring_kept"`, Kratos' rule): gross sliding exact under damped Hertz,
/// with the restitution damping or none.
pub type HertzSpringKept<D = Plane> = ContactModel<Hertz, Viscoelastic, TotalForceCapSpringKept, NoCohesion, NoRolling, D>;
pub type HertzSpringKeptElastic<D = Plane> = ContactModel<Hertz, Undamped, TotalForceCapSpringKept, NoCohesion, NoRolling, D>;
pub type HookeSpringKept<D = Plane> = ContactModel<Hooke, LinearRestitution, TotalForceCapSpringKept, NoCohesion, NoRolling, D>;
pub type HookeSpringKeptElastic<D = Plane> = ContactModel<Hooke, Undamped, TotalForceCapSpringKept, NoCohesion, NoRolling, D>;

/// Mindlin-Deresiewicz micro-slip (`model.tangential = "mindlin_deresiewicz"`), Hertz
/// only (its bed of springs spans the Hertz radius, `kt = 8 G* a`), with the restitution
/// damping or none.
pub type HertzMicroSlip = ContactModel<Hertz, Viscoelastic, MicroSlip>;
pub type HertzMicroSlipElastic = ContactModel<Hertz, Undamped, MicroSlip>;

/// LAMMPS `pair granular ... damping tsuji` (`model.damping = "tsuji"`), either normal
/// law, frictionless or with the total-displacement history.
pub type HertzTsujiFrictionless<D = Plane> = ContactModel<Hertz, TsujiFit, Frictionless, NoCohesion, NoRolling, D>;
pub type HertzTsujiHistory<D = Plane> = ContactModel<Hertz, TsujiFit, TotalDisplacement, NoCohesion, NoRolling, D>;
pub type HookeTsujiFrictionless<D = Plane> = ContactModel<Hooke, TsujiFit, Frictionless, NoCohesion, NoRolling, D>;
pub type HookeTsujiHistory<D = Plane> = ContactModel<Hooke, TsujiFit, TotalDisplacement, NoCohesion, NoRolling, D>;
/// LAMMPS' current `damping tsuji` (`model.damping = "tsuji_sqrt2"`: the fit times
/// sqrt(2)), with the same normal laws and tangential formulations.
pub type HertzTsujiSqrt2Frictionless<D = Plane> = ContactModel<Hertz, TsujiFit<true>, Frictionless, NoCohesion, NoRolling, D>;
pub type HertzTsujiSqrt2History<D = Plane> = ContactModel<Hertz, TsujiFit<true>, TotalDisplacement, NoCohesion, NoRolling, D>;
pub type HertzTsujiSqrt2ForceCap<D = Plane> = ContactModel<Hertz, TsujiFit<true>, TotalForceCap, NoCohesion, NoRolling, D>;
pub type HookeTsujiSqrt2Frictionless<D = Plane> = ContactModel<Hooke, TsujiFit<true>, Frictionless, NoCohesion, NoRolling, D>;
pub type HookeTsujiSqrt2History<D = Plane> = ContactModel<Hooke, TsujiFit<true>, TotalDisplacement, NoCohesion, NoRolling, D>;
pub type HookeTsujiSqrt2ForceCap<D = Plane> = ContactModel<Hooke, TsujiFit<true>, TotalForceCap, NoCohesion, NoRolling, D>;

/// DMT cohesion (`materials[].work_of_adhesion` > 0) with either normal law and its
/// restitution damping (which is 0 at e = 1), frictionless or with the total-displacement
/// history: LAMMPS `pair granular dmt` for Hertz.
pub type HertzDmtFrictionless<D = Plane> = ContactModel<Hertz, Viscoelastic, Frictionless, Dmt, NoRolling, D>;
pub type HertzDmtHistory<D = Plane> = ContactModel<Hertz, Viscoelastic, TotalDisplacement, Dmt, NoRolling, D>;
pub type HookeDmtFrictionless<D = Plane> = ContactModel<Hooke, LinearRestitution, Frictionless, Dmt, NoRolling, D>;
pub type HookeDmtHistory<D = Plane> = ContactModel<Hooke, LinearRestitution, TotalDisplacement, Dmt, NoRolling, D>;

/// Rolling resistance (`model.rolling`) with either normal law, its restitution damping
/// and the total-displacement history: LIGGGHTS `rolling_friction cdt` and `epsd2`,
/// LAMMPS `rolling sds`.
pub type HertzHistoryCdt = ContactModel<Hertz, Viscoelastic, TotalDisplacement, NoCohesion, Cdt>;
pub type HertzHistoryEpsd2 = ContactModel<Hertz, Viscoelastic, TotalDisplacement, NoCohesion, Epsd2>;
pub type HertzHistorySds = ContactModel<Hertz, Viscoelastic, TotalDisplacement, NoCohesion, Sds>;
pub type HookeHistoryCdt = ContactModel<Hooke, LinearRestitution, TotalDisplacement, NoCohesion, Cdt>;
pub type HookeHistoryEpsd2 = ContactModel<Hooke, LinearRestitution, TotalDisplacement, NoCohesion, Epsd2>;
pub type HookeHistorySds = ContactModel<Hooke, LinearRestitution, TotalDisplacement, NoCohesion, Sds>;

/// The names of the compiled combinations, for a refusal.
pub const COMPILED: &str = "normal hertz or hooke (hooke_stiffness), each with damping (beta(e); the linear spring's constant-restitution form) or none (every e = 1), and tangential total_displacement, total_force_cap, total_force_cap_spring_kept, incremental_force or frictionless; mindlin_deresiewicz with hertz, its damping or none; damping tsuji or tsuji_sqrt2 with either normal law, total_displacement, total_force_cap or frictionless; cohesion (work_of_adhesion > 0) with either normal law, the restitution damping, total_displacement or frictionless, without limit_force; rolling (cdt, epsd2, sds) with either normal law, the restitution damping and total_displacement, without cohesion";
