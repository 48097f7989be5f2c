//! CSV time series. Headers come from the row types' field names, which carry the unit
//! (`time_s`, `work_walls_j`, ...). Rows are flushed as written, so a run that stops
//! keeps everything it computed.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use serde::Serialize;

use crate::error::Error;

pub struct CsvSeries {
    w: ::csv::Writer<BufWriter<File>>,
    path: String,
}

impl CsvSeries {
    pub fn create(path: &Path) -> Result<Self, Error> {
        let f = File::create(path).map_err(|e| Error::io(path.display(), e))?;
        Ok(CsvSeries { w: ::csv::Writer::from_writer(BufWriter::new(f)), path: path.display().to_string() })
    }
    pub fn row<T: Serialize>(&mut self, row: &T) -> Result<(), Error> {
        self.w.serialize(row).map_err(|e| Error::Other(format!("{}: {e}", self.path)))?;
        self.w.flush().map_err(|e| Error::io(&self.path, e))
    }
}
