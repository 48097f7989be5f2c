//! Finite numbers only: the check that every output row and every health check of a run
//! share. An undefined quantity is an `Option` (an empty CSV cell, `null` in JSON); a
//! number that is NaN or infinite means the run went wrong and is never written.

use serde::Serialize;
use serde_value::Value;

/// The name (JSON-style path) of the first number in `row` that is NaN or infinite, if
/// any. The row is read as a value tree (serde-value keeps the numbers as they are; an
/// `Option` that is `None` is no number and passes).
pub fn non_finite_column<T: Serialize>(row: &T) -> Option<String> {
    fn find(v: &Value, at: &str) -> Option<String> {
        match v {
            Value::F64(x) if !x.is_finite() => Some(at.to_string()),
            Value::F32(x) if !x.is_finite() => Some(at.to_string()),
            Value::Option(Some(inner)) | Value::Newtype(inner) => find(inner, at),
            Value::Seq(items) => items.iter().enumerate().find_map(|(k, x)| find(x, &format!("{at}[{k}]"))),
            Value::Map(fields) => fields.iter().find_map(|(k, x)| {
                let name = match k {
                    Value::String(s) => s.clone(),
                    other => format!("{other:?}"),
                };
                find(x, &if at.is_empty() { name } else { format!("{at}.{name}") })
            }),
            _ => None,
        }
    }
    // A row that does not serialise has no number to check.
    find(&serde_value::to_value(row).ok()?, "")
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
