//! What accuracy costs: a scene run over one lever, the time step or the grains'
//! stiffness, for each model variant, one row per listed run (`grainlab sweep`).
//!
//! **References that no listed row is.** Every error is measured against a reference
//! from runs beyond the listed range, never against a listed row:
//! - the time step lever: the finest listed step is run again at dt/2 and dt/4; the order
//!   of convergence is measured from the three (`p = log2((Q(h) - Q(h/2)) / (Q(h/2) -
//!   Q(h/4)))`) and the reference is Q(h/4) extrapolated with it (Richardson). Its
//!   uncertainty is the size of that correction, combined with the runs' noise. Where the
//!   differences do not shrink, are within the noise, or give an order no integrator has
//!   ([`BELIEVED_ORDERS`]), no order is measured: the reference is Q(h/4) and its
//!   uncertainty the spread of the three runs;
//! - the stiffness lever: the stiffest listed scale s is run again at 2 s and 4 s, and
//!   the quantity is extrapolated to rigid grains, linearly in the measured overlap (the
//!   impact's largest overlap, the packing's mean overlap over radius) to zero overlap.
//!   A deterministic run ([`rigid_limit`]) extrapolates from the two stiffest, the
//!   curvature the third point (s) shows giving the uncertainty; ensembles
//!   ([`rigid_trend`]) fit every point of the lever by weighted least squares, a parabola
//!   where the data show curvature, so that the noise of two ensembles is not what is
//!   extrapolated. A quantity with no rigid limit (an impact's peak force, overlap and
//!   contact time) has no reference there.
//!
//! Where a closed form exists it is reported too: the restitution the continuous-time law
//! returns (the input without the clamp or with the clamped damping; beta(e)'s or Tsuji's
//! closed form otherwise, docs/model.md) and, for an elastic impact of two equal grains,
//! Hertz's largest overlap, peak force and contact time.
//!
//! **Costs** are the run's own clock of its time stepping (building and packing left
//! out): the median of `repeats` runs of a deterministic scene, or of the runs of an
//! ensemble, with their smallest and largest.
//!
//! **Noise.** With packing `seeds`, every point is an ensemble
//! ([`crate::study::ensemble`]) and its values are ensemble means with 95% intervals from
//! the run-to-run spread; a sheared packing is chaotic, and one run cannot show what a
//! time step or a stiffness changes in tau/sigma.

use serde::Serialize;

use crate::error::Error;
use crate::observe::impact::ImpactSummary;
use crate::physics::contact::LeverArm;
use crate::physics::material::{PairMaterial, hertz_contact_time_exact, hertz_max_overlap};
use crate::scene::limits::Limits;
use crate::scene::{Analysis, Grains, Scene, TangentialSpec, TimeStepRule};
use crate::study::ensemble::{EnsembleStat, ensemble};
use crate::study::run::{RunOptions, run_scene};

/// A model variant: the scene as given, or with one setting changed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Variant {
    Scene,
    Tangential(TangentialSpec),
    Clamp(bool),
    Lever(LeverArm),
}

impl Variant {
    pub fn label(&self) -> String {
        match self {
            Variant::Scene => "scene".into(),
            Variant::Tangential(t) => format!("tangential={}", serde_json::to_value(t).unwrap().as_str().unwrap_or("?")),
            Variant::Clamp(c) => format!("limit_force={c}"),
            Variant::Lever(l) => format!("lever_arm={}", serde_json::to_value(l).unwrap().as_str().unwrap_or("?")),
        }
    }
    fn apply(&self, s: &mut Scene) {
        match *self {
            Variant::Scene => {}
            Variant::Tangential(t) => s.model.tangential = t,
            Variant::Clamp(c) => s.model.limit_force = c,
            Variant::Lever(l) => s.model.lever_arm = l,
        }
    }
    /// The variants a family name stands for (`tangential`, `clamp`, `lever`).
    pub fn family(name: &str) -> Result<Vec<Variant>, Error> {
        Ok(match name {
            "tangential" => vec![
                Variant::Tangential(TangentialSpec::TotalDisplacement),
                Variant::Tangential(TangentialSpec::TotalForceCap),
                Variant::Tangential(TangentialSpec::IncrementalForce),
                Variant::Tangential(TangentialSpec::Frictionless),
            ],
            "clamp" => vec![Variant::Clamp(false), Variant::Clamp(true)],
            "lever" => vec![Variant::Lever(LeverArm::Radius), Variant::Lever(LeverArm::RadiusMinusHalfOverlap), Variant::Lever(LeverArm::Yade), Variant::Lever(LeverArm::ContactPoint), Variant::Lever(LeverArm::Lammps)],
            _ => {
                return Err(Error::BadOption { option: "--variants".into(), value: name.into(), allowed: "tangential, clamp, lever".into() });
            }
        })
    }
}

/// A time step setting of the sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// Steps per Hertz contact time at the scene's impact (or characteristic) speed.
    PerContact(f64),
    /// A fraction of the Rayleigh time.
    Rayleigh(f64),
    /// The scene's own rule (a stiffness sweep that lists no time step).
    Scene,
}

