//! The scene file (JSON): what is simulated, how, and what is written.
//!
//! Every field, its unit and its default are listed in docs/scene.md. A scene is
//! validated as a whole before anything is built or written
//! ([`crate::scene::validate`]); an error names the field, the value and the allowed
//! range.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::physics::contact::LeverArm;
pub use crate::physics::contact::normal::NormalLaw;
use crate::physics::dim::GrainShape;
use crate::physics::material::Material;
pub use crate::scene::coords::{Coords, Dimension, SpinSpec};
use crate::scene::pack::RadiusDist;

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name, used for output files.
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// Sphere-in-plane (default) or disk of a stated thickness.
    #[serde(default)]
    pub grain_shape: GrainShape,
    /// 2 (the plane, the default) or 3 (spheres in space). In a 3D scene a vector may
    /// have three numbers, a spin three components; a plane value is lifted into space
    /// (z = 0). Left out of written scenes at 2.
    #[serde(default, skip_serializing_if = "Dimension::is_two")]
    pub dimension: Dimension,
    /// Materials; grains and walls refer to them by index. Default: one glass.
    #[serde(default = "default_materials")]
    pub materials: Vec<Material>,
    /// Periodicity in x. Default: none.
    #[serde(default)]
    pub domain: Domain,
    pub grains: Grains,
    /// Bottom and top walls. Default: none.
    #[serde(default)]
    pub walls: Option<WallsSpec>,
    /// Gravity, m/s^2: `[gx, gy]`, or `[gx, gy, gz]` in 3D. Default [0, 0] (off: no
    /// stage).
    #[serde(default)]
    pub gravity: Coords,
    #[serde(default)]
    pub model: ModelSpec,
    pub time_step: TimeStepSpec,
    /// Simulated time, s. With `stages` it may be left out (it is then their sum) or
    /// given as their sum.
    #[serde(default)]
    pub duration: f64,
    #[serde(default)]
    pub neighbor: NeighborSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// What the summary reports. Default: none.
    #[serde(default)]
    pub analysis: Analysis,
    /// How a shear analysis averages its rows: from where, in how many blocks. Default:
    /// the second half of each averaged stretch, blocks from the measured autocorrelation.
    #[serde(default)]
    pub statistics: StatisticsSpec,
    /// A protocol: stages run one after another, each changing the walls' motion and
    /// control, gravity, the output rates and the averaging at its start. Default: none
    /// (the scene runs as given for `duration`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<StageSpec>,
}

/// One stage of a protocol: what changes at its start and how long it runs. What it does
/// not name stays as the scene (or the stage before) left it.
#[derive(Clone, Debug, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    /// Name, written in the time series' `stage` column and the summary. Letters, digits,
    /// spaces and `-_.`, at most 64 characters. Default `stage K` (K counts from 1).
    #[serde(default)]
    pub name: String,
    /// Simulated time of the stage, s (> 0).
    pub duration: f64,
    /// The walls' motion and control from the stage's start. Default: unchanged.
    #[serde(default)]
    pub walls: StageWalls,
    /// Gravity from the stage's start, m/s^2 (three numbers in 3D). Default: unchanged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<Coords>,
    /// Rows of the time series over the stage (>= 1). Default: the scene's
    /// `output.samples` shared out by duration.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<u64>,
    /// ParaView frames over the stage. Default: the scene's `output.frames` shared out by
    /// duration.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames: Option<u64>,
    /// Whether the summary averages the stage's wall stresses (analysis `shear`): a
    /// compression or relaxation stage is not a steady state. Default true.
    #[serde(default = "yes")]
    pub average: bool,
}

/// The walls' changes at a stage's start.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StageWalls {
    #[serde(default, skip_serializing_if = "WallChange::is_none")]
    pub bottom: WallChange,
    #[serde(default, skip_serializing_if = "WallChange::is_none")]
    pub top: WallChange,
}

