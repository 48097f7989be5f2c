//! An ensemble: one shear scene run over several packing seeds, independent realisations
//! of the same packing statistics (`grainlab ensemble`). Each quantity's ensemble mean
//! gets a 95% interval from the run-to-run spread (Student t over the runs), beside each
//! run's own block interval ([`crate::observe::stats::estimate`]): a sheared
//! packing is chaotic, and a run's block interval does not cover what another seed gives.

use serde::Serialize;

use crate::error::Error;
use crate::observe::stats::{Estimate, t975};
use crate::scene::limits::Limits;
use crate::scene::{Analysis, Grains, Scene};
use crate::study::run::{RunOptions, run_report};

/// Most seeds one ensemble runs.
pub const MAX_SEEDS: usize = 1000;

/// One realisation.
#[derive(Clone, Debug, Serialize)]
pub struct EnsembleRun {
    /// The packing seed (`grains.pack.seed`).
    pub seed: u64,
    /// How the run ended (`completed`, `stopped`, `interrupted`); only completed runs
    /// enter the ensemble statistics.
    pub status: String,
    pub error: Option<String>,
    /// The run's own time averages with their block intervals.
    pub stress_ratio: Option<Estimate>,
    pub shear_stress_pa: Option<Estimate>,
    pub normal_stress_pa: Option<Estimate>,
    pub packing_fraction: Option<f64>,
    /// Mean overlap over radius at the end ([`crate::observe::stress::ShearSummary`]).
    pub mean_overlap_rel: Option<f64>,
    /// The run's time step, s, and steps per Hertz contact time.
    pub dt_s: f64,
    pub steps_per_contact: f64,
    /// Steps run, and the grains stepped.
    pub steps: u64,
    pub grains: usize,
    /// The energy ledger's largest residual over the energy put in, if kept.
    pub energy_residual_rel: Option<f64>,
    /// Wall-clock time of the time stepping, s (the run's own clock).
    pub wall_time_s: f64,
}

/// A quantity over the ensemble.
#[derive(Clone, Debug, Serialize)]
pub struct EnsembleStat {
    /// Completed runs that have the quantity.
    pub runs: usize,
    /// Mean of the runs' values.
    pub mean: f64,
    /// Sample standard deviation of the runs' values (the run-to-run spread).
    pub std: f64,
    /// Half-width of the 95% interval of the mean: t(0.975, runs - 1) std / sqrt(runs).
    pub ci95: f64,
    /// The runs' own block intervals (95% half-widths), averaged; none for a quantity
    /// without one (the packing fraction).
    pub mean_block_ci95: Option<f64>,
    /// The runs' own standard errors of the mean, averaged: each run's block half-width
    /// over its t(0.975, blocks - 1).
    pub mean_block_standard_error: Option<f64>,
    /// Run-to-run standard deviation over the mean block standard error. Were the block
    /// intervals honest, a run's mean would scatter from run to run by its standard
    /// error: about 1 (with 8 runs, itself uncertain by about a quarter). Above, the runs
    /// scatter more than their block intervals allow.
    pub spread_over_standard_error: Option<f64>,
}

/// An ensemble's runs and statistics (`ensemble.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Ensemble {
    pub scene: String,
    pub seeds: Vec<u64>,
    pub runs: Vec<EnsembleRun>,
    /// None where fewer than two completed runs have the quantity.
    pub stress_ratio: Option<EnsembleStat>,
    pub shear_stress_pa: Option<EnsembleStat>,
    pub normal_stress_pa: Option<EnsembleStat>,
    pub packing_fraction: Option<EnsembleStat>,
    pub mean_overlap_rel: Option<EnsembleStat>,
}

/// The seeds a `--seeds` value names: `A..B` (both included) or a comma-separated list.
pub fn parse_seeds(text: &str) -> Result<Vec<u64>, Error> {
    let bad = || Error::BadOption { option: "--seeds".into(), value: text.into(), allowed: format!("A..B (both included) or a comma-separated list, 2 to {MAX_SEEDS} different seeds") };
    let seeds: Vec<u64> = if let Some((a, b)) = text.split_once("..") {
        let (a, b): (u64, u64) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
        if b < a || b - a >= MAX_SEEDS as u64 {
            return Err(bad());
        }
        (a..=b).collect()
    } else {
        text.split(',').map(|s| s.trim().parse().map_err(|_| bad())).collect::<Result<_, _>>()?
    };
    let mut unique = seeds.clone();
    unique.sort_unstable();
    unique.dedup();
    if seeds.len() < 2 || seeds.len() > MAX_SEEDS || unique.len() != seeds.len() {
        return Err(bad());
    }
    Ok(seeds)
}