impl Step {
    /// The same rule at a time step `k` times smaller.
    fn finer(self, k: f64) -> Step {
        match self {
            Step::PerContact(n) => Step::PerContact(n * k),
            Step::Rayleigh(f) => Step::Rayleigh(f / k),
            Step::Scene => Step::Scene,
        }
    }
    fn label(self) -> String {
        match self {
            Step::PerContact(n) => format!("t_c/{n}"),
            Step::Rayleigh(f) => format!("{f} t_Rayleigh"),
            Step::Scene => "scene".into(),
        }
    }
}

/// The lever a sweep moves.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Lever {
    TimeStep,
    Stiffness,
}

/// What a sweep runs.
#[derive(Clone, Debug)]
pub struct SweepPlan {
    /// Time steps; none: the scene's own rule (then `stiffness` must list two or more).
    pub steps: Vec<Step>,
    /// Scales of every material's Young's modulus (1: the scene's); none: `[1]`. Two or
    /// more make stiffness the lever, with at most one time step.
    pub stiffness: Vec<f64>,
    pub variants: Vec<Variant>,
    /// Override of the scene's duration, s.
    pub duration: Option<f64>,
    /// Timed runs of each point of a deterministic scene (at least 1); the cost is their
    /// median. An ensemble's point is timed by its runs instead.
    pub repeats: usize,
    /// Packing seeds: with two or more, every point is an ensemble over them.
    pub seeds: Vec<u64>,
}

impl Default for SweepPlan {
    fn default() -> Self {
        SweepPlan { steps: Vec::new(), stiffness: Vec::new(), variants: vec![Variant::Scene], duration: None, repeats: 1, seeds: Vec::new() }
    }
}

/// Most timed runs per point.
pub const MAX_REPEATS: usize = 1000;

/// How many times finer (dt) or stiffer the two reference runs are than the listed
/// extreme: 2 and 4.
const REFERENCE_FACTORS: [f64; 2] = [2.0, 4.0];

/// One run of the sweep. A quantity that does not apply (an impact's in a shear run, an
/// error against a closed form the scene has none of, a reference the lever has none of)
/// is empty. For each quantity Q: `Q` (with seeds, the ensemble mean), `Q_ci95` (its 95%
/// half-width: the ensemble's, or one run's block interval), `Q_reference` and
/// `Q_reference_uncertainty` (the converged or rigid value and a bound on its own error),
/// `Q_err` or `Q_err_rel` (|Q - reference|, relative for the dimensional ones) and
/// `Q_order` (the measured order of convergence in dt, where one was measured).
#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    pub variant: String,
    pub lever: Lever,
    /// Scale of the Young's moduli, and the first material's modulus it gives, Pa.
    pub stiffness_scale: f64,
    pub youngs_modulus_pa: f64,
    pub rule: String,
    pub dt_s: f64,
    pub steps_per_contact: f64,
    pub steps: u64,
    /// Completed runs behind the row's values (the ensemble's size; 1 without seeds).
    pub runs: usize,
    /// Timed runs, and their median, smallest and largest wall-clock time of the time
    /// stepping, s.
    pub timings: usize,
    pub wall_time_s: f64,
    pub wall_time_min_s: f64,
    pub wall_time_max_s: f64,
    pub ns_per_particle_step: f64,
    pub energy_residual_rel: Option<f64>,
    /// The reference runs: what they are (`t_c/400, t_c/800`; `stiffness x2, x4`).
    pub reference_runs: String,
    /// Impact: largest overlap over the grains' mean radius; shear: mean overlap of the
    /// touching pairs over their mean radius at the end (with seeds, the ensemble mean).
    pub overlap_rel: Option<f64>,
    /// Shear: the stiffness number (E* / sigma)^(2/3), E* of two grains of the first
    /// material and sigma the measured normal stress.
    pub stiffness_number: Option<f64>,
    // Impacts.
    pub restitution: Option<f64>,
    pub restitution_reference: Option<f64>,
    pub restitution_reference_uncertainty: Option<f64>,
    pub restitution_err: Option<f64>,
    pub restitution_order: Option<f64>,
    pub restitution_err_input: Option<f64>,
    pub peak_force_n: Option<f64>,
    pub peak_force_reference: Option<f64>,
    pub peak_force_reference_uncertainty: Option<f64>,
    pub peak_force_err_rel: Option<f64>,
    pub peak_force_order: Option<f64>,
    pub peak_force_err_hertz_rel: Option<f64>,
    pub max_overlap_m: Option<f64>,
    pub max_overlap_reference: Option<f64>,
    pub max_overlap_reference_uncertainty: Option<f64>,
    pub max_overlap_err_rel: Option<f64>,
    pub max_overlap_order: Option<f64>,
    pub max_overlap_err_hertz_rel: Option<f64>,
    pub contact_time_s: Option<f64>,
    pub contact_time_reference: Option<f64>,
    pub contact_time_reference_uncertainty: Option<f64>,
    pub contact_time_err_rel: Option<f64>,
    pub contact_time_order: Option<f64>,
    pub contact_time_err_hertz_rel: Option<f64>,
    // Shear.
    pub stress_ratio: Option<f64>,
    pub stress_ratio_ci95: Option<f64>,
    pub stress_ratio_reference: Option<f64>,
    pub stress_ratio_reference_uncertainty: Option<f64>,
    pub stress_ratio_err: Option<f64>,
    pub stress_ratio_order: Option<f64>,
    pub packing_fraction: Option<f64>,
    pub packing_fraction_ci95: Option<f64>,
    pub packing_fraction_reference: Option<f64>,
    pub packing_fraction_reference_uncertainty: Option<f64>,
    pub packing_fraction_err: Option<f64>,
    pub packing_fraction_order: Option<f64>,
}

