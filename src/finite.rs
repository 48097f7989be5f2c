//! Finite numbers only: the check that every output row and every health check of a run
//! share. An undefined quantity is an `Option` (an empty CSV cell, `null` in JSON); a
//! number that is NaN or infinite means the run went wrong and is never written.

use serde::Serialize;

/// The header of the first column of `row` that holds NaN or an infinity, if any (an
/// undefined quantity is an `Option`, written as an empty cell).
pub fn non_finite_column<T: Serialize>(row: &T) -> Option<String> {
    let mut w = ::csv::Writer::from_writer(Vec::new());
    w.serialize(row).ok()?;
    let text = w.into_inner().ok()?;
    let mut r = ::csv::Reader::from_reader(&text[..]);
    let headers = r.headers().ok()?.clone();
    let record = r.records().next()?.ok()?;
    let bad = |v: &str| matches!(v.to_ascii_lowercase().as_str(), "nan" | "inf" | "-inf" | "+inf" | "infinity" | "-infinity");
    record.iter().position(bad).map(|k| headers.get(k).unwrap_or("?").to_string())
}

#[cfg(test)]
mod tests {
    #[derive(serde::Serialize)]
    struct Row {
        name: &'static str,
        a_m: f64,
        b_m: Option<f64>,
        c_m: f64,
    }

    #[test]
    fn a_non_finite_number_is_found_by_its_column_and_an_empty_cell_is_not() {
        assert_eq!(super::non_finite_column(&Row { name: "nan", a_m: 1.0, b_m: None, c_m: 2.0 }), None);
        assert_eq!(super::non_finite_column(&Row { name: "x", a_m: 1.0, b_m: Some(f64::NAN), c_m: 2.0 }).as_deref(), Some("b_m"));
        assert_eq!(super::non_finite_column(&Row { name: "x", a_m: 1.0, b_m: None, c_m: f64::NEG_INFINITY }).as_deref(), Some("c_m"));
    }
}
