//! Reading a scene and validating it as a whole: a parse error names the JSON path of
//! the field it is in, a refusal names the field, its value and what is allowed. Nothing
//! is built or written before a scene has passed.

use crate::error::{Error, check};
use crate::physics::dim::GrainShape;
use crate::scene::limits::{MAX_FRAMES, MAX_MATERIALS, MAX_STAGES};
use crate::scene::spec::*;

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
        let mut s = s;
        // A protocol's duration left out is its stages' sum.
        if !s.stages.is_empty() && s.duration == 0.0 {
            s.duration = s.stages.iter().map(|st| st.duration).sum();
        }
        s.validate()?;
        Ok(s)
    }

    /// What the scene's dimension allows: in 2D no third component anywhere; in 3D
    /// spheres, and what space does not have yet refused by name (each says so).
    fn validate_dimension(&self) -> Result<(), Error> {
        let vectors = || {
            let mut v: Vec<(String, String, usize)> = Vec::new();
            if let Grains::List(list) = &self.grains {
                for (k, g) in list.iter().enumerate() {
                    v.push((format!("grains.list[{k}]"), "x".into(), g.x.len()));
                    v.push((format!("grains.list[{k}]"), "v".into(), g.v.len()));
                    v.push((format!("grains.list[{k}]"), "omega".into(), if g.omega.is_vector() { 3 } else { 2 }));
                }
            }
            v.push((String::new(), "gravity".into(), self.gravity.len()));
            for (k, st) in self.stages.iter().enumerate() {
                if let Some(g) = st.gravity {
                    v.push((format!("stages[{k}]"), "gravity".into(), g.len()));
                }
            }
            v
        };
        let not_yet = |at: &str, field: &str, value: &dyn std::fmt::Display, allowed: &str| check(false, at, field, value.to_string(), &format!("{allowed} in a 3D scene (\"dimension\": 3): space does not have it yet"));
        match self.dimension {
            Dimension::Two => {
                for (at, field, n) in vectors() {
                    let what = if field == "omega" { "a number (the spin about z) in a 2D scene: three components need \"dimension\": 3" } else { "2 numbers [x, y] in a 2D scene: three need \"dimension\": 3" };
                    check(n <= 2, &at, &field, "3 numbers", what)?;
                }
                if let Some([a, b]) = self.domain.periodic_z {
                    check(false, "domain", "periodic_z", format!("[{a}, {b}]"), "absent in a 2D scene: a periodic z needs \"dimension\": 3")?;
                }
                if let Grains::Pack(PackSpec { z: Some([a, b]), .. }) = &self.grains {
                    check(false, "grains.pack", "z", format!("[{a}, {b}]"), "absent in a 2D scene: a z range needs \"dimension\": 3")?;
                }
            }
            Dimension::Three => {
                if let GrainShape::Disk { thickness } = self.grain_shape {
                    check(false, "grain_shape", "disk", format!("{{\"thickness\": {thickness}}}"), "spheres (the default grain_shape) in a 3D scene: a disk is a plane grain")?;
                }
                if let Some([a, b]) = self.domain.periodic_z {
                    check(a.is_finite() && b.is_finite() && finite_pos(b - a), "domain", "periodic_z", format!("[{a}, {b}]"), "finite z_min < z_max")?;
                }
                match &self.grains {
                    Grains::File { columns, .. } => check(*columns == GrainColumns::XYZR, "grains.file", "columns", format!("\"{}\"", columns.name()), "\"x y z r\" in a 3D scene (each sphere's centre needs its z)")?,
                    Grains::Pack(p) => {
                        let Some([a, b]) = p.z else { return check(false, "grains.pack", "z", "none", "[z_min, z_max] of the packing region in a 3D scene, m") };
                        check(a.is_finite() && b.is_finite() && finite_pos(b - a), "grains.pack", "z", format!("[{a}, {b}]"), "finite z_min < z_max")?;
                        if let Some([za, zb]) = self.domain.periodic_z {
                            check(a >= za && b <= zb, "grains.pack", "z", format!("[{a}, {b}]"), &format!("inside the periodic cell [{za}, {zb}] m along z"))?;
                        }
                        check(p.packing_fraction <= 0.6, "grains.pack", "packing_fraction", p.packing_fraction, "a volume fraction in (0, 0.6] in a 3D scene (random close packing of spheres is about 0.64; the default 0.75 is the plane's area fraction: give one, 0.5 relaxes quickly)")?;
                    }
                    Grains::List(_) => {}
                }
                if !self.model.rolling.is_none() {
                    not_yet("model", "rolling", &serde_json::to_string(&self.model.rolling).unwrap_or_default(), "\"none\" (rolling resistance is the plane's)")?;
                }
                if self.model.tangential == TangentialSpec::MindlinDeresiewicz {
                    not_yet("model", "tangential", &"\"mindlin_deresiewicz\"", "another formulation (micro-slip is the plane's)")?;
                }
                if self.output.contacts {
                    not_yet("output", "contacts", &true, "false (the contact record and the packing observers are the plane's)")?;
                }
                if let Some(t) = self.walls.as_ref().and_then(|w| w.thickness) {
                    check(false, "walls", "thickness", t, "absent in a 3D scene: the walls' area is the cell's x length times its z length")?;
                }
            }
        }
        Ok(())
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a scene always serialises")
    }

    /// Check every field on its own and against the others, before anything is built;
    /// the first error names the field (its JSON path), the value and what is allowed.
    /// What depends on the grains themselves (a file's grains, a packing's radii, the
    /// time step) is checked by the build once it has them, still before the engine is
    /// allocated ([`crate::engine::build`]).
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
        self.validate_dimension()?;
        match &self.grains {
            Grains::List(list) => {
                check(!list.is_empty(), "grains", "list", "[]", "at least one grain")?;
                for (k, g) in list.iter().enumerate() {
                    let at = format!("grains.list[{k}]");
                    check(finite_pos(g.r), &at, "r", g.r, "> 0 m")?;
                    check(g.x.iter().all(|v| v.is_finite()), &at, "x", format!("{:?}", g.x), "finite m")?;
                    check(g.v.iter().all(|v| v.is_finite()), &at, "v", format!("{:?}", g.v), "finite m/s")?;
                    check(g.omega.iter().all(|w| w.is_finite()), &at, "omega", g.omega.to_string(), "finite rad/s")?;
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
                check(s.velocity_y.is_finite(), &at, "velocity_y", s.velocity_y, "finite m/s")?;
                check(s.velocity_y == 0.0 || s.control == ControlSpec::Fixed, &at, "velocity_y", s.velocity_y, "0 under pressure control (the load moves the wall in y)")?;
                check(mat_ok(s.material), &at, "material", s.material, &mats)?;
                if let SurfaceSpec::Rough { radius } = s.surface {
                    check(finite_pos(radius), &format!("{at}.surface.rough"), "radius", radius, "> 0 m")?;
                    if let Some([a, b]) = self.domain.periodic_x {
                        check(2.0 * radius <= b - a, &format!("{at}.surface.rough"), "radius", radius, &format!("<= {} m, half the periodic cell's length (one glued grain must fit in it)", 0.5 * (b - a)))?;
                    }
                    if let Some([a, b]) = self.domain.periodic_z {
                        check(2.0 * radius <= b - a, &format!("{at}.surface.rough"), "radius", radius, &format!("<= {} m, half the periodic cell's length along z (one glued grain must fit in it)", 0.5 * (b - a)))?;
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
        match self.model.normal {
            crate::scene::NormalLaw::Hertz => {}
            crate::scene::NormalLaw::Hooke { characteristic_velocity: v } => {
                check(finite_pos(v), "model.normal.hooke", "characteristic_velocity", v, "> 0 m/s")?;
            }
            crate::scene::NormalLaw::HookeStiffness { kn, kt } => {
                check(finite_pos(kn), "model.normal.hooke_stiffness", "kn", kn, "> 0 N/m")?;
                check(finite_pos(kt), "model.normal.hooke_stiffness", "kt", kt, "> 0 N/m")?;
            }
        }
        let tsuji = self.model.damping.tsuji().is_some();
        // Micro-slip's bed of springs spans the Hertz contact radius (kt = 8 G* a).
        if self.model.tangential == TangentialSpec::MindlinDeresiewicz && !self.model.normal.is_hertz() {
            check(false, "model", "tangential", "\"mindlin_deresiewicz\"", &format!("another formulation with a linear spring (micro-slip spreads over the Hertz contact radius, kt = 8 G* a; compiled: {})", crate::physics::contact::model::COMPILED))?;
        }
        // The clamped restitution damping returns e under the clamp, which it needs, and
        // has no finite damping for e = 0.
        if self.model.damping == DampingSpec::ClampedRestitution {
            check(self.model.limit_force, "model", "damping", "\"clamped_restitution\"", "\"restitution\" with model.limit_force = false (the clamped damping returns e only under the clamp Fn >= 0: set limit_force true)")?;
            if let Some(k) = self.materials.iter().position(|m| m.restitution == 0.0) {
                check(false, &format!("materials[{k}]"), "restitution", 0.0, "(0, 1] with model.damping = clamped_restitution (under the clamp e -> 0 needs infinite damping; without the clamp, the default damping's e = 0 keeps the grains together)")?;
            }
        }
        if tsuji && matches!(self.model.tangential, TangentialSpec::IncrementalForce | TangentialSpec::TotalForceCapSpringKept | TangentialSpec::MindlinDeresiewicz) {
            check(false, "model", "damping", self.model.damping.name(), &format!("\"restitution\" with model.tangential = {} (compiled: {})", self.model.tangential.name(), crate::physics::contact::model::COMPILED))?;
        }
        // DMT cohesion is compiled with the restitution damping, frictionless or with the
        // total displacement, and without the clamp (which would remove the attraction).
        if let Some((k, m)) = self.adhesive_material() {
            let w = m.work_of_adhesion;
            let at = format!("materials[{k}]");
            let compiled = crate::physics::contact::model::COMPILED;
            check(matches!(self.model.tangential, TangentialSpec::TotalDisplacement | TangentialSpec::Frictionless), &at, "work_of_adhesion", w, &format!("0 with model.tangential = {} (compiled: {compiled})", self.model.tangential.name()))?;
            check(!tsuji, &at, "work_of_adhesion", w, &format!("0 with model.damping = tsuji (compiled: {compiled})"))?;
            check(!self.model.limit_force, &at, "work_of_adhesion", w, "0 with model.limit_force = true (the clamp Fn >= 0 would remove the attraction; LAMMPS refuses limit_damping with dmt too)")?;
        }
        // Rolling resistance is compiled with the restitution damping, the total
        // displacement and spins, without cohesion.
        if !self.model.rolling.is_none() {
            let compiled = crate::physics::contact::model::COMPILED;
            let name = serde_json::to_string(&self.model.rolling).unwrap_or_default();
            check(self.model.tangential == TangentialSpec::TotalDisplacement, "model", "rolling", &name, &format!("\"none\" with model.tangential other than total_displacement (compiled: {compiled})"))?;
            check(!tsuji, "model", "rolling", &name, &format!("\"none\" with model.damping = tsuji (compiled: {compiled})"))?;
            check(self.model.rotation, "model", "rolling", &name, "\"none\" with model.rotation = false (a rolling torque acts on spins)")?;
            check(self.adhesive_material().is_none(), "model", "rolling", &name, &format!("\"none\" with a work_of_adhesion above 0 (compiled: {compiled})"))?;
            if let crate::scene::RollingSpec::Sds { stiffness, damping } = self.model.rolling {
                check(finite_pos(stiffness), "model.rolling.sds", "stiffness", stiffness, "> 0 N/m")?;
                check(damping.is_finite() && damping >= 0.0, "model.rolling.sds", "damping", damping, ">= 0 kg/s")?;
            }
        }
        if let Some(c) = self.model.general_damping {
            check(finite_pos(c), "model", "general_damping", c, "> 0 1/s (omit it for none)")?;
        }
        if let Some(v) = self.time_step.characteristic_speed {
            check(finite_pos(v), "time_step", "characteristic_speed", v, "> 0 m/s")?;
        }
        check(finite_pos(self.duration), "", "duration", self.duration, if self.stages.is_empty() { "> 0 s (required without stages)" } else { "> 0 s" })?;
        check(finite_pos(self.neighbor.skin) && self.neighbor.skin <= 2.0, "neighbor", "skin", self.neighbor.skin, "(0, 2] smallest diameters")?;
        check(self.output.samples >= 1, "output", "samples", self.output.samples, ">= 1")?;
        let st = &self.statistics;
        check((0.0..1.0).contains(&st.average_from), "statistics", "average_from", st.average_from, "a fraction of the averaged rows, 0 <= f < 1")?;
        if let crate::scene::BlocksSpec::Count(k) = st.blocks {
            check((2..=1000).contains(&k), "statistics", "blocks", k, "\"auto\", or 2 to 1000 blocks")?;
        }
        check(self.output.frames <= MAX_FRAMES, "output", "frames", self.output.frames, &format!("0 to {MAX_FRAMES} (each frame rewrites the .pvd index and the manifest)"))?;
        if self.analysis == Analysis::Shear {
            check(self.walls.is_some() && self.domain.periodic_x.is_some(), "", "analysis", "shear", "a scene with walls and periodic_x")?;
        }
        self.validate_stages()
    }

    /// A protocol's stages: each on its own, and each wall's control as the stages
    /// before it leave it (a prescribed y velocity needs `fixed` control).
    fn validate_stages(&self) -> Result<(), Error> {
        let stages = &self.stages;
        if stages.is_empty() {
            return Ok(());
        }
        check(stages.len() <= MAX_STAGES, "", "stages", format!("{} stages", stages.len()), &format!("at most {MAX_STAGES}"))?;
        check(self.analysis != Analysis::Impact, "", "stages", format!("{} stages", stages.len()), "none with analysis impact (an impact ends at separation, not with a protocol)")?;
        let mut pressure = self.walls.as_ref().map(|w| [w.bottom.control != ControlSpec::Fixed, w.top.control != ControlSpec::Fixed]);
        let mut names = std::collections::HashSet::new();
        let mut frames = 0u64;
        for (k, st) in stages.iter().enumerate() {
            let at = format!("stages[{k}]");
            let name_ok = st.name.len() <= 64 && st.name.chars().all(|c| c.is_ascii_alphanumeric() || " -_.".contains(c)) && st.name.trim() == st.name;
            check(name_ok, &at, "name", format!("{:?}", st.name), "letters, digits, spaces and -_. (at most 64 characters, no space at either end)")?;
            let name = self.stage_name(k);
            check(names.insert(name.clone()), &at, "name", format!("{name:?}"), "a name no other stage has")?;
            check(finite_pos(st.duration), &at, "duration", st.duration, "> 0 s")?;
            if let Some(g) = st.gravity {
                check(g.iter().all(|g| g.is_finite()), &at, "gravity", format!("{g:?}"), "finite m/s^2")?;
            }
            if let Some(n) = st.samples {
                check(n >= 1, &at, "samples", n, ">= 1")?;
            }
            frames = frames.saturating_add(st.frames.unwrap_or(0));
            for (w, (name, c)) in [("bottom", &st.walls.bottom), ("top", &st.walls.top)].into_iter().enumerate() {
                let at = format!("{at}.walls.{name}");
                let Some(loaded) = pressure.as_mut() else {
                    check(c.is_none(), &at.replace(&format!(".walls.{name}"), ""), "walls", name, "no wall changes: the scene has no walls")?;
                    continue;
                };
                if let Some(v) = c.velocity_x {
                    check(v.is_finite(), &at, "velocity_x", v, "finite m/s")?;
                }
                match &c.control {
                    Some(ControlSpec::Pressure(p)) => {
                        check(name == "top", &at, "control", "pressure", "fixed (only the top wall carries a load)")?;
                        check(finite_pos(*p), &at, "control.pressure", *p, "> 0 Pa")?;
                        loaded[w] = true;
                    }
                    Some(ControlSpec::Fixed) => loaded[w] = false,
                    None => {}
                }
                if let Some(v) = c.velocity_y {
                    check(v.is_finite(), &at, "velocity_y", v, "finite m/s")?;
                    check(!loaded[w], &at, "velocity_y", v, "none while the wall is under pressure control (its load moves it in y)")?;
                }
            }
        }
        check(frames <= MAX_FRAMES, "", "stages", format!("{frames} frames in all"), &format!("at most {MAX_FRAMES} frames"))?;
        let sum: f64 = stages.iter().map(|s| s.duration).sum();
        check((self.duration - sum).abs() <= 1e-9 * sum, "", "duration", self.duration, &format!("the stages' sum, {sum} s (or leave it out)"))?;
        Ok(())
    }

/// The stages in one line, for `explain`: each with its duration and what it changes.
    pub fn describe_stages(&self) -> Option<String> {
            let scene = self;
        if scene.stages.is_empty() {
            return None;
        }
        let parts: Vec<String> = scene
            .stages
            .iter()
            .enumerate()
            .map(|(k, st)| {
                let mut what = Vec::new();
                for (name, c) in [("bottom", &st.walls.bottom), ("top", &st.walls.top)] {
                    let mut w = Vec::new();
                    if let Some(v) = c.velocity_x {
                        w.push(format!("vx {v} m/s"));
                    }
                    if let Some(v) = c.velocity_y {
                        w.push(format!("vy {v} m/s"));
                    }
                    match &c.control {
                        Some(ControlSpec::Fixed) => w.push("fixed".into()),
                        Some(ControlSpec::Pressure(p)) => w.push(format!("pressure {p} Pa")),
                        None => {}
                    }
                    if !w.is_empty() {
                        what.push(format!("{name} {}", w.join(", ")));
                    }
                }
                if let Some(g) = st.gravity {
                    what.push(format!("gravity [{}, {}] m/s^2", g[0], g[1]));
                }
                if !st.average {
                    what.push("not averaged".into());
                }
                let what = if what.is_empty() { String::new() } else { format!(": {}", what.join("; ")) };
                format!("{} ({} s{what})", scene.stage_name(k), st.duration)
            })
            .collect();
        Some(format!("stages: {}", parts.join(" -> ")))
    }

    /// The name of stage `k`: its own, or `stage K` (K = k + 1).
    pub fn stage_name(&self, k: usize) -> String {
        match self.stages.get(k) {
            Some(s) if !s.name.is_empty() => s.name.clone(),
            _ => format!("stage {}", k + 1),
        }
    }

    /// The scene cut to its first `duration` s: the stages that begin before it, the last
    /// one shortened (a scene without stages only takes the new duration).
    pub fn truncated(&self, duration: f64) -> Scene {
        let mut s = self.clone();
        s.duration = duration;
        if !s.stages.is_empty() {
            let mut start = 0.0;
            let mut kept = Vec::new();
            for (k, st) in self.stages.iter().enumerate() {
                if start >= duration && !kept.is_empty() {
                    break;
                }
                let mut st = st.clone();
                st.name = self.stage_name(k);
                st.duration = st.duration.min(duration - start);
                start += self.stages[k].duration;
                kept.push(st);
            }
            s.duration = kept.iter().map(|st| st.duration).sum();
            s.stages = kept;
        }
        s
    }

    /// The walls' velocities `[bottom, top]`, m/s: the scene's, then after each stage's
    /// changes (element k + 1 is stage k's). Empty without walls. A loaded wall's y
    /// velocity is its own dynamics: here it keeps the value it was given.
    pub fn wall_velocities(&self) -> Vec<[[f64; 2]; 2]> {
        let Some(w) = &self.walls else { return Vec::new() };
        let mut v = [[w.bottom.velocity_x, w.bottom.velocity_y], [w.top.velocity_x, w.top.velocity_y]];
        let mut out = vec![v];
        for st in &self.stages {
            for (k, c) in [&st.walls.bottom, &st.walls.top].into_iter().enumerate() {
                v[k][0] = c.velocity_x.unwrap_or(v[k][0]);
                v[k][1] = c.velocity_y_set().unwrap_or(v[k][1]);
            }
            out.push(v);
        }
        out
    }

    /// The fastest wall speed of the scene and of any of its stages, m/s.
    pub fn fastest_wall(&self) -> f64 {
        self.wall_velocities().iter().flatten().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max)
    }

    /// The first material with a work of adhesion above 0 (DMT cohesion), with its index.
    pub fn adhesive_material(&self) -> Option<(usize, &crate::physics::material::Material)> {
        self.materials.iter().enumerate().find(|(_, m)| m.work_of_adhesion > 0.0)
    }

    /// The strongest gravity of the scene and of any of its stages, m/s^2.
    pub fn strongest_gravity(&self) -> f64 {
        self.stages.iter().filter_map(|s| s.gravity).chain([self.gravity]).map(|g| g[0].hypot(g[1])).fold(0.0, f64::max)
    }

    /// The lower edge of a packing's region: its `y_min`, else the bottom wall's surface.
    pub fn grains_floor(&self) -> Option<f64> {
        match &self.grains {
            Grains::Pack(p) => p.y_min.or_else(|| self.walls.as_ref().and_then(|w| w.bottom.y.map(|y| y + w.bottom.surface.radius()))),
            _ => None,
        }
    }
}