/// A measured value: a mean and the half-width of its 95% interval (0 for a
/// deterministic run, none where the noise is not known).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Value {
    pub mean: f64,
    pub ci95: Option<f64>,
}

impl Value {
    fn exact(mean: f64) -> Value {
        Value { mean, ci95: Some(0.0) }
    }
    fn noise(&self) -> f64 {
        self.ci95.unwrap_or(0.0)
    }
}

impl From<&EnsembleStat> for Value {
    fn from(s: &EnsembleStat) -> Value {
        Value { mean: s.mean, ci95: Some(s.ci95) }
    }
}

/// A reference value with a bound on its own error, and the measured order of
/// convergence where one was measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    pub value: f64,
    pub uncertainty: f64,
    pub order: Option<f64>,
}

/// Orders of convergence a measurement is believed in: below 1/2 the differences barely
/// shrink, above 4 (twice Verlet's order) two small differences met by chance (a wobble
/// of the contact's start between steps, or round-off).
pub const BELIEVED_ORDERS: std::ops::RangeInclusive<f64> = 0.5..=4.0;

/// Richardson extrapolation from a quantity at time steps h, h/2 and h/4. The order is
/// measured where the two differences have one sign, shrink, stand out of the noise
/// (their combined 95% half-widths), and give an order in [`BELIEVED_ORDERS`]; the
/// reference is then Q(h/4) - d2 / (2^p - 1), with d2 = Q(h/2) - Q(h/4), and its
/// uncertainty the correction combined with the noise it carries. Otherwise the
/// reference is Q(h/4), uncertain by the spread of the three (largest minus smallest)
/// and its noise: for an error c(h) h^p with p >= 1 that spread covers the error of
/// Q(h/4) as long as c wobbles by less than a factor two between the three steps (the
/// damped impact's restitution does, by the contact's phase between steps).
pub fn richardson(q1: Value, q2: Value, q4: Value) -> Reference {
    let (d1, d2) = (q1.mean - q2.mean, q2.mean - q4.mean);
    let (n1, n2) = (q1.noise().hypot(q2.noise()), q2.noise().hypot(q4.noise()));
    let order = (d1 / d2).log2();
    if d1 * d2 > 0.0 && d1.abs() > d2.abs() && d1.abs() > n1 && d2.abs() > n2 && BELIEVED_ORDERS.contains(&order) {
        let k = d1 / d2 - 1.0; // 2^p - 1
        let correction = d2 / k;
        let noise = ((1.0 + 1.0 / k) * q4.noise()).hypot(q2.noise() / k);
        return Reference { value: q4.mean - correction, uncertainty: correction.hypot(noise), order: Some(order) };
    }
    let spread = q1.mean.max(q2.mean).max(q4.mean) - q1.mean.min(q2.mean).min(q4.mean);
    Reference { value: q4.mean, uncertainty: spread.hypot(q4.noise()), order: None }
}

/// Extrapolation to rigid grains: a quantity `q` against the overlap `x` at the stiffest
/// listed scale (`s`) and at two stiffer ones (`s2`, `s4`), taken linear in the overlap
/// through the two stiffest to zero overlap. The curvature c that the third point shows
/// (its distance from that line over (x_s - x_2)(x_s - x_4)) makes the extrapolation wrong
/// by about |c| x_2 x_4: that, combined with the noise the two carry, is the uncertainty.
/// Overlaps that do not fall with the stiffness give no extrapolation: the stiffest run,
/// uncertain by its difference from the next.
pub fn rigid_limit(s: (f64, Value), s2: (f64, Value), s4: (f64, Value)) -> Reference {
    let ((xs, qs), (x2, q2), (x4, q4)) = (s, s2, s4);
    if !(xs > x2 && x2 > x4 && x4 >= 0.0) {
        return Reference { value: q4.mean, uncertainty: (q2.mean - q4.mean).abs().hypot(q4.noise()), order: None };
    }
    let slope = (q2.mean - q4.mean) / (x2 - x4);
    let value = q4.mean - slope * x4;
    let residual = qs.mean - (q4.mean + slope * (xs - x4));
    let curvature = residual / ((xs - x2) * (xs - x4));
    let (a4, a2) = (x2 / (x2 - x4), x4 / (x2 - x4));
    let noise = (a4 * q4.noise()).hypot(a2 * q2.noise());
    Reference { value, uncertainty: (curvature * x2 * x4).hypot(noise), order: None }
}

/// A polynomial of `degree` in x fitted to noisy points by weighted least squares (weights
/// 1/sigma^2): its coefficients, their standard errors, and chi^2 over the degrees of
/// freedom left (1 where none are).
fn weighted_fit(points: &[(f64, f64, f64)], degree: usize) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let (n, k) = (points.len(), degree + 1);
    if n < k {
        return None;
    }
    let x = nalgebra::DMatrix::from_fn(n, k, |i, j| points[i].0.powi(j as i32));
    let w = nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(n, points.iter().map(|p| p.2.powi(-2))));
    let y = nalgebra::DVector::from_iterator(n, points.iter().map(|p| p.1));
    let covariance = (x.transpose() * &w * &x).try_inverse()?;
    let coef = &covariance * x.transpose() * &w * &y;
    let residual = &y - &x * &coef;
    let chi2 = (residual.transpose() * &w * &residual)[(0, 0)];
    let per_dof = if n > k { chi2 / (n - k) as f64 } else { 1.0 };
    let errors = (0..k).map(|j| covariance[(j, j)].sqrt()).collect();
    coef.iter().all(|c| c.is_finite()).then(|| (coef.iter().copied().collect(), errors, per_dof))
}

