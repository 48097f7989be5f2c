//! Helpers shared by the integration tests.

/// The arrays of a `.vtp` written with appended raw data: name -> values (Float64 and
/// Int64 as f64), read as a VTK reader would (offset into the block after `_`, a 64-bit
/// byte count, then the values).
pub fn read_vtp(path: &std::path::Path) -> std::collections::HashMap<String, Vec<f64>> {
    let bytes = std::fs::read(path).unwrap();
    let start = bytes.windows(3).position(|w| w == b"  _").unwrap() + 3;
    let xml = String::from_utf8_lossy(&bytes[..start]).into_owned();
    let mut out = std::collections::HashMap::new();
    for tag in xml.split("<DataArray ").skip(1) {
        let attr = |k: &str| tag.split(&format!("{k}=\"")).nth(1).unwrap().split('"').next().unwrap().to_string();
        let at = start + attr("offset").parse::<usize>().unwrap();
        let len = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
        let raw = &bytes[at + 8..at + 8 + len];
        let values = raw
            .chunks(8)
            .map(|b| match attr("type").as_str() {
                "Float64" => f64::from_le_bytes(b.try_into().unwrap()),
                "Int64" => i64::from_le_bytes(b.try_into().unwrap()) as f64,
                t => panic!("type {t}"),
            })
            .collect();
        // Point and cell arrays may share a name (normal_force_n): the cells' come last.
        out.insert(attr("Name"), values);
    }
    out
}
