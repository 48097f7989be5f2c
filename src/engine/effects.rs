//! The effects a scene calls for, each on or off and why: declared by a field (friction
//! off with `model.tangential = frictionless`), or derived from the scene's values (no
//! pair of bodies that can touch has a friction coefficient above 0: no tangential
//! force, no torque, so no spin integration). The build assembles the kernel and the
//! stages from these, so an effect that is off has no stage and no branch in the contact
//! kernel whichever way it came to be off; `grainlab explain` lists them with what each
//! costs where bench-peers measured it (docs/effect-costs.json, written by
//! `scripts/bench-peers --write-docs`).

use serde::{Deserialize, Serialize};

use crate::physics::material::{Material, PairMaterial};
use crate::physics::particles::Particles;
use crate::physics::walls::Wall;
use crate::scene::{Analysis, Scene, TangentialSpec};

/// bench-peers' variant with the observers inside the packing on (its name in
/// docs/effect-costs.json).
const INSIDE_VARIANT: &str = "inside the packing on (output.contacts, a sample per 50 steps)";

/// One effect: whether it is on, and why.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Effect {
    /// What it is, e.g. `friction (tangential force)`.
    pub name: String,
    pub on: bool,
    /// `declared: FIELD = VALUE`, `derived: ...` or `always`.
    pub why: String,
    /// The variant of bench-peers' effect table that times it, if any.
    #[serde(skip)]
    pub measured_as: Option<&'static str>,
}

/// What the build needs of the effects, and the whole list for `explain`.
#[derive(Clone, Debug)]
pub struct Effects {
    /// A tangential force can arise: some pair of bodies that can touch has friction > 0
    /// and the scene does not declare the frictionless law.
    pub friction: bool,
    /// The grains' spins are integrated: friction, and `model.rotation`.
    pub rotation: bool,
    /// Contacts are damped: some pair that can touch has a restitution below 1.
    pub damping: bool,
    /// Contacts attract (DMT): some pair that can touch has a work of adhesion above 0.
    pub cohesion: bool,
    /// Rolling resistance: declared by `model.rolling`, some pair that can touch has a
    /// rolling friction above 0, and the grains spin.
    pub rolling: bool,
    pub list: Vec<Effect>,
}

/// Materials in the pairs of bodies that can touch: each free grain's against every free
/// grain's, and against every other body's (a rough wall's glued grains, a flat wall),
/// as material indices `(a, b)`.
pub(crate) fn meeting_pairs<D: crate::physics::dim::Dim>(p: &Particles<D>, walls: &[Wall<D>]) -> Vec<(usize, usize)> {
    let mut free: Vec<usize> = p.material[..p.n_free].iter().map(|&m| m as usize).collect();
    free.sort_unstable();
    free.dedup();
    let mut other: Vec<usize> = p.material[p.n_free..].iter().map(|&m| m as usize).chain(walls.iter().filter(|w| w.is_flat()).map(|w| w.material)).collect();
    other.sort_unstable();
    other.dedup();
    let mut pairs = Vec::new();
    for (k, &a) in free.iter().enumerate() {
        for &b in free[k..].iter().chain(other.iter()) {
            pairs.push((a, b));
        }
    }
    pairs
}

/// Numbers as the scene has them, `a, b` (or `a, b, c`).
fn numbers(c: &[f64]) -> String {
    c.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(", ")
}

fn pair_name(mats: &[Material], (a, b): (usize, usize)) -> String {
    let name = |m: usize| if mats[m].name.is_empty() { format!("material {m}") } else { mats[m].name.clone() };
    format!("{} on {}", name(a), name(b))
}