/// Extrapolation to rigid grains from every point of the lever when each is an ensemble
/// mean with a 95% half-width (a chaotic packing): a straight line in the overlap through
/// all of them, fitted by weighted least squares with sigma = ci95 / 1.96 (which overstates
/// sigma for small ensembles, whose intervals use Student's t), and its intercept. Its
/// uncertainty is 1.96 standard errors, widened by sqrt(chi^2 per degree of freedom) where
/// the points scatter more than their intervals say. With four points or more a parabola
/// is fitted too: where its curvature stands out of its own noise (beyond 1.96 standard
/// errors) the line is no fit, and the parabola's intercept is taken, uncertain by its
/// standard errors and by its distance from the line's. Using every point, not the three
/// stiffest, keeps the noise of two ensembles from being amplified by the extrapolation.
pub fn rigid_trend(points: &[(f64, Value)]) -> Option<Reference> {
    let data: Vec<(f64, f64, f64)> = points.iter().map(|(x, q)| (*x, q.mean, q.noise() / 1.96)).collect();
    if data.len() < 3 || data.iter().any(|p| !(p.2 > 0.0) || !p.0.is_finite()) {
        return None;
    }
    let (line, line_err, line_chi) = weighted_fit(&data, 1)?;
    let widen = |chi: f64| chi.max(1.0).sqrt();
    if data.len() >= 4 {
        if let Some((parabola, errors, chi)) = weighted_fit(&data, 2) {
            if parabola[2].abs() > 1.96 * errors[2] * widen(chi) {
                let u = (1.96 * errors[0] * widen(chi)).hypot(parabola[0] - line[0]);
                return Some(Reference { value: parabola[0], uncertainty: u, order: None });
            }
        }
    }
    Some(Reference { value: line[0], uncertainty: 1.96 * line_err[0] * widen(line_chi), order: None })
}

/// One point of the sweep: a run, or an ensemble of runs, and what it measured.
#[derive(Clone, Debug)]
struct Point {
    scale: f64,
    step: Step,
    dt_s: f64,
    steps_per_contact: f64,
    steps: u64,
    runs: usize,
    grains: usize,
    timings: Vec<f64>,
    energy_residual_rel: Option<f64>,
    impact: Option<ImpactSummary>,
    overlap: Option<Value>,
    stress_ratio: Option<Value>,
    packing_fraction: Option<Value>,
    normal_stress_pa: Option<f64>,
}

/// The quantities a sweep measures and references.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Quantity {
    Restitution,
    PeakForce,
    MaxOverlap,
    ContactTime,
    StressRatio,
    PackingFraction,
}

impl Quantity {
    const ALL: [Quantity; 6] = [Quantity::Restitution, Quantity::PeakForce, Quantity::MaxOverlap, Quantity::ContactTime, Quantity::StressRatio, Quantity::PackingFraction];
    fn of(self, p: &Point) -> Option<Value> {
        let i = p.impact.as_ref();
        match self {
            Quantity::Restitution => i.map(|i| Value::exact(i.restitution_normal)),
            Quantity::PeakForce => i.map(|i| Value::exact(i.peak_force_n)),
            Quantity::MaxOverlap => i.map(|i| Value::exact(i.max_overlap_m)),
            Quantity::ContactTime => i.map(|i| Value::exact(i.contact_time_s)),
            Quantity::StressRatio => p.stress_ratio,
            Quantity::PackingFraction => p.packing_fraction,
        }
    }
    /// Errors relative to the reference (dimensional quantities) or absolute.
    fn relative(self) -> bool {
        matches!(self, Quantity::PeakForce | Quantity::MaxOverlap | Quantity::ContactTime)
    }
    /// Whether rigid grains have a finite value of it.
    fn has_rigid_limit(self) -> bool {
        !self.relative()
    }
}

