//! The scene file (JSON): what is simulated, how, and what is written.
//!
//! Every field, its unit and its default are listed in docs/scene.md. A scene is
//! validated as a whole before anything is built or written; an error names the field,
//! the value and the allowed range.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::contact::LeverArm;
use crate::dim::GrainShape;
use crate::error::{Error, check};
use crate::limits::{MAX_FRAMES, MAX_MATERIALS};
use crate::material::Material;
use crate::pack::RadiusDist;

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
    /// Gravity, m/s^2. Default [0, 0] (off: no stage).
    #[serde(default)]
    pub gravity: [f64; 2],
    #[serde(default)]
    pub model: ModelSpec,
    pub time_step: TimeStepSpec,
    /// Simulated time, s.
    pub duration: f64,
    #[serde(default)]
    pub neighbor: NeighborSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// What the summary reports. Default: none.
    #[serde(default)]
    pub analysis: Analysis,
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
    /// Centre x, y, z and radius, m; z is read and ignored (a LAMMPS-style 3D file of a
    /// monolayer).
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
    /// Centre, m.
    pub x: [f64; 2],
    /// Velocity, m/s. Default [0, 0].
    #[serde(default)]
    pub v: [f64; 2],
    /// Spin about z, rad/s. Default 0.
    #[serde(default)]
    pub omega: f64,
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
    /// Lower edge of the packing region, m. Default: on the bottom wall.
    #[serde(default)]
    pub y_min: Option<f64>,
    /// Area fraction the region is sized for (its height follows), in (0, 0.8].
    /// Default 0.75 (denser random packings do not relax free of overlaps).
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
    /// Default: the disk thickness, or the mean grain diameter for spheres in the plane.
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
    /// YADE `Law2_ScGeom_MindlinPhys_Mindlin`.
    IncrementalForce,
    /// No tangential force (and no spin).
    Frictionless,
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    #[serde(default)]
    pub tangential: TangentialSpec,
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

impl Default for ModelSpec {
    fn default() -> Self {
        ModelSpec { tangential: TangentialSpec::default(), limit_force: false, lever_arm: LeverArm::default(), rotation: true, general_damping: None }
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
    /// see [`crate::accuracy`].
    Accuracy { quantity: crate::accuracy::AccuracyQuantity, tolerance: f64, impact_speed: f64 },
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
}

fn default_samples() -> u64 {
    200
}
fn default_frames() -> u64 {
    20
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec { samples: default_samples(), frames: default_frames(), energy: true }
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
    /// Wall stresses with confidence intervals over the second half of the run.
    Shear,
}

fn finite_pos(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

impl Scene {
    /// Parse and validate a scene. A parse error names the JSON path of the field it is
    /// in (`grains.list[1].r: invalid type: string "a", expected f64 at line 9 column 14`).
    pub fn from_json(text: &str) -> Result<Scene, Error> {
        let mut de = serde_json::Deserializer::from_str(text);
        let s: Scene = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let mut what = inner.to_string();
            // serde_json reports an array with more elements than a fixed-size field takes
            // (`"gravity": [0, -9.81, 0]`) as trailing characters: say what it is.
            if what.starts_with("trailing characters") && path != "." {
                what = what.replacen("trailing characters", "more elements than the field takes", 1);
            }
            Error::Parse { path, what }
        })?;
        de.end().map_err(|e| Error::Parse { path: ".".into(), what: format!("{e} (after the scene object)") })?;
        s.validate()?;
        Ok(s)
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a scene always serialises")
    }