/// One wall's change at a stage's start; each field left out stays as it was.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallChange {
    /// Velocity in x, m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_x: Option<f64>,
    /// Velocity in y of a wall under `fixed` control (a prescribed motion), m/s. A wall
    /// that changes to `fixed` without it is held (0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_y: Option<f64>,
    /// `"fixed"` (prescribed motion) or `{"pressure": p}` (Pa, top wall only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<ControlSpec>,
}

impl WallChange {
    pub fn is_none(&self) -> bool {
        *self == WallChange::default()
    }
    /// The y velocity the change sets, m/s: its own, or 0 (held) when it changes the wall
    /// to fixed control without one; `None` leaves the wall's as it is.
    pub fn velocity_y_set(&self) -> Option<f64> {
        self.velocity_y.or(match self.control {
            Some(ControlSpec::Fixed) => Some(0.0),
            _ => None,
        })
    }
}

fn default_materials() -> Vec<Material> {
    vec![Material::default()]
}

#[derive(Clone, Debug, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    /// `[x_min, x_max]` of the periodic cell, m. Default: not periodic.
    #[serde(default)]
    pub periodic_x: Option<[f64; 2]>,
    /// `[z_min, z_max]` of the periodic cell along z, m (3D only). Default: not periodic
    /// (grains free along z).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic_z: Option<[f64; 2]>,
}

/// Where the grains come from.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Grains {
    /// Grains listed one by one.
    List(Vec<GrainSpec>),
    /// A particle file: one grain per line, in the declared `columns` (m); `#` starts a
    /// comment. A relative path is taken from the scene file's folder.
    File {
        path: String,
        /// The numbers on each line. Default `"x y r"`.
        #[serde(default)]
        columns: GrainColumns,
        #[serde(default)]
        material: usize,
    },
    /// A seeded random packing.
    Pack(PackSpec),
}

/// The columns of a grain file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub enum GrainColumns {
    /// Centre x, y and radius, m.
    #[default]
    #[serde(rename = "x y r")]
    XYR,
    /// Centre x, y, z and radius, m: in a 3D scene the sphere's centre; in a plane
    /// scene z is read and ignored (a LAMMPS-style 3D file of a monolayer). The columns
    /// a 3D scene's file needs.
    #[serde(rename = "x y z r")]
    XYZR,
}