/// Run `scene` at every point of `plan`, with the references beyond the listed range;
/// `progress` hears of every point measured (listed or reference), in a line.
pub fn sweep(scene: &Scene, plan: &SweepPlan, limits: &Limits, mut progress: impl FnMut(&str)) -> Result<Vec<SweepRow>, Error> {
    let stiffness = if plan.stiffness.is_empty() { vec![1.0] } else { plan.stiffness.clone() };
    for &s in &stiffness {
        crate::error::check_option(s.is_finite() && s > 0.0, "--stiffness", s, "scales of Young's modulus > 0")?;
    }
    crate::error::check_option((1..=MAX_REPEATS).contains(&plan.repeats), "--repeats", plan.repeats as f64, &format!("1 to {MAX_REPEATS}"))?;
    let lever = if stiffness.len() >= 2 { Lever::Stiffness } else { Lever::TimeStep };
    if let (Lever::Stiffness, crate::scene::NormalLaw::HookeStiffness { kn, .. }) = (lever, scene.model.normal) {
        return Err(Error::BadOption {
            option: "--stiffness".into(),
            value: format!("{} scales", stiffness.len()),
            allowed: format!("a scene whose stiffness follows Young's modulus (hertz, hooke): model.normal.hooke_stiffness gives kn = {kn} N/m, which the sweep's scaling of E would leave as it is"),
        });
    }
    let steps = match lever {
        Lever::TimeStep if plan.steps.is_empty() => {
            return Err(Error::BadOption { option: "--steps/--rayleigh".into(), value: "none".into(), allowed: "at least one time step, or two or more --stiffness scales".into() });
        }
        Lever::Stiffness if plan.steps.len() > 1 => {
            return Err(Error::BadOption {
                option: "--steps/--rayleigh".into(),
                value: format!("{} time steps with {} stiffness scales", plan.steps.len(), stiffness.len()),
                allowed: "one lever per sweep: several time steps, or several --stiffness scales with at most one time step".into(),
            });
        }
        Lever::Stiffness if plan.steps.is_empty() => vec![Step::Scene],
        _ => plan.steps.clone(),
    };
    if plan.seeds.len() == 1 {
        return Err(Error::BadOption { option: "--seeds".into(), value: plan.seeds[0].to_string(), allowed: "two or more seeds (an ensemble), or none".into() });
    }
    let mut out = Vec::new();
    for v in &plan.variants {
        let mut measure = |scale: f64, step: Step, role: &str| -> Result<Point, Error> {
            let p = measure(scene, *v, scale, step, plan, limits, &mut progress)?;
            let mut t = p.timings.clone();
            progress(&format!("{:<24} {role:<9} stiffness x{scale:<6} {:<14} dt = {:.3e} s, {} timed run(s), median {:.4} s", v.label(), step.label(), p.dt_s, t.len(), median(&mut t)));
            Ok(p)
        };
        let mut points = Vec::new();
        for &s in &stiffness {
            for &st in &steps {
                points.push(measure(s, st, "listed")?);
            }
        }
        // The reference runs, beyond the listed extreme.
        let (extreme, refs, reference_runs) = match lever {
            Lever::TimeStep => {
                let finest = points.iter().min_by(|a, b| a.dt_s.total_cmp(&b.dt_s)).expect("at least one step").clone();
                let refs = REFERENCE_FACTORS.iter().map(|&k| measure(finest.scale, finest.step.finer(k), "reference")).collect::<Result<Vec<_>, _>>()?;
                let names = refs.iter().map(|p| p.step.label()).collect::<Vec<_>>().join(", ");
                (finest, refs, names)
            }
            Lever::Stiffness => {
                let stiffest = points.iter().max_by(|a, b| a.scale.total_cmp(&b.scale)).expect("at least one scale").clone();
                let refs = REFERENCE_FACTORS.iter().map(|&k| measure(stiffest.scale * k, stiffest.step, "reference")).collect::<Result<Vec<_>, _>>()?;
                let names = refs.iter().map(|p| format!("stiffness x{}", p.scale)).collect::<Vec<_>>().join(", ");
                (stiffest, refs, names)
            }
        };
        let reference = |q: Quantity| -> Option<Reference> {
            let (a, b, c) = (q.of(&extreme)?, q.of(&refs[0])?, q.of(&refs[1])?);
            match lever {
                Lever::TimeStep => Some(richardson(a, b, c)),
                Lever::Stiffness if q.has_rigid_limit() => {
                    // Ensembles: the trend of every point; a deterministic run: the three stiffest.
                    let all: Option<Vec<(f64, Value)>> = points.iter().chain(&refs).map(|p| Some((p.overlap?.mean, q.of(p)?))).collect();
                    all.and_then(|all| rigid_trend(&all)).or_else(|| Some(rigid_limit((extreme.overlap?.mean, a), (refs[0].overlap?.mean, b), (refs[1].overlap?.mean, c))))
                }
                Lever::Stiffness => None,
            }
        };
        let references: Vec<Option<Reference>> = Quantity::ALL.iter().map(|&q| reference(q)).collect();
        for p in &points {
            out.push(row(scene, *v, lever, p, &references, &reference_runs));
        }
    }
    Ok(out)
}

/// The scene with a variant, a stiffness scale and a time step applied.
fn scene_at(scene: &Scene, v: Variant, scale: f64, step: Step) -> Scene {
    let mut s = scene.clone();
    v.apply(&mut s);
    for m in &mut s.materials {
        m.youngs_modulus *= scale;
    }
    s.output.frames = 0;
    let speed = match scene.time_step.rule {
        TimeStepRule::StepsPerContact { impact_speed, .. } | TimeStepRule::Accuracy { impact_speed, .. } => impact_speed,
        _ => scene.time_step.characteristic_speed.unwrap_or(1.0),
    };
    match step {
        Step::PerContact(n) => s.time_step.rule = TimeStepRule::StepsPerContact { steps: n, impact_speed: speed },
        Step::Rayleigh(f) => s.time_step.rule = TimeStepRule::RayleighFraction { fraction: f },
        Step::Scene => {}
    }
    s
}

