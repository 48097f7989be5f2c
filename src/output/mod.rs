//! What a run writes into `--out DIR`: `summary.json`, CSV time series with
//! unit-suffixed headers, ParaView frames, and the folder's manifest ([`folder`]: the
//! folder is grainlab's, and every file appears whole).

pub mod csv;
pub mod folder;
pub mod vtk;
