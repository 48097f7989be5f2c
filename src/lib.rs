//! # grainlab: a 2D Hertz-Mindlin DEM engine built as a validation workbench
//!
//! A guided tour, folder by folder in the order a run goes through the code. Each folder
//! is one concern and imports only from the folders before it (`tests/layout.rs` holds
//! the code to that); `error` and `finite` serve them all.
//!
//! 1. **Physics** ([`physics`]): what a grain is ([`physics::dim`]: the plane, sphere in
//!    the plane or disk, and the [`physics::dim::Dim`] trait that lets one source serve
//!    the plane and space, so far the force of one contact and the tangential laws
//!    (issue 30);
//!    [`physics::particles`]: grain state as struct of arrays), the
//!    materials and their mixing ([`physics::material`]), the contact law composed at
//!    compile time ([`physics::contact`]: a normal law, Hertz or the linear spring; a
//!    damping form, the one that returns e or LAMMPS' Tsuji fit; a tangential
//!    formulation, LIGGGHTS' total displacement, YADE's increments, LAMMPS' cap on the
//!    total force, that cap with the spring kept (Kratos' rule), or Mindlin-Deresiewicz
//!    micro-slip on a bed of springs across the contact; one monomorphized
//!    kernel per named combination), written once over its number type to run one
//!    contact or four in SIMD lanes with the same bits ([`physics::lanes`]); walls, flat
//!    or rough, fixed or loaded ([`physics::walls`]), the periodic boundary in x
//!    ([`physics::boundary`]), and the energy ledger ([`physics::energy`]).
//! 2. **Kernels** ([`kernels`]): the Verlet list and its contact histories
//!    ([`kernels::pairs`]), the cell lists that fill it ([`kernels::cells`]), the
//!    branch-free sweep that finds the touching pairs ([`kernels::sweep`]; eight pairs at
//!    a time on AVX-512 CPUs, four on AVX2, with the portable sweep's bits) and the
//!    driver that runs the law on them ([`kernels::driver`]), on a pool of threads that
//!    gives one thread's bits ([`kernels::threads`]). Slices and views in, forces out.
//! 3. **Scene** ([`scene`]): a JSON file (or a built-in, [`scene::builtin`]) says what is
//!    simulated: materials, grains (listed, from a file, or a seeded packing,
//!    [`scene::pack`]), walls, periodicity, the contact model, the time step rule,
//!    outputs. Each field is validated with its JSON path, value and allowed range
//!    ([`error`]); what the scene may ask of the machine is bounded ([`scene::limits`]).
//! 4. **Engine** ([`engine`]): the build ([`engine::build`]) checks the grains, walls,
//!    speeds and load against each other ([`engine::consistency`]) and turns the scene
//!    into a world ([`engine::world`]) and a pipeline of the stages it asks for, and no
//!    others ([`engine::stages`]): no walls, no wall stage; no gravity, no gravity stage;
//!    no friction, no spin. The pipeline runs behind one dynamic call per step, the
//!    [`Engine`] ([`engine::simulation`]), which hands observers a read-only [`View`]. Velocity Verlet ([`engine::integrate`]; between the steps a
//!    run looks at, a step's final half kick rides along the next drift, with the same
//!    bits) with a time step from a rule, checked against the stability limit
//!    ([`engine::timestep`]); the neighbour list is rebuilt when a grain has moved half
//!    the skin ([`engine::neighbor`]), where the domain's checks stop a run that goes
//!    wrong with a diagnosis ([`engine::domain`]). With the `parallel` feature the
//!    contact forces run on several threads, bit for bit as on one (`engine::parallel`).
//!    Everything a simulation carries from step to step can be saved and restored into
//!    one built from the same scene, for an exact restart ([`engine::snapshot`]).
//! 5. **Observers** ([`observe`]): impacts ([`observe::impact`]), wall stresses
//!    ([`observe::stress`]), the energy balance's summary ([`observe::energy`]),
//!    block-averaged confidence intervals ([`observe::stats`]), the packing inside from
//!    the contacts a step records (stress tensor, coordination, fabric:
//!    [`observe::packing`]) and its profiles across the gap ([`observe::profiles`]),
//!    each from a [`View`].
//! 6. **Output** ([`output`]): only finite numbers ([`finite`]; an undefined quantity is
//!    empty or `null`): `summary.json` ([`output::summary`]), CSV time series with
//!    unit-suffixed headers, ParaView `.vtp` frames (binary; grains, and the contacts as
//!    force-chain lines) with `.pvd` indexes, in an output
//!    folder that is grainlab's ([`output::folder`]: a manifest, files that appear whole),
//!    with the scene as it ran and what produced the run ([`output::provenance`]), and
//!    the checkpoint a run resumes from ([`output::checkpoint`]: versioned, checksummed).
//! 7. **Studies** ([`study`]): a run with its progress bar, observers and outputs, ended
//!    early on a stop request with everything written, checkpointed and resumed bit for
//!    bit ([`study::run`], [`study::protocol`]: a scene's stages as phases of the run); sweeps of the
//!    time step or the grains' stiffness, against references beyond the swept range
//!    ([`study::sweep`]); the accuracy calibration that picks a
//!    time step for a stated accuracy before the engine is built ([`study::accuracy`]).
//! 8. **Workbench** ([`workbench`]): the reference cases under `reference/`
//!    ([`workbench::cases`](mod@workbench::cases)), the digest of LIGGGHTS', YADE's and LAMMPS' output with the engine's
//!    own observers ([`workbench::digest`](mod@workbench::digest)), the comparison ([`workbench::compare`]); the
//!    exporter writes any scene as a deck for each code, exactly or refused by name
//!    ([`workbench::export`]); frozen states the codes evaluate without moving, to
//!    check what the packing observers read ([`workbench::frozen`]).
//!
//! Each class of failure has its exit code ([`error::exit`]). Everything is SI: m, kg,
//! s, N, Pa, J.

// The checks refuse NaN by writing `!(value <= bound)`: false for NaN, so NaN fails them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;
pub mod finite;

pub mod physics;
pub mod kernels;
pub mod scene;
pub mod engine;
pub mod observe;
pub mod output;
pub mod study;
pub mod workbench;

// The public API a user needs: a scene, its build, a run, the engine and its view, the
// observers and what a run reports.
pub use engine::build::Built;
pub use engine::simulation::Engine;
pub use engine::world::View;
pub use error::Error;
pub use observe::impact::{ImpactObserver, ImpactSummary};
pub use observe::stress::{ShearSummary, WallAverager};
pub use output::summary::Summary;
pub use scene::Scene;
pub use study::run::{RunOptions, run_scene};
pub use study::{build, build_in, build_limited, build_with};