/// Run `scene` once per seed (its packing's `seed` replaced), on `threads`, each for
/// `duration` (s, else the scene's), and gather the shear estimates; `each` hears of every
/// run as it ends. The scene must pack its grains (the seed is what varies) and analyse
/// shear; a refused build refuses the ensemble, a run that stops is reported and left out
/// of the statistics.
pub fn ensemble(scene: &Scene, seeds: &[u64], duration: Option<f64>, threads: usize, limits: &Limits, mut each: impl FnMut(&EnsembleRun)) -> Result<Ensemble, Error> {
    if !matches!(scene.grains, Grains::Pack(_)) {
        return Err(Error::Invalid { field: "grains".into(), value: "listed or read from a file".into(), allowed: "grains.pack: an ensemble varies the packing's seed".into() });
    }
    if scene.analysis != Analysis::Shear {
        return Err(Error::Invalid { field: "analysis".into(), value: scene.analysis.name().into(), allowed: "\"shear\": an ensemble gathers the shear estimates".into() });
    }
    let mut runs = Vec::with_capacity(seeds.len());
    for &seed in seeds {
        let mut s = scene.clone();
        if let Grains::Pack(p) = &mut s.grains {
            p.seed = seed;
        }
        let built = crate::study::accuracy::build_limited(&s, threads, limits)?;
        let opts = RunOptions { duration, limits: *limits, ..RunOptions::default() };
        let report = run_report(&s, built, &opts)?;
        let sum = report.summary;
        let shear = sum.shear.as_ref();
        let run = EnsembleRun {
            seed,
            status: sum.status.clone(),
            error: sum.error.clone(),
            stress_ratio: shear.and_then(|x| x.stress_ratio),
            shear_stress_pa: shear.map(|x| x.shear_stress_pa),
            normal_stress_pa: shear.map(|x| x.normal_stress_pa),
            packing_fraction: shear.and_then(|x| x.packing_fraction),
            mean_overlap_rel: shear.and_then(|x| x.mean_overlap_rel),
            dt_s: sum.time_step.dt_s,
            steps_per_contact: sum.time_step.steps_per_contact,
            steps: sum.steps,
            grains: sum.grains,
            energy_residual_rel: sum.energy.as_ref().map(|e| e.max_residual_rel),
            wall_time_s: sum.wall_time_s,
        };
        each(&run);
        runs.push(run);
    }
    let done: Vec<&EnsembleRun> = runs.iter().filter(|r| r.status == "completed").collect();
    let of = |f: &dyn Fn(&EnsembleRun) -> Option<Estimate>| stat(&done.iter().filter_map(|r| f(r)).map(|e| (e.mean, Some((e.ci95, e.standard_error())))).collect::<Vec<_>>());
    Ok(Ensemble {
        scene: scene.name.clone(),
        seeds: seeds.to_vec(),
        stress_ratio: of(&|r| r.stress_ratio),
        shear_stress_pa: of(&|r| r.shear_stress_pa),
        normal_stress_pa: of(&|r| r.normal_stress_pa),
        packing_fraction: stat(&done.iter().filter_map(|r| r.packing_fraction).map(|x| (x, None)).collect::<Vec<_>>()),
        mean_overlap_rel: stat(&done.iter().filter_map(|r| r.mean_overlap_rel).map(|x| (x, None)).collect::<Vec<_>>()),
        runs,
    })
}

/// The ensemble statistics of values without block intervals (one per run); none for
/// fewer than two values or a value that is not finite.
pub fn ensemble_stat(values: &[f64]) -> Option<EnsembleStat> {
    stat(&values.iter().map(|&x| (x, None)).collect::<Vec<_>>())
}

impl EnsembleStat {
    /// The ensemble mean as an estimate whose interval is the run-to-run one: its
    /// standard error std / sqrt(runs) and runs - 1 degrees of freedom (`blocks` = runs).
    pub fn as_estimate(&self) -> Estimate {
        Estimate { mean: self.mean, ci95: self.ci95, blocks: self.runs, autocorrelation_time_s: None }
    }
}

/// The ensemble statistics of the runs' values (each with its block half-width and
/// standard error, if any); none for fewer than two values or a value that is not finite.
fn stat(values: &[(f64, Option<(f64, f64)>)]) -> Option<EnsembleStat> {
    let n = values.len();
    if n < 2 || values.iter().any(|(x, c)| !x.is_finite() || c.is_some_and(|c| !c.0.is_finite())) {
        return None;
    }
    let mean = values.iter().map(|v| v.0).sum::<f64>() / n as f64;
    let std = (values.iter().map(|v| (v.0 - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let blocks: Vec<(f64, f64)> = values.iter().filter_map(|v| v.1).collect();
    let all = blocks.len() == n;
    let mean_block_ci95 = all.then(|| blocks.iter().map(|b| b.0).sum::<f64>() / n as f64);
    let mean_block_standard_error = all.then(|| blocks.iter().map(|b| b.1).sum::<f64>() / n as f64);
    Some(EnsembleStat {
        runs: n,
        mean,
        std,
        ci95: t975(n - 1) * std / (n as f64).sqrt(),
        mean_block_ci95,
        mean_block_standard_error,
        spread_over_standard_error: mean_block_standard_error.filter(|&c| c > 0.0).map(|c| std / c),
    })
}