impl GrainColumns {
    /// Numbers per line.
    pub fn count(self) -> usize {
        match self {
            GrainColumns::XYR => 3,
            GrainColumns::XYZR => 4,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            GrainColumns::XYR => "x y r",
            GrainColumns::XYZR => "x y z r",
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GrainSpec {
    /// Centre, m: `[x, y]`, or `[x, y, z]` in 3D.
    pub x: Coords,
    /// Velocity, m/s (three numbers in 3D). Default [0, 0].
    #[serde(default)]
    pub v: Coords,
    /// Spin, rad/s: a number (about z), or `[wx, wy, wz]` in 3D. Default 0.
    #[serde(default)]
    pub omega: SpinSpec,
    /// Radius, m.
    pub r: f64,
    /// Material index. Default 0.
    #[serde(default)]
    pub material: usize,
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PackSpec {
    /// Number of grains.
    pub count: usize,
    pub radius: RadiusDist,
    /// Seed of the ChaCha8 stream for radii and positions. Default 1.
    #[serde(default = "one")]
    pub seed: u64,
    /// Material index. Default 0.
    #[serde(default)]
    pub material: usize,
    /// `[x_min, x_max]` of the packing region, m (the periodic cell if periodic).
    pub x: [f64; 2],
    /// `[z_min, z_max]` of the packing region in 3D, m (the periodic cell along z if
    /// periodic in z; needed in 3D, refused in 2D).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<[f64; 2]>,
    /// Lower edge of the packing region, m. Default: on the bottom wall.
    #[serde(default)]
    pub y_min: Option<f64>,
    /// Area fraction (2D) the region is sized for (its height follows), in (0, 0.8].
    /// Default 0.75 (denser random packings do not relax free of overlaps). In 3D the
    /// volume fraction, in (0, 0.6] (random close packing of spheres is about 0.64), to
    /// be given: the default is the plane's.
    #[serde(default = "default_fraction")]
    pub packing_fraction: f64,
}

fn one() -> u64 {
    1
}
fn default_fraction() -> f64 {
    0.75
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallsSpec {
    pub bottom: WallSpec,
    pub top: WallSpec,
    /// Out-of-plane depth that turns wall forces into stresses, m: stress = F / (L_x t).
    /// Default: the disk thickness, or the mean grain diameter for spheres in the plane;
    /// in 3D the cell's length along z (refused there: the wall's area is L_x L_z).
    #[serde(default)]
    pub thickness: Option<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    /// Position of the contact plane (flat) or of the glued grains' centres (rough), m.
    /// Default for the top wall: just above the packing.
    #[serde(default)]
    pub y: Option<f64>,
    /// Velocity in x, m/s. Default 0.
    #[serde(default)]
    pub velocity_x: f64,
    /// Velocity in y, m/s, of a wall under `fixed` control (a prescribed motion, e.g. a
    /// compression at constant rate). Default 0 (held).
    #[serde(default)]
    pub velocity_y: f64,
    /// `"flat"` (default) or `{"rough": {"radius": r}}`.
    #[serde(default)]
    pub surface: SurfaceSpec,
    /// `"fixed"` (default) or `{"pressure": p}` (Pa, on the top wall).
    #[serde(default)]
    pub control: ControlSpec,
    /// Mass that a pressure accelerates, kg. Default: the glued grains, or a row of
    /// grains of mean size for a flat wall.
    #[serde(default)]
    pub mass: Option<f64>,
    /// Material index. Default 0.
    #[serde(default)]
    pub material: usize,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SurfaceSpec {
    #[default]
    Flat,
    /// A row of touching grains of this radius (m) glued to the wall.
    Rough { radius: f64 },
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ControlSpec {
    #[default]
    Fixed,
    /// Constant normal stress on the wall, Pa.
    Pressure(f64),
}

/// Tangential formulation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum TangentialSpec {
    /// LIGGGHTS `tangential history`.
    #[default]
    TotalDisplacement,
    /// LAMMPS `pair granular ... tangential mindlin` (Hertz) or `linear_history` (the
    /// linear spring): a total displacement like LIGGGHTS', but the Coulomb cap holds the
    /// total tangential force, damping included, and the history is rescaled to its
    /// length when the contact frame turns. The friction impulse never exceeds mu times
    /// the normal one (docs/model.md).
    TotalForceCap,
    /// The cap on the total tangential force with the spring kept (the rule of Kratos
    /// DEMApplication's `DEM_D_Hertz_viscous_Coulomb` on LIGGGHTS' total displacement):
    /// while sliding the total force is mu |Fn| exactly, the spring keeps its displacement
    /// (scaled to the cap only if it alone exceeds it) and the dashpot takes the rest. The
    /// friction impulse of a gross slide is mu times the normal one, damped Hertz included
    /// (docs/model.md). No reference code has it: exports write the nearest law with a
    /// `# Differs:` line.
    TotalForceCapSpringKept,
    /// Mindlin-Deresiewicz micro-slip (Hertz only): the contact is a bed of springs
    /// across its radius, each holding its share of the Hertz pressure times mu, so slip
    /// spreads in from the edge as the tangential load grows, under any history of normal
    /// and tangential load (Popov and Heß's method of dimensionality reduction, exact for
    /// these contacts; docs/model.md). Dashpot and cap as the spring-kept cap. No
    /// reference code has micro-slip: exports refuse it.
    MindlinDeresiewicz,
    /// YADE `Law2_ScGeom_MindlinPhys_Mindlin`.
    IncrementalForce,
    /// No tangential force (and no spin).
    Frictionless,
}

impl TangentialSpec {
    /// The name a scene gives it.
    pub fn name(self) -> &'static str {
        match self {
            TangentialSpec::TotalDisplacement => "total_displacement",
            TangentialSpec::TotalForceCap => "total_force_cap",
            TangentialSpec::TotalForceCapSpringKept => "total_force_cap_spring_kept",
            TangentialSpec::MindlinDeresiewicz => "mindlin_deresiewicz",
            TangentialSpec::IncrementalForce => "incremental_force",
            TangentialSpec::Frictionless => "frictionless",
        }
    }
}

/// Rolling resistance (`model.rolling`): a torque against the relative spin w_i - w_j
/// of two bodies in contact, at most `mu_r R* |Fn|` with `mu_r` the pair's
/// `materials[].rolling_friction` ([`crate::physics::contact::rolling`]). Compiled with
/// either normal law, the restitution damping and the total-displacement tangential
/// history, without cohesion.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RollingSpec {
    /// No rolling resistance (the default).
    #[default]
    None,
    /// Constant directional torque (LIGGGHTS `rolling_friction cdt`): `mu_r R* kn dn`
    /// against the relative spin.
    Cdt,
    /// Elastic-plastic torque spring (LIGGGHTS `rolling_friction epsd2`): stiffness
    /// `kt R*^2`, loaded by the relative rotation, capped at `mu_r R* |Fn|`.
    Epsd2,
    /// Spring-dashpot-slider on the rolling displacement (LAMMPS `rolling sds`):
    /// `stiffness` k (N/m, > 0) and `damping` g (kg/s, >= 0); the force `-k s - g R* w`
    /// capped at `mu_r |Fn|` acts at arm R*.
    Sds { stiffness: f64, damping: f64 },
}

impl RollingSpec {
    pub fn is_none(&self) -> bool {
        *self == RollingSpec::None
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Normal law: `"hertz"` (default), `{"hooke": {"characteristic_velocity": vc}}` or
    /// `{"hooke_stiffness": {"kn": .., "kt": ..}}` (the linear spring; see
    /// [`NormalLaw`]). Left out of written scenes when it is Hertz.
    #[serde(default, skip_serializing_if = "NormalLaw::is_hertz")]
    pub normal: NormalLaw,
    /// Contact damping: `"restitution"` (default: the damping that returns each pair's
    /// restitution e, beta(e) viscoelastic for Hertz, constant restitution for the linear
    /// spring), `"clamped_restitution"`, `"tsuji"` (LAMMPS 20220106's `damping tsuji`) or
    /// `"tsuji_sqrt2"` (LAMMPS' current one); see [`DampingSpec`]. Left out of
    /// written scenes at its default.
    #[serde(default, skip_serializing_if = "DampingSpec::is_restitution")]
    pub damping: DampingSpec,
    #[serde(default)]
    pub tangential: TangentialSpec,
    /// Rolling resistance: `"none"` (default), `"cdt"`, `"epsd2"` or `{"sds":
    /// {"stiffness": k, "damping": g}}` (see [`RollingSpec`]); it acts on the pairs
    /// whose materials have a `rolling_friction` above 0. Left out of written scenes
    /// when none.
    #[serde(default, skip_serializing_if = "RollingSpec::is_none")]
    pub rolling: RollingSpec,
    /// Clamp Fn >= 0 (LIGGGHTS `limitForce`). Default false.
    #[serde(default)]
    pub limit_force: bool,
    /// Torque lever arm: `"radius"` (default, the seed) or `"radius_minus_half_overlap"`.
    #[serde(default)]
    pub lever_arm: LeverArm,
    /// Integrate spins. Default true (ignored without friction).
    #[serde(default = "yes")]
    pub rotation: bool,
    /// The seed's general damping: a viscous drag on every free grain, `F = -c m v`,
    /// `M = -c I w`, with the rate `c` in 1/s (> 0). Its dissipation enters the energy
    /// balance. Default none (no stage).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub general_damping: Option<f64>,
}

fn yes() -> bool {
    true
}

/// The contact damping (`model.damping`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DampingSpec {
    /// The damping that returns each pair's restitution e (the default): Hertz,
    /// `gn = -2 sqrt(5/6) beta(e) sqrt(Sn m*)`; the linear spring, `gn = -2 beta(e)
    /// sqrt(kn m*)`; tangential alike with St, kt.
    #[default]
    Restitution,
    /// The restitution damping with the beta that returns each pair's e *under the
    /// clamp* (`model.limit_force: true`, which it requires): the same force laws as
    /// `restitution`, with `beta` solved from the clamped contact's equation of motion
    /// (a closed form, the same for Hertz and the spring: src/physics/restitution.rs,
    /// docs/model.md) instead of `beta(e)`, which under the clamp returns more than e
    /// (0.2 gives 0.325). |beta| exceeds 1 below e = exp(-2) = 0.135; e = 0 is refused
    /// (infinite damping). The
    /// tangential damping takes the same beta. Exported to YADE (which always clamps)
    /// and LAMMPS (`limit_damping`) as their damping coefficient; to LIGGGHTS as the
    /// restitution whose beta(e) it is (Hertz: e above 0.214, where that restitution is
    /// above the 0.05 LIGGGHTS takes; refused below).
    ClampedRestitution,
    /// LAMMPS' `damping tsuji` (pair granular and fix wall/gran granular, 29Sep2021):
    /// `gn = alpha(e) sqrt(m* kn)`, `gt = alpha(e) sqrt(m* kt)` (the force -g v), kn the secant normal
    /// stiffness (Hertz 4/3 E* sqrt(R* dn), or the spring's), kt the tangential one, and
    /// `alpha(e) = 1.2728 - 4.2783 e + 11.087 e^2 - 22.348 e^3 + 27.467 e^4 - 18.022 e^5
    /// + 4.8218 e^6` (LAMMPS' fit after Tsuji et al. 1992). The realised restitution is
    /// not e: in continuous time without the clamp it is `exp(-pi b / sqrt(1 - b^2))`,
    /// b = alpha / sqrt(5) for Hertz (e = 0.5 gives 0.62), b = alpha / 2 for the spring;
    /// alpha(1) = 3e-4, so contacts are damped at e = 1 too. Compiled with the
    /// total-displacement history, LAMMPS' cap on the total force and frictionless
    /// contacts.
    Tsuji,
    /// LAMMPS' current `damping tsuji` (its src/GRANULAR/gran_sub_mod_damping.cpp): the
    /// same fit times sqrt(2), "for effective mass convention (as in Tsuji 1992)", so
    /// `gn = sqrt(2) alpha(e) sqrt(m* kn)`. Under Hertz the realised restitution in
    /// continuous time is then the input within 1.1e-3 over e = 0.1 to 1 (b = sqrt(2)
    /// alpha / sqrt(5): e = 0.5 gives 0.4999); under the linear spring it is not (b =
    /// alpha / sqrt(2): 0.5 gives 0.458). The damping
    /// LAMMPS' analytic granular tests expect. Compiled as `tsuji`; exported to LAMMPS
    /// 20220106 as its `damping tsuji` with the input its fit maps to the same alpha.
    TsujiSqrt2,
}

impl DampingSpec {
    pub fn is_restitution(&self) -> bool {
        *self == DampingSpec::Restitution
    }
    /// Its name in a scene file (`model.damping`).
    pub fn name(&self) -> &'static str {
        match self {
            DampingSpec::Restitution => "restitution",
            DampingSpec::ClampedRestitution => "clamped_restitution",
            DampingSpec::Tsuji => "tsuji",
            DampingSpec::TsujiSqrt2 => "tsuji_sqrt2",
        }
    }
    /// LAMMPS' Tsuji fit, either release's: its factor on the fit (1 or sqrt(2)), or None.
    pub fn tsuji(&self) -> Option<f64> {
        match self {
            DampingSpec::Tsuji => Some(crate::physics::contact::damping::tsuji_factor(false)),
            DampingSpec::TsujiSqrt2 => Some(crate::physics::contact::damping::tsuji_factor(true)),
            _ => None,
        }
    }
}

impl ModelSpec {
    /// How each pair's damping beta follows from its restitution under this model.
    pub fn beta_rule(&self) -> crate::physics::material::BetaRule {
        use crate::physics::material::BetaRule;
        match self.damping {
            DampingSpec::ClampedRestitution => BetaRule::Clamped,
            _ => BetaRule::Free,
        }
    }
}

impl Default for ModelSpec {
    fn default() -> Self {
        ModelSpec { normal: NormalLaw::Hertz, damping: DampingSpec::Restitution, tangential: TangentialSpec::default(), rolling: RollingSpec::None, limit_force: false, lever_arm: LeverArm::default(), rotation: true, general_damping: None }
    }
}

/// How the time step is chosen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeStepRule {
    /// A given dt, s.
    Fixed { dt: f64 },
    /// dt = t_c / steps, t_c the Hertz contact time of the smallest grains at `impact_speed` (m/s).
    StepsPerContact { steps: f64, impact_speed: f64 },
    /// dt = fraction x the Rayleigh time of the smallest grain.
    RayleighFraction { fraction: f64 },
    /// The seed's rule dt = factor x 2 sqrt(min m / max k), k = kn at an overlap of
    /// `reference_overlap` x the smallest radius.
    SeedRule { factor: f64, reference_overlap: f64 },
    /// The largest dt whose measured error on `quantity` is within `tolerance`, from the
    /// convergence of a head-on impact of the smallest grains at `impact_speed` (m/s);
    /// see [`crate::study::accuracy`].
    Accuracy { quantity: AccuracyQuantity, tolerance: f64, impact_speed: f64 },
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeStepSpec {
    pub rule: TimeStepRule,
    /// Speed that sets the overlap for the stability limit and for reporting steps per
    /// contact, m/s. Default: the rule's impact speed, else 1.
    #[serde(default)]
    pub characteristic_speed: Option<f64>,
    /// Run even when dt exceeds the stability limit. Default false.
    #[serde(default)]
    pub allow_unstable: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NeighborSpec {
    /// Verlet skin as a fraction of the smallest grain diameter, > 0. Default 0.2.
    #[serde(default = "default_skin")]
    pub skin: f64,
}

fn default_skin() -> f64 {
    0.2
}

impl Default for NeighborSpec {
    fn default() -> Self {
        NeighborSpec { skin: default_skin() }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Rows of the time series (energy, walls). Default 200.
    #[serde(default = "default_samples")]
    pub samples: u64,
    /// ParaView frames (0: none). Default 20.
    #[serde(default = "default_frames")]
    pub frames: u64,
    /// Track the energy balance. Default true.
    #[serde(default = "yes")]
    pub energy: bool,
    /// Record every contact at each sample (and frame): the packing's stress tensor,
    /// coordination, sliding fraction and fabric go to `packing.csv`. Default false (no
    /// recording stage in the pipeline, nothing to pay; left out of written scenes).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub contacts: bool,
}

fn default_samples() -> u64 {
    200
}
fn default_frames() -> u64 {
    20
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec { samples: default_samples(), frames: default_frames(), energy: true, contacts: false }
    }
}

/// How a shear analysis averages the wall rows of a run, or of each averaged stage
/// (docs/statistics.md).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StatisticsSpec {
    /// Where the average starts, as a fraction of the stretch's rows (the run's, or the
    /// averaged stage's): the rows before it are the transient left out. 0 <= f < 1;
    /// default 0.5 (the second half).
    #[serde(default = "default_average_from")]
    pub average_from: f64,
    /// Blocks of the 95% interval of each quantity: `"auto"` (default) cuts the averaged
    /// rows into blocks of 8 integrated autocorrelation times of that quantity, measured
    /// on its rows (at least 2 blocks, at most 100; the time is reported); a number from 2
    /// to 1000 fixes the count.
    #[serde(default)]
    pub blocks: BlocksSpec,
}

fn default_average_from() -> f64 {
    0.5
}

impl Default for StatisticsSpec {
    fn default() -> Self {
        StatisticsSpec { average_from: default_average_from(), blocks: BlocksSpec::default() }
    }
}

/// `"auto"` or a number of blocks ([`StatisticsSpec::blocks`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum BlocksSpec {
    Auto(AutoBlocks),
    Count(u64),
}

/// The word `"auto"`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AutoBlocks {
    Auto,
}

/// Read by hand so that a wrong value is refused saying what is allowed (an untagged
/// enum's derived reader says only that no variant matched).
impl<'de> Deserialize<'de> for BlocksSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::{Error, Unexpected, Visitor};
        struct Blocks;
        impl Visitor<'_> for Blocks {
            type Value = BlocksSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"auto\" or a number of blocks (2 to 1000)")
            }
            fn visit_str<E: Error>(self, s: &str) -> Result<BlocksSpec, E> {
                if s == "auto" { Ok(BlocksSpec::Auto(AutoBlocks::Auto)) } else { Err(E::invalid_value(Unexpected::Str(s), &self)) }
            }
            fn visit_u64<E: Error>(self, n: u64) -> Result<BlocksSpec, E> {
                Ok(BlocksSpec::Count(n))
            }
            fn visit_i64<E: Error>(self, n: i64) -> Result<BlocksSpec, E> {
                u64::try_from(n).map(BlocksSpec::Count).map_err(|_| E::invalid_value(Unexpected::Signed(n), &self))
            }
        }
        d.deserialize_any(Blocks)
    }
}

