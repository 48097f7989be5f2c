//! What a run writes into `--out DIR`: the summary, CSV time series with unit-suffixed
//! headers, ParaView frames, the scene as it ran and what produced the run
//! ([`provenance`]), and the folder's manifest ([`folder`]: the folder is grainlab's, and
//! every file appears whole). May use: `observe`, `engine` (its view),
//! `scene`, `physics`, `error`, `finite`.

pub mod checkpoint;
pub mod csv;
pub mod folder;
pub mod provenance;
pub mod summary;
pub mod vtk;