impl Effects {
    /// The effects of `scene`, built into grains `p` (free and glued) and `walls`.
    pub fn of<D: crate::physics::dim::Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>]) -> Effects {
        let mats = &scene.materials;
        let pairs = meeting_pairs(p, walls);
        let rule = scene.model.beta_rule();
        let mix = |&(a, b): &(usize, usize)| PairMaterial::mix_with(&mats[a], &mats[b], rule);
        let mut list = Vec::new();
        let mut push = |name: &str, on: bool, why: String, measured_as: Option<&'static str>| list.push(Effect { name: name.into(), on, why, measured_as });

        let (normal, normal_why) = match scene.model.normal {
            crate::scene::NormalLaw::Hertz => ("Hertz normal force", "always (model.normal = hertz, the default)".to_string()),
            crate::scene::NormalLaw::Hooke { characteristic_velocity } => {
                ("linear spring normal force", format!("declared: model.normal = hooke, kn = kt derived per pair at vc = {characteristic_velocity} m/s"))
            }
            crate::scene::NormalLaw::HookeStiffness { kn, kt } => ("linear spring normal force", format!("declared: model.normal = hooke_stiffness, kn = {kn} N/m, kt = {kt} N/m")),
        };
        push(normal, true, normal_why, if scene.model.normal.is_hertz() { None } else { Some("linear spring (hooke)") });
        // Friction: declared off, or derived off from the coefficients of the pairs that
        // can touch.
        let rubbing = pairs.iter().find(|q| mix(q).friction > 0.0);
        let friction = scene.model.tangential != TangentialSpec::Frictionless && rubbing.is_some();
        let form = match scene.model.tangential {
            TangentialSpec::TotalDisplacement => "total displacement (LIGGGHTS' history)",
            TangentialSpec::TotalForceCap => "total displacement, cap on the total force (LAMMPS' history)",
            TangentialSpec::TotalForceCapSpringKept => "total displacement, cap on the total force with the spring kept (Kratos' rule)",
            TangentialSpec::MindlinDeresiewicz => "Mindlin-Deresiewicz micro-slip (a bed of springs across the Hertz radius)",
            TangentialSpec::IncrementalForce => "incremental force (YADE's)",
            TangentialSpec::Frictionless => "none",
        };
        let friction_why = match (scene.model.tangential, rubbing) {
            (TangentialSpec::Frictionless, _) => "declared: model.tangential = frictionless".to_string(),
            (_, Some(&q)) => format!("declared: model.tangential, {form}; the {} pair has friction {}", pair_name(mats, q), mix(&q).friction),
            (_, None) => format!("derived: friction = 0 for every pair of bodies that can touch ({}), so no tangential force can arise", pairs.iter().map(|&q| pair_name(mats, q)).collect::<Vec<_>>().join(", ")),
        };
        let measured = match scene.model.tangential {
            TangentialSpec::IncrementalForce => "incremental force (YADE's)",
            TangentialSpec::TotalForceCap => "total force cap (LAMMPS')",
            TangentialSpec::TotalForceCapSpringKept => "total force cap, spring kept (Kratos')",
            TangentialSpec::MindlinDeresiewicz => "Mindlin-Deresiewicz micro-slip",
            _ => "frictionless (no tangential, no spin stage)",
        };
        push("friction (tangential force)", friction, friction_why, Some(measured));
        let rotation = friction && scene.model.rotation;
        let rotation_why = if !scene.model.rotation {
            "declared: model.rotation = false".to_string()
        } else if !friction {
            "derived: without friction no torque arises; spins keep their initial values (and are written)".to_string()
        } else {
            "declared: model.rotation = true (the default)".to_string()
        };
        push("rotation (spin integration, torques)", rotation, rotation_why, Some("rotation off"));
        let lossy = pairs.iter().find(|q| mix(q).restitution < 1.0);
        let tsuji = scene.model.damping.tsuji().is_some();
        let damping_why = match lossy {
            _ if scene.model.damping == crate::scene::DampingSpec::Tsuji => "declared: model.damping = tsuji (LAMMPS 20220106's fit alpha(e) sqrt(m* k); alpha(1) = 3e-4 damps e = 1 too, and the realised e is not the input e)".to_string(),
            _ if tsuji => "declared: model.damping = tsuji_sqrt2 (LAMMPS' current fit sqrt(2) alpha(e) sqrt(m* k); alpha(1) = 3e-4 damps e = 1 too; under Hertz the realised e is the input within 1.1e-3)".to_string(),
            Some(&q) if scene.model.damping == crate::scene::DampingSpec::ClampedRestitution => {
                let pm = mix(&q);
                format!("derived: the {} pair has restitution {} < 1 (declared model.damping = clamped_restitution: beta = {:.6} returns it under the clamp, against beta(e) = {:.6})", pair_name(mats, q), pm.restitution, pm.beta, crate::physics::material::beta(pm.restitution))
            }
            Some(&q) => format!("derived: the {} pair has restitution {} < 1", pair_name(mats, q), mix(&q).restitution),
            None => "derived: restitution = 1 for every pair of bodies that can touch".to_string(),
        };
        let damping = lossy.is_some() || tsuji;
        push(if tsuji { "contact damping (Tsuji, LAMMPS' fit)" } else { "contact damping" }, damping, damping_why, None);
        // Cohesion: derived from the works of adhesion of the pairs that can touch.
        let sticky = pairs.iter().find(|q| mix(q).pulloff > 0.0);
        let cohesion_why = match sticky {
            Some(&q) => format!("derived: the {} pair has work of adhesion {} J/m^2 (DMT: attraction 2 pi w R* while overlapping)", pair_name(mats, q), mix(&q).work_of_adhesion()),
            None => "derived: work_of_adhesion = 0 for every pair of bodies that can touch".to_string(),
        };
        let cohesion = sticky.is_some();
        push("cohesion (DMT)", cohesion, cohesion_why, None);
        // Rolling resistance: declared, on the pairs with a rolling friction above 0.
        let resisting = pairs.iter().find(|q| mix(q).rolling_friction > 0.0);
        let law = serde_json::to_string(&scene.model.rolling).unwrap_or_default();
        let (rolling, rolling_why) = match resisting {
            _ if scene.model.rolling.is_none() => (false, "declared: model.rolling absent (none)".to_string()),
            None => (false, format!("derived: model.rolling = {law}, but rolling_friction = 0 for every pair of bodies that can touch")),
            Some(_) if !rotation => (false, format!("derived: model.rolling = {law}, but the grains do not spin (rotation off)")),
            Some(&q) => (true, format!("declared: model.rolling = {law}; the {} pair has rolling friction {}", pair_name(mats, q), mix(&q).rolling_friction)),
        };
        push("rolling resistance", rolling, rolling_why, None);
        let clamp = scene.model.limit_force;
        push("normal force clamp (Fn >= 0)", clamp, format!("declared: model.limit_force = {clamp}"), Some("force clamp on"));
        let g = scene.gravity;
        let staged_g: Vec<String> = scene.stages.iter().enumerate().filter_map(|(k, st)| st.gravity.map(|g| format!("stages[{k}].gravity = [{}]", numbers(g.as_slice())))).collect();
        let g_why = if staged_g.is_empty() { String::new() } else { format!("; {}", staged_g.join(", ")) };
        push("gravity", scene.strongest_gravity() > 0.0, format!("declared: gravity = [{}]{g_why}", numbers(g.as_slice())), None);
        let gd = scene.model.general_damping;
        push("general damping (per grain)", gd.is_some(), gd.map_or("declared: model.general_damping absent".into(), |c| format!("declared: model.general_damping = {c}")), None);
        let wall_why = match &scene.walls {
            Some(ws) => format!("declared: walls (bottom {}, top {})", ws.bottom.surface.kind(), ws.top.surface.kind()),
            None => "declared: no walls".into(),
        };
        push("walls", scene.walls.is_some(), wall_why, Some("walls"));
        let periodic = scene.domain.periodic_x;
        push("periodic x", periodic.is_some(), periodic.map_or("declared: domain.periodic_x absent".into(), |[a, b]| format!("declared: domain.periodic_x = [{a}, {b}]")), None);
        if !scene.dimension.is_two() {
            let periodic = scene.domain.periodic_z;
            push("periodic z", periodic.is_some(), periodic.map_or("declared: domain.periodic_z absent (grains free along z)".into(), |[a, b]| format!("declared: domain.periodic_z = [{a}, {b}]")), None);
        }
        push("energy ledger", scene.output.energy, format!("declared: output.energy = {}{}", scene.output.energy, if scene.output.energy { " (the default)" } else { "" }), Some("energy balance on"));
        let impact = scene.analysis == Analysis::Impact;
        push("impact observer", impact, format!("declared: analysis = {}", scene.analysis.name()), None);
        let stresses = scene.walls.is_some();
        push("wall stresses (averaged per sample)", stresses, if stresses { "derived: the scene has walls".into() } else { "derived: no walls".into() }, None);
        let inside = scene.output.contacts;
        push(
            "packing observers (contacts, profiles)",
            inside,
            format!("declared: output.contacts = {inside}{}", if inside { "" } else { " (the default): no recording stage" }),
            Some(INSIDE_VARIANT),
        );
        let frames = scene.output.frames;
        push("ParaView frames", frames > 0, format!("declared: output.frames = {frames}"), None);
        push("watchdog (overlaps, finite state)", true, "always".into(), None);
        Effects { friction, rotation, damping, cohesion, rolling, list }
    }

    /// The list as a table: each effect on or off, why, and what it cost where
    /// bench-peers timed it: the median over the runs kept for this CPU (`cpu`), else over
    /// every run kept, said so.
    pub fn table(&self, costs: &[CostRun], cpu: &str) -> String {
        let here: Vec<&CostRun> = costs.iter().filter(|r| r.cpu == cpu).collect();
        let (runs, whose) = if here.is_empty() {
            (costs.iter().collect::<Vec<_>>(), format!("median of {} runs on other CPUs than this one", costs.len()))
        } else {
            (here.clone(), format!("median of {} runs on this CPU", here.len()))
        };
        let mut out = format!("effects (on/off, why; cost: the rate of bench-peers' 5000-grain shear cell with the effect's variant, relative to its full model, {whose})\n");
        for e in &self.list {
            let cost = e.measured_as.and_then(|v| cost(&runs, v)).map(|c| format!("; cost: {c}"));
            let cost = cost.unwrap_or_else(|| if e.on && e.why != "always" { "; cost: not measured".into() } else { String::new() });
            out += &format!("  {:<38} {:<3}  {}{cost}\n", e.name, if e.on { "on" } else { "off" }, e.why);
        }
        out
    }
}