fn median(x: &mut [f64]) -> f64 {
    x.sort_by(f64::total_cmp);
    let n = x.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

/// Run one point: `repeats` timed runs of a deterministic scene, or an ensemble (whose
/// runs `progress` hears of as they end).
fn measure(scene: &Scene, v: Variant, scale: f64, step: Step, plan: &SweepPlan, limits: &Limits, progress: &mut dyn FnMut(&str)) -> Result<Point, Error> {
    let s = scene_at(scene, v, scale, step);
    if plan.seeds.len() >= 2 {
        let e = ensemble(&s, &plan.seeds, plan.duration, 1, limits, |r| {
            let ratio = r.stress_ratio.map(|x| format!(", tau/sigma {:.4}", x.mean)).unwrap_or_default();
            progress(&format!("  seed {}: {} in {:.1} s{ratio}", r.seed, r.status, r.wall_time_s));
        })?;
        let done: Vec<_> = e.runs.iter().filter(|r| r.status == "completed").collect();
        let first = done.first().ok_or_else(|| Error::Other(format!("no run of the ensemble at stiffness x{scale}, {} completed: {}", step.label(), e.runs.iter().filter_map(|r| r.error.clone()).next().unwrap_or_default())))?;
        let sigma = e.normal_stress_pa.as_ref().map(|x| x.mean);
        return Ok(Point {
            scale,
            step,
            dt_s: first.dt_s,
            steps_per_contact: first.steps_per_contact,
            steps: first.steps,
            runs: done.len(),
            grains: first.grains,
            timings: done.iter().map(|r| r.wall_time_s).collect(),
            energy_residual_rel: {
                let r: Vec<f64> = done.iter().filter_map(|r| r.energy_residual_rel).collect();
                (r.len() == done.len()).then(|| r.iter().sum::<f64>() / r.len() as f64)
            },
            impact: None,
            overlap: e.mean_overlap_rel.as_ref().map(Value::from),
            stress_ratio: e.stress_ratio.as_ref().map(Value::from),
            packing_fraction: e.packing_fraction.as_ref().map(Value::from),
            normal_stress_pa: sigma,
        });
    }
    let mut timings = Vec::with_capacity(plan.repeats);
    let mut first = None;
    for _ in 0..plan.repeats {
        let sum = run_scene(&s, &RunOptions { duration: plan.duration, limits: *limits, ..RunOptions::default() })?;
        timings.push(sum.wall_time_s);
        first.get_or_insert(sum);
    }
    let sum = first.expect("at least one repeat");
    if s.analysis == Analysis::Impact && sum.impact.is_none() {
        return Err(Error::BadOption {
            option: "--duration".into(),
            value: format!("{:e} s", plan.duration.unwrap_or(s.duration)),
            allowed: format!("a duration in which the impact ends (it did not at stiffness x{scale}, {}; softer grains touch longer, and the run stops at separation)", step.label()),
        });
    }
    let shear = sum.shear.as_ref();
    let impact = sum.impact;
    let overlap = match (&impact, mean_radius(&s)) {
        (Some(i), Some(r)) => Some(Value::exact(i.max_overlap_m / r)),
        _ => shear.and_then(|x| x.mean_overlap_rel).map(|m| Value { mean: m, ci95: None }),
    };
    Ok(Point {
        scale,
        step,
        dt_s: sum.time_step.dt_s,
        steps_per_contact: sum.time_step.steps_per_contact,
        steps: sum.steps,
        runs: 1,
        grains: sum.grains,
        timings,
        energy_residual_rel: sum.energy.as_ref().map(|e| e.max_residual_rel),
        impact,
        overlap,
        stress_ratio: shear.and_then(|x| x.stress_ratio).map(|e| Value { mean: e.mean, ci95: Some(e.ci95).filter(|c| c.is_finite()) }),
        packing_fraction: shear.and_then(|x| x.packing_fraction).map(|m| Value { mean: m, ci95: None }),
        normal_stress_pa: shear.map(|x| x.normal_stress_pa.mean),
    })
}

/// The mean radius of a scene's listed grains (an impact's).
fn mean_radius(s: &Scene) -> Option<f64> {
    let Grains::List(g) = &s.grains else { return None };
    (!g.is_empty()).then(|| g.iter().map(|g| g.r).sum::<f64>() / g.len() as f64)
}

/// |a - b| / |b| where both are known and the quotient is finite.
fn rel(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    Some((a? - b?).abs() / b?.abs()).filter(|e| e.is_finite())
}

/// |a - b| where both are known.
fn abs_diff(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    Some((a? - b?).abs())
}

fn row(scene: &Scene, v: Variant, lever: Lever, p: &Point, references: &[Option<Reference>], reference_runs: &str) -> SweepRow {
    let mut timings = p.timings.clone();
    let wall = median(&mut timings);
    let scaled = scene_at(scene, v, p.scale, p.step);
    let value = |q: Quantity| q.of(p).map(|x| x.mean);
    let r = |q: Quantity| references[Quantity::ALL.iter().position(|&x| x == q).expect("listed")];
    let err = |q: Quantity| {
        let reference = r(q).map(|r| r.value);
        if q.relative() { rel(value(q), reference) } else { abs_diff(value(q), reference) }
    };
    let closed = (scene.analysis == Analysis::Impact).then(|| closed_form(&scaled)).flatten();
    let elastic = closed.filter(|c| c.restitution == 1.0);
    let e_star = scaled.materials.first().map(|m| PairMaterial::mix(m, m).e_star);
    SweepRow {
        variant: v.label(),
        lever,
        stiffness_scale: p.scale,
        youngs_modulus_pa: scaled.materials.first().map_or(f64::NAN, |m| m.youngs_modulus),
        rule: p.step.label(),
        dt_s: p.dt_s,
        steps_per_contact: p.steps_per_contact,
        steps: p.steps,
        runs: p.runs,
        timings: timings.len(),
        wall_time_s: wall,
        wall_time_min_s: timings.first().copied().unwrap_or(f64::NAN),
        wall_time_max_s: timings.last().copied().unwrap_or(f64::NAN),
        ns_per_particle_step: 1e9 * wall / (p.steps.max(1) as f64 * p.grains.max(1) as f64),
        energy_residual_rel: p.energy_residual_rel.filter(|x| x.is_finite()),
        reference_runs: reference_runs.into(),
        overlap_rel: p.overlap.map(|x| x.mean),
        stiffness_number: match (e_star, p.normal_stress_pa) {
            (Some(e), Some(sigma)) if sigma > 0.0 => Some((e / sigma).powf(2.0 / 3.0)),
            _ => None,
        },
        restitution: value(Quantity::Restitution),
        restitution_reference: r(Quantity::Restitution).map(|r| r.value),
        restitution_reference_uncertainty: r(Quantity::Restitution).map(|r| r.uncertainty),
        restitution_err: err(Quantity::Restitution),
        restitution_order: r(Quantity::Restitution).and_then(|r| r.order),
        restitution_err_input: closed.and_then(|c| abs_diff(value(Quantity::Restitution), Some(c.restitution))),
        peak_force_n: value(Quantity::PeakForce),
        peak_force_reference: r(Quantity::PeakForce).map(|r| r.value),
        peak_force_reference_uncertainty: r(Quantity::PeakForce).map(|r| r.uncertainty),
        peak_force_err_rel: err(Quantity::PeakForce),
        peak_force_order: r(Quantity::PeakForce).and_then(|r| r.order),
        peak_force_err_hertz_rel: elastic.and_then(|c| rel(value(Quantity::PeakForce), Some(c.peak_force))),
        max_overlap_m: value(Quantity::MaxOverlap),
        max_overlap_reference: r(Quantity::MaxOverlap).map(|r| r.value),
        max_overlap_reference_uncertainty: r(Quantity::MaxOverlap).map(|r| r.uncertainty),
        max_overlap_err_rel: err(Quantity::MaxOverlap),
        max_overlap_order: r(Quantity::MaxOverlap).and_then(|r| r.order),
        max_overlap_err_hertz_rel: elastic.and_then(|c| rel(value(Quantity::MaxOverlap), Some(c.max_overlap))),
        contact_time_s: value(Quantity::ContactTime),
        contact_time_reference: r(Quantity::ContactTime).map(|r| r.value),
        contact_time_reference_uncertainty: r(Quantity::ContactTime).map(|r| r.uncertainty),
        contact_time_err_rel: err(Quantity::ContactTime),
        contact_time_order: r(Quantity::ContactTime).and_then(|r| r.order),
        contact_time_err_hertz_rel: elastic.and_then(|c| rel(value(Quantity::ContactTime), Some(c.contact_time))),
        stress_ratio: value(Quantity::StressRatio),
        stress_ratio_ci95: p.stress_ratio.and_then(|x| x.ci95),
        stress_ratio_reference: r(Quantity::StressRatio).map(|r| r.value),
        stress_ratio_reference_uncertainty: r(Quantity::StressRatio).map(|r| r.uncertainty),
        stress_ratio_err: err(Quantity::StressRatio),
        stress_ratio_order: r(Quantity::StressRatio).and_then(|r| r.order),
        packing_fraction: value(Quantity::PackingFraction),
        packing_fraction_ci95: p.packing_fraction.and_then(|x| x.ci95),
        packing_fraction_reference: r(Quantity::PackingFraction).map(|r| r.value),
        packing_fraction_reference_uncertainty: r(Quantity::PackingFraction).map(|r| r.uncertainty),
        packing_fraction_err: err(Quantity::PackingFraction),
        packing_fraction_order: r(Quantity::PackingFraction).and_then(|r| r.order),
    }
}

#[derive(Clone, Copy)]
struct Closed {
    restitution: f64,
    max_overlap: f64,
    peak_force: f64,
    contact_time: f64,
}

/// Closed-form values for a two-grain head-on impact of equal sphere-in-plane grains.
fn closed_form(s: &Scene) -> Option<Closed> {
    let Grains::List(g) = &s.grains else { return None };
    // Hertz's closed forms (the linear spring's are in tests/hooke.rs).
    if !s.model.normal.is_hertz() || g.len() != 2 || g[0].r != g[1].r || g[0].material != g[1].material || s.walls.is_some() {
        return None;
    }
    let m = &s.materials[g[0].material];
    let v = ((g[0].v[0] - g[1].v[0]).powi(2) + (g[0].v[1] - g[1].v[1]).powi(2)).sqrt();
    let (r, mass) = (g[0].r, s.grain_shape.mass(g[0].r, m.density));
    let e = PairMaterial::mix(m, m).e_star;
    let (ms, rs) = (mass / 2.0, r / 2.0);
    let d = hertz_max_overlap(ms, rs, e, v);
    // The restitution the continuous-time law returns (docs/model.md): the input, except
    // with the clamp (beta(e) then returns more) or Tsuji's fit, both in closed form.
    use crate::physics::restitution::{clamped_restitution, restitution_of_beta};
    use crate::scene::DampingSpec;
    let b = match s.model.damping.tsuji() {
        Some(factor) => crate::physics::contact::damping::tsuji_alpha(m.restitution) * factor / 5f64.sqrt(),
        None => s.model.beta_rule().beta(m.restitution).abs(),
    };
    let restitution = match (s.model.limit_force, s.model.damping) {
        // exp(-pi b / sqrt(1 - b^2)); b >= 1 never parts.
        (false, DampingSpec::Tsuji | DampingSpec::TsujiSqrt2) => restitution_of_beta(-b).unwrap_or(0.0),
        (false, _) => m.restitution,
        (true, DampingSpec::ClampedRestitution) => m.restitution,
        (true, _) => clamped_restitution(b),
    };
    Some(Closed {
        restitution,
        max_overlap: d,
        peak_force: 4.0 / 3.0 * e * rs.sqrt() * d.powf(1.5),
        contact_time: hertz_contact_time_exact(ms, rs, e, v),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn richardson_recovers_a_known_limit_and_order() {
        // Q(h) = 3 + 0.5 h^2 at h = 1, 1/2, 1/4: the limit 3 and the order 2 exactly.
        let q = |h: f64| Value::exact(3.0 + 0.5 * h * h);
        let r = richardson(q(1.0), q(0.5), q(0.25));
        assert!((r.value - 3.0).abs() < 1e-15 && (r.order.unwrap() - 2.0).abs() < 1e-12, "{r:?}");
        // Differences within the noise: no order, the finest value, the spread of the three.
        let n = |x: f64| Value { mean: x, ci95: Some(0.1) };
        let r = richardson(n(0.30), n(0.28), n(0.29));
        assert_eq!((r.value, r.order), (0.29, None));
        assert!((r.uncertainty - (0.02f64).hypot(0.1)).abs() < 1e-12);
        // An error c(h) h whose c wobbles (1.0, 1.6, 1.9): the differences do not shrink,
        // no order; the spread still covers the finest run's error.
        let r = richardson(Value::exact(1.0 * 1.0), Value::exact(1.6 * 0.5), Value::exact(1.9 * 0.25));
        assert_eq!(r.order, None);
        assert!(r.value.abs() <= r.uncertainty, "{r:?}");
        // Differences that shrink 130-fold are no power law: no order of 7 believed.
        let r = richardson(Value::exact(1.0 + 1.3e-8), Value::exact(1.0 + 1e-10), Value::exact(1.0));
        assert_eq!(r.order, None);
        assert!((r.uncertainty / 1.3e-8 - 1.0).abs() < 1e-6, "{r:?}");
    }

    #[test]
    fn the_rigid_trend_of_noisy_points_covers_the_true_intercept() {
        // Q = 0.25 + 3 x with deterministic "noise" of +-ci/2 alternating: the line's
        // intercept within its stated uncertainty, and that uncertainty well below one
        // point's interval (seven points, not two, carry the extrapolation).
        let xs = [0.012, 0.006, 0.003, 0.0014, 0.0006, 0.0004, 0.00025];
        let pts: Vec<(f64, Value)> = xs.iter().enumerate().map(|(i, &x)| (x, Value { mean: 0.25 + 3.0 * x + if i % 2 == 0 { 0.0025 } else { -0.0025 }, ci95: Some(0.005) })).collect();
        let r = rigid_trend(&pts).unwrap();
        assert!((r.value - 0.25).abs() <= r.uncertainty && r.uncertainty < 0.005, "{r:?}");
        // A strong curvature (Q = 0.25 + 3 x - 400 x^2, noise 1e-4): the parabola, whose
        // intercept covers the truth where the line's would miss it.
        let pts: Vec<(f64, Value)> = xs.iter().map(|&x| (x, Value { mean: 0.25 + 3.0 * x - 400.0 * x * x, ci95: Some(1e-4) })).collect();
        let r = rigid_trend(&pts).unwrap();
        assert!((r.value - 0.25).abs() <= r.uncertainty, "{r:?}");
        // Exact points (a deterministic run) are no trend to fit: the three-point rule.
        assert!(rigid_trend(&[(0.1, Value::exact(1.0)), (0.05, Value::exact(1.0)), (0.02, Value::exact(1.0))]).is_none());
    }

    #[test]
    fn the_rigid_limit_of_a_linear_trend_is_its_intercept() {
        // Q = 0.6 + 2 x exactly: the intercept, with no curvature to make it uncertain.
        let p = |x: f64| (x, Value::exact(0.6 + 2.0 * x));
        let r = rigid_limit(p(0.04), p(0.02), p(0.01));
        assert!((r.value - 0.6).abs() < 1e-14 && r.uncertainty < 1e-13, "{r:?}");
        // Q = 0.6 + 2 x + 30 x^2: the uncertainty covers the true error (30 x2 x4).
        let p = |x: f64| (x, Value::exact(0.6 + 2.0 * x + 30.0 * x * x));
        let r = rigid_limit(p(0.04), p(0.02), p(0.01));
        assert!((r.value - 0.6).abs() <= r.uncertainty * (1.0 + 1e-9), "{r:?}");
    }
}
