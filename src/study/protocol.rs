//! A protocol's stages as a run goes through them ([`Phase`]): each stage's steps, its
//! output rates and its change of the walls' motion and gravity, resolved from the scene
//! and the time step. A scene without stages is one phase with no name (its outputs have
//! no `stage` column), on the schedule every run had before protocols.

use crate::engine::build::control;
use crate::engine::timestep::{schedule, stage_steps, stage_too_short, step_count};
use crate::engine::world::{MotionChange, WallMotion};
use crate::error::Error;
use crate::scene::{Scene, WallChange};

/// One stage of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Phase {
    /// The stage's name; empty for a scene without stages.
    pub name: String,
    /// Steps done before the stage's first, over the whole run.
    pub first: u64,
    /// The stage's steps.
    pub steps: u64,
    /// A sample row every this many of the stage's steps, and at its last.
    pub sample_every: u64,
    /// A ParaView frame every this many of the stage's steps, if any.
    pub frame_every: Option<u64>,
    /// The summary averages the stage's wall stresses.
    pub average: bool,
    /// What changes at the stage's start (before its first step); its y velocities are
    /// resolved ([`WallChange::velocity_y_set`]).
    pub change: MotionChange,
}

impl Phase {
    /// The step count after the stage's last step.
    pub fn last(&self) -> u64 {
        self.first + self.steps
    }
}

/// The phases of `scene` at time step `dt`, s; a pressure becomes a force on the walls'
/// area `length` x `depth`, m. The stage durations were validated; their step counts are
/// checked here against the bound on steps.
pub fn phases(scene: &Scene, dt: f64, length: f64, depth: f64) -> Result<Vec<Phase>, Error> {
    if scene.stages.is_empty() {
        let (total, sample_every) = schedule(scene.duration, dt, scene.output.samples);
        let frame_every = (scene.output.frames > 0).then(|| (total / scene.output.frames).max(1));
        return Ok(vec![Phase { name: String::new(), first: 0, steps: total, sample_every, frame_every, average: true, change: MotionChange::default() }]);
    }
    let total_s: f64 = scene.stages.iter().map(|s| s.duration).sum();
    // A count shared out by duration: cumulative rounding, so the stages' shares add up.
    let share = |count: u64, from: f64, to: f64| ((count as f64 * to / total_s).round() - (count as f64 * from / total_s).round()).max(0.0) as u64;
    let mut out = Vec::with_capacity(scene.stages.len());
    let (mut first, mut start) = (0u64, 0.0);
    step_count(scene.duration, dt, "duration")?;
    let counts = stage_steps(scene.stages.iter().map(|s| s.duration), dt);
    // A protocol cut short (`--duration`) may end within a step of its last stage's start.
    let kept = counts.iter().rposition(|&n| n > 0).map_or(0, |k| k + 1);
    for (k, st) in scene.stages.iter().enumerate().take(kept) {
        let steps = counts[k];
        if steps == 0 {
            return Err(stage_too_short(k, st.duration, dt));
        }
        let end = start + st.duration;
        let samples = st.samples.unwrap_or_else(|| share(scene.output.samples, start, end).max(1));
        let frames = st.frames.unwrap_or_else(|| share(scene.output.frames, start, end));
        let motion = |c: &WallChange| WallMotion { velocity_x: c.velocity_x, velocity_y: c.velocity_y_set(), control: c.control.as_ref().map(|c| control(c, length, depth)) };
        let change = MotionChange { walls: [motion(&st.walls.bottom), motion(&st.walls.top)], gravity: st.gravity };
        out.push(Phase {
            name: scene.stage_name(k),
            first,
            steps,
            sample_every: (steps / samples).max(1),
            frame_every: (frames > 0).then(|| (steps / frames).max(1)),
            average: st.average,
            change,
        });
        first += steps;
        start = end;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples and frames shared out by duration add up to the scene's counts; the
    /// stages follow each other step for step.
    #[test]
    fn shares_add_up() {
        let s = crate::scene::builtin::protocol();
        let dt = 1e-6;
        let ph = phases(&s, dt, 0.04, 1e-3).unwrap();
        assert_eq!(ph.len(), 4);
        for w in ph.windows(2) {
            assert_eq!(w[0].last(), w[1].first);
        }
        let rows: u64 = ph.iter().map(|p| p.steps.div_ceil(p.sample_every)).sum();
        assert!((rows as i64 - s.output.samples as i64).abs() <= 4, "{rows} rows for {} samples", s.output.samples);
        assert_eq!(ph[2].change.walls[1].velocity_x, Some(0.5));
        assert_eq!(ph[0].change, MotionChange::default());
    }
}
