//! # grainlab: a 2D Hertz-Mindlin DEM engine built as a validation workbench
//!
//! A guided tour, in the order a run goes through the code:
//!
//! 1. **Scene** ([`scene`]): a JSON file (or a built-in, [`scenes`]) says what is simulated:
//!    materials ([`material`]), grains (listed, from a file, or a seeded packing, [`pack`]),
//!    walls, periodicity, the contact model, the time step rule, outputs. It is
//!    validated as a whole; errors name the field's JSON path, the value and what is
//!    allowed ([`error`]).
//! 2. **Build** ([`build`]): every size the scene asks for is estimated and checked
//!    against a memory budget before it is allocated ([`limits`]), and the grains, walls,
//!    speeds, load and analysis are checked against each other ([`consistency`]). Then
//!    the scene becomes a [`sim::World`] (grain state as struct of
//!    arrays, [`particles`]; the plane and grain shapes, [`dim`]) and a **pipeline**
//!    ([`pipeline`]) of stages, only those the scene asks for: no walls, no wall stage; no
//!    gravity, no gravity stage; no friction, no spin. The time step follows a rule and
//!    is checked against the stability limit ([`timestep`]), or picked for a stated accuracy
//!    from the measured convergence of an impact ([`accuracy`]).
//! 3. **Contact physics** ([`contact`]) is composed at compile time: Hertz normal force,
//!    a damping form, a tangential formulation (LIGGGHTS' total displacement or YADE's
//!    increments), one monomorphized kernel per named combination. The law is written
//!    once, generic over its number type, and runs one contact or four in SIMD lanes with
//!    the same bits ([`lanes`]); a sweep over the Verlet list hands it the touching
//!    pairs (on AVX-512 CPUs eight pairs at a time, module `avx512`; on AVX2 CPUs four,
//!    module `avx2`: each compiled in only for its CPUs, with the portable sweep's
//!    bits). Neighbours come from a cell list with a skin, and contact history survives
//!    rebuilds ([`neighbor`]); x may be periodic ([`boundary`]); walls are flat or rough,
//!    fixed or loaded ([`walls`]).
//! 4. **Simulation** ([`sim`]): velocity Verlet ([`integrate`]; on AVX-512 CPUs eight
//!    grains at a time, module `avx512`; between the steps a run looks at, a step's final
//!    half kick rides along the next drift, with the same bits) runs the stages each
//!    step, timed per stage; a watchdog and the domain's checks at each neighbour rebuild
//!    ([`domain`]) stop a run that goes wrong, naming the grain, the step and the likely
//!    cause.
//!    With the `parallel` feature the per-grain stages and the contact forces run on
//!    several threads ([`threads`], [`parallel`]), bit for bit the same as on one.
//! 5. **Observers** ([`observe`]): the energy balance, impact measurements, wall stresses,
//!    with block-averaged confidence intervals ([`stats`]).
//! 6. **Output** ([`output`]): only finite numbers ([`finite`]; an undefined quantity is
//!    empty or `null`): `summary.json`, CSV time series with unit-suffixed headers,
//!    ParaView `.vtp` frames with a `.pvd` index, in an output folder that is grainlab's
//!    (a manifest of what it wrote, files that appear whole; [`output::folder`]); [`run`]
//!    drives it all with a progress bar, and ends early on a stop request (SIGINT,
//!    SIGTERM) with everything written. Each class of failure has its exit code
//!    ([`error::exit`]).
//!
//! Around a run:
//!
//! 7. **Sweeps** ([`sweep`]): a scene over time steps and model variants, error against cost.
//! 8. **Export** ([`export`]): the same scene as a LIGGGHTS deck or a YADE script, for the
//!    reference workbench ([`workbench`]: the cases under `reference/`, the reading of
//!    the reference codes' output, the comparison) or for bigger machines.
//!
//! Everything is SI: m, kg, s, N, Pa, J.

// The checks refuse NaN by writing `!(value <= bound)`: false for NaN, so NaN fails them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accuracy;
#[cfg(all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))))]
pub mod avx2;
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
pub mod avx512;
pub mod boundary;
pub mod build;
pub mod consistency;
pub mod contact;
pub mod dim;
pub mod domain;
pub mod error;
pub mod export;
pub mod finite;
pub mod integrate;
pub mod lanes;
pub mod limits;
pub mod material;
pub mod neighbor;
pub mod observe;
pub mod output;
pub mod pack;
#[cfg(feature = "parallel")]
pub mod parallel;
pub mod particles;
pub mod pipeline;
pub mod run;
pub mod scene;
pub mod scenes;
pub mod sim;
pub mod stats;
pub mod sweep;
pub mod threads;
pub mod timestep;
pub mod walls;
pub mod workbench;

pub use build::{Built, Engine, build, build_with};
pub use error::Error;
pub use scene::Scene;
