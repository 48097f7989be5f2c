//! What a run writes into `--out DIR`: `summary.json`, CSV time series with
//! unit-suffixed headers, ParaView frames.

pub mod csv;
pub mod vtk;