/// What variant `v` cost over `runs` (the median), in words.
fn cost(runs: &[&CostRun], v: &str) -> Option<String> {
    let median = |mut xs: Vec<f64>| -> Option<f64> {
        if xs.is_empty() {
            return None;
        }
        xs.sort_by(f64::total_cmp);
        let m = xs.len() / 2;
        Some(if xs.len() % 2 == 1 { xs[m] } else { 0.5 * (xs[m - 1] + xs[m]) })
    };
    if v == "walls" {
        let share = median(runs.iter().filter_map(|r| r.variants.first().map(|x| x.walls_share)).collect())?;
        return Some(format!("{:.1}% of the step", 100.0 * share));
    }
    let rel = median(runs.iter().filter_map(|r| r.variants.iter().find(|x| x.variant == v).map(|x| x.relative)).collect())?;
    Some(format!("{v}: {rel:.2}x"))
}

/// One bench-peers run's effect table, as docs/effect-costs.json keeps it.
#[derive(Clone, Debug, Deserialize)]
pub struct CostRun {
    /// The CPU, with its family and model numbers.
    pub cpu: String,
    pub date: String,
    pub variants: Vec<CostVariant>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct CostVariant {
    pub variant: String,
    /// Rate relative to the full model (total displacement, energy off).
    pub relative: f64,
    /// The walls' share of the step's time.
    pub walls_share: f64,
}

/// The effect costs bench-peers measured (docs/effect-costs.json, compiled in).
pub fn cost_runs() -> Vec<CostRun> {
    serde_json::from_str(include_str!("../../docs/effect-costs.json")).unwrap_or_default()
}

/// This machine's CPU as bench-peers names it: `model name (family F model M)`.
pub fn this_cpu() -> String {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let field = |key: &str| info.lines().find_map(|l| l.split_once(':').filter(|(k, _)| k.trim() == key).map(|(_, v)| v.trim().to_string()));
    let mut cpu = field("model name").unwrap_or_else(|| "unknown CPU".into());
    if let (Some(f), Some(m)) = (field("cpu family"), field("model")) {
        cpu += &format!(" (family {f} model {m})");
    }
    cpu
}