impl Default for BlocksSpec {
    fn default() -> Self {
        BlocksSpec::Auto(AutoBlocks::Auto)
    }
}

/// What the summary reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Analysis {
    #[default]
    None,
    /// Grain 0 against grain 1, or grain 0 against a wall: restitution, overlap, force.
    Impact,
    /// Wall stresses with confidence intervals, averaged as `statistics` says.
    Shear,
}

impl SurfaceSpec {
    /// The glued grains' radius of a rough wall (its surface lies that far from its `y`),
    /// 0 for a flat wall, m.
    pub fn radius(&self) -> f64 {
        match *self {
            SurfaceSpec::Flat => 0.0,
            SurfaceSpec::Rough { radius } => radius,
        }
    }
    /// `flat` or `rough`, as the scene file names it.
    pub fn kind(&self) -> &'static str {
        match self {
            SurfaceSpec::Flat => "flat",
            SurfaceSpec::Rough { .. } => "rough",
        }
    }
}

impl Analysis {
    /// As the scene file names it.
    pub fn name(self) -> &'static str {
        match self {
            Analysis::None => "none",
            Analysis::Impact => "impact",
            Analysis::Shear => "shear",
        }
    }
}

/// The measured quantity a tolerance applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AccuracyQuantity {
    /// Realised normal restitution, absolute error.
    Restitution,
    /// Peak normal force, relative error.
    PeakForce,
    /// Largest overlap, relative error.
    MaxOverlap,
    /// Contact duration, relative error.
    ContactTime,
}

impl AccuracyQuantity {
    pub fn name(self) -> &'static str {
        match self {
            AccuracyQuantity::Restitution => "restitution error (abs)",
            AccuracyQuantity::PeakForce => "peak force error (rel)",
            AccuracyQuantity::MaxOverlap => "max overlap error (rel)",
            AccuracyQuantity::ContactTime => "contact time error (rel)",
        }
    }
}