    /// Check every field on its own and against the others, before anything is built;
    /// the first error names the field (its JSON path), the value and what is allowed.
    /// What depends on the grains themselves (a file's grains, a packing's radii, the
    /// time step) is checked by the build once it has them, still before the engine is
    /// allocated ([`crate::build`]).
    pub fn validate(&self) -> Result<(), Error> {
        let nmat = self.materials.len();
        check((1..=MAX_MATERIALS).contains(&nmat), "", "materials", format!("{nmat} materials"), &format!("1 to {MAX_MATERIALS} materials"))?;
        for (k, m) in self.materials.iter().enumerate() {
            m.validate(&format!("materials[{k}]"))?;
        }
        let mat_ok = |k: usize| k < nmat;
        let mats = format!("0..{}", nmat - 1);
        if let GrainShape::Disk { thickness } = self.grain_shape {
            check(finite_pos(thickness), "grain_shape.disk", "thickness", thickness, "> 0 m")?;
        }
        if let Some([a, b]) = self.domain.periodic_x {
            check(a.is_finite() && b.is_finite() && finite_pos(b - a), "domain", "periodic_x", format!("[{a}, {b}]"), "finite x_min < x_max")?;
        }
        match &self.grains {
            Grains::List(list) => {
                check(!list.is_empty(), "grains", "list", "[]", "at least one grain")?;
                for (k, g) in list.iter().enumerate() {
                    let at = format!("grains.list[{k}]");
                    check(finite_pos(g.r), &at, "r", g.r, "> 0 m")?;
                    check(g.x.iter().all(|v| v.is_finite()), &at, "x", format!("{:?}", g.x), "finite m")?;
                    check(g.v.iter().all(|v| v.is_finite()), &at, "v", format!("{:?}", g.v), "finite m/s")?;
                    check(g.omega.is_finite(), &at, "omega", g.omega, "finite rad/s")?;
                    check(mat_ok(g.material), &at, "material", g.material, &mats)?;
                }
            }
            Grains::File { path, material, .. } => {
                check(!path.is_empty(), "grains.file", "path", "\"\"", "a file name")?;
                check(mat_ok(*material), "grains.file", "material", material, &mats)?;
            }
            Grains::Pack(p) => {
                check(p.count >= 1, "grains.pack", "count", p.count, ">= 1")?;
                p.radius.validate("grains.pack.radius")?;
                check(mat_ok(p.material), "grains.pack", "material", p.material, &mats)?;
                check(p.x.iter().all(|v| v.is_finite()) && finite_pos(p.x[1] - p.x[0]), "grains.pack", "x", format!("{:?}", p.x), "finite x_min < x_max")?;
                if let Some(y) = p.y_min {
                    check(y.is_finite(), "grains.pack", "y_min", y, "finite m")?;
                }
                check(p.packing_fraction > 0.0 && p.packing_fraction <= 0.8, "grains.pack", "packing_fraction", p.packing_fraction, "(0, 0.8]")?;
                check(p.y_min.is_some() || self.walls.is_some(), "grains.pack", "y_min", "none", "a value, or walls to stand on")?;
                if let Some([a, b]) = self.domain.periodic_x {
                    // The packing is periodic over the cell when its region is the cell;
                    // a region inside the cell is packed with walls at its ends; one that
                    // reaches out of it would overlap its own image.
                    check(p.x[0] >= a && p.x[1] <= b, "grains.pack", "x", format!("{:?}", p.x), &format!("inside the periodic cell [{a}, {b}] m"))?;
                }
            }
        }
        if let Some(w) = &self.walls {
            for (name, s) in [("bottom", &w.bottom), ("top", &w.top)] {
                let at = format!("walls.{name}");
                if let Some(y) = s.y {
                    check(y.is_finite(), &at, "y", y, "finite m")?;
                }
                check(s.velocity_x.is_finite(), &at, "velocity_x", s.velocity_x, "finite m/s")?;
                check(mat_ok(s.material), &at, "material", s.material, &mats)?;
                if let SurfaceSpec::Rough { radius } = s.surface {
                    check(finite_pos(radius), &format!("{at}.surface.rough"), "radius", radius, "> 0 m")?;
                    if let Some([a, b]) = self.domain.periodic_x {
                        check(2.0 * radius <= b - a, &format!("{at}.surface.rough"), "radius", radius, &format!("<= {} m, half the periodic cell's length (one glued grain must fit in it)", 0.5 * (b - a)))?;
                    }
                }
                if let ControlSpec::Pressure(p) = s.control {
                    check(name == "top", &at, "control", "pressure", "fixed (only the top wall carries a load)")?;
                    check(finite_pos(p), &at, "control.pressure", p, "> 0 Pa")?;
                }
                if let Some(m) = s.mass {
                    check(finite_pos(m), &at, "mass", m, "> 0 kg")?;
                }
            }
            let bottom_y = w.bottom.y;
            check(bottom_y.is_some(), "walls.bottom", "y", "none", "a position in m")?;
            if let (Some(b), Some(t)) = (bottom_y, w.top.y) {
                // The contact surfaces: the plane of a flat wall, the far side of a rough
                // wall's glued grains.
                let (bs, ts) = (b + w.bottom.surface.radius(), t - w.top.surface.radius());
                check(ts > bs, "walls.top", "y", t, &format!("a top wall above the bottom wall: its surface (now {ts} m) above the bottom wall's (at {bs} m)"))?;
            }
            if let (Grains::Pack(_), Some(y0), Some(b)) = (&self.grains, self.grains_floor(), bottom_y) {
                let bs = b + w.bottom.surface.radius();
                check(y0 >= bs, "grains.pack", "y_min", y0, &format!(">= {bs} m, the bottom wall's surface (or omit it to stand on the wall)"))?;
            }
            if let Some(t) = w.thickness {
                check(finite_pos(t), "walls", "thickness", t, "> 0 m")?;
            }
        }
        check(self.gravity.iter().all(|g| g.is_finite()), "", "gravity", format!("{:?}", self.gravity), "finite m/s^2")?;
        match self.time_step.rule {
            TimeStepRule::Fixed { dt } => check(finite_pos(dt), "time_step.rule.fixed", "dt", dt, "> 0 s")?,
            TimeStepRule::StepsPerContact { steps, impact_speed } => {
                check(steps.is_finite() && steps >= 1.0, "time_step.rule.steps_per_contact", "steps", steps, ">= 1")?;
                check(finite_pos(impact_speed), "time_step.rule.steps_per_contact", "impact_speed", impact_speed, "> 0 m/s")?;
            }
            TimeStepRule::RayleighFraction { fraction } => {
                check(fraction > 0.0 && fraction <= 1.0, "time_step.rule.rayleigh_fraction", "fraction", fraction, "(0, 1]")?
            }
            TimeStepRule::SeedRule { factor, reference_overlap } => {
                check(factor > 0.0 && factor <= 1.0, "time_step.rule.seed_rule", "factor", factor, "(0, 1]")?;
                check(reference_overlap > 0.0 && reference_overlap < 1.0, "time_step.rule.seed_rule", "reference_overlap", reference_overlap, "(0, 1) of the smallest radius")?;
            }
            TimeStepRule::Accuracy { tolerance, impact_speed, .. } => {
                check(tolerance.is_finite() && tolerance > 0.0, "time_step.rule.accuracy", "tolerance", tolerance, "> 0")?;
                check(finite_pos(impact_speed), "time_step.rule.accuracy", "impact_speed", impact_speed, "> 0 m/s")?;
            }
        }
        if let Some(c) = self.model.general_damping {
            check(finite_pos(c), "model", "general_damping", c, "> 0 1/s (omit it for none)")?;
        }
        if let Some(v) = self.time_step.characteristic_speed {
            check(finite_pos(v), "time_step", "characteristic_speed", v, "> 0 m/s")?;
        }
        check(finite_pos(self.duration), "", "duration", self.duration, "> 0 s")?;
        check(finite_pos(self.neighbor.skin) && self.neighbor.skin <= 2.0, "neighbor", "skin", self.neighbor.skin, "(0, 2] smallest diameters")?;
        check(self.output.samples >= 1, "output", "samples", self.output.samples, ">= 1")?;
        check(self.output.frames <= MAX_FRAMES, "output", "frames", self.output.frames, &format!("0 to {MAX_FRAMES} (each frame rewrites the .pvd index and the manifest)"))?;
        if self.analysis == Analysis::Shear {
            check(self.walls.is_some() && self.domain.periodic_x.is_some(), "", "analysis", "shear", "a scene with walls and periodic_x")?;
        }
        Ok(())
    }

    /// The lower edge of a packing's region: its `y_min`, else the bottom wall's surface.
    pub fn grains_floor(&self) -> Option<f64> {
        match &self.grains {
            Grains::Pack(p) => p.y_min.or_else(|| self.walls.as_ref().and_then(|w| w.bottom.y.map(|y| y + w.bottom.surface.radius()))),
            _ => None,
        }
    }
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
}
