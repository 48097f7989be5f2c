//! The numbers of a scene that depend on its dimension: `dimension` itself, a vector's
//! components (two in the plane, two or three in space) and a spin (a number about z,
//! or three components in space).
//!
//! A plane value in a 3D scene is the plane's value lifted into space: `[x, y]` is
//! `[x, y, 0]`, a spin `w` is `[0, 0, w]`. So a 2D scene with `"dimension": 3` is the
//! same scene in space, every grain at z = 0 (docs/scene.md): tests/space_scenes.rs runs
//! the two and compares them.

use std::ops::Index;

use schemars::JsonSchema;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::physics::dim::{Dim, Vec2};

/// The scene's dimension (`dimension`): 2 (the plane, the default) or 3 (space).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dimension {
    /// Grains in the x-y plane (spheres in the plane or disks), spins about z.
    #[default]
    Two,
    /// Spheres in space, spins about every axis.
    Three,
}

impl Dimension {
    pub fn is_two(&self) -> bool {
        *self == Dimension::Two
    }
    /// 2 or 3.
    pub fn count(self) -> usize {
        match self {
            Dimension::Two => 2,
            Dimension::Three => 3,
        }
    }
}

impl Serialize for Dimension {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u64(self.count() as u64)
    }
}

impl<'de> Deserialize<'de> for Dimension {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::{Error, Unexpected, Visitor};
        struct Count;
        impl Visitor<'_> for Count {
            type Value = Dimension;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("2 (the plane) or 3 (space)")
            }
            fn visit_u64<E: Error>(self, n: u64) -> Result<Dimension, E> {
                match n {
                    2 => Ok(Dimension::Two),
                    3 => Ok(Dimension::Three),
                    _ => Err(E::invalid_value(Unexpected::Unsigned(n), &self)),
                }
            }
            fn visit_i64<E: Error>(self, n: i64) -> Result<Dimension, E> {
                u64::try_from(n).map_err(|_| E::invalid_value(Unexpected::Signed(n), &self)).and_then(|n| self.visit_u64(n))
            }
            fn visit_f64<E: Error>(self, x: f64) -> Result<Dimension, E> {
                Err(E::invalid_value(Unexpected::Float(x), &self))
            }
        }
        d.deserialize_any(Count)
    }
}

impl JsonSchema for Dimension {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Dimension".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({ "type": "integer", "enum": [2, 3], "description": "2 (the plane, the default) or 3 (space)" })
    }
}

/// A vector of a scene (m, m/s, m/s^2): `[x, y]`, or in a 3D scene `[x, y, z]` (a plane
/// vector there lies in x-y). Read without allocating: a fourth number is refused.
#[derive(Clone, Copy, PartialEq)]
pub struct Coords {
    len: u8,
    c: [f64; 3],
}

impl Coords {
    /// The numbers given.
    pub fn as_slice(&self) -> &[f64] {
        &self.c[..self.len as usize]
    }
    pub fn iter(&self) -> std::slice::Iter<'_, f64> {
        self.as_slice().iter()
    }
    /// How many numbers were given: 2 or 3.
    pub fn len(&self) -> usize {
        self.len as usize
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// The z component: 0 for a plane vector.
    pub fn z(&self) -> f64 {
        self.c[2]
    }
    /// The plane's vector (x, y); a 3D scene's z is not in it.
    pub fn plane(&self) -> Vec2 {
        Vec2::new(self.c[0], self.c[1])
    }
    /// The vector in dimension `D`: a plane vector lifted into space with z = 0.
    pub fn lift<D: Dim>(&self) -> D::Vector<f64> {
        let mut v = D::zero::<f64>();
        for k in 0..D::D {
            v[k] = self.c[k];
        }
        v
    }
    /// The largest magnitude of its components' vector, `sqrt(x^2 + y^2 + z^2)`.
    pub fn norm(&self) -> f64 {
        self.c[0].hypot(self.c[1]).hypot(self.c[2])
    }
}

impl Default for Coords {
    fn default() -> Self {
        [0.0, 0.0].into()
    }
}

impl From<[f64; 2]> for Coords {
    fn from([x, y]: [f64; 2]) -> Self {
        Coords { len: 2, c: [x, y, 0.0] }
    }
}

impl From<[f64; 3]> for Coords {
    fn from(c: [f64; 3]) -> Self {
        Coords { len: 3, c }
    }
}

impl Index<usize> for Coords {
    type Output = f64;
    fn index(&self, k: usize) -> &f64 {
        &self.as_slice()[k]
    }
}

impl std::ops::IndexMut<usize> for Coords {
    fn index_mut(&mut self, k: usize) -> &mut f64 {
        let len = self.len as usize;
        &mut self.c[..len][k]
    }
}

/// As the scene writes it: `[x, y]` or `[x, y, z]`.
impl std::fmt::Debug for Coords {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.debug_list().entries(self.as_slice()).finish()
    }
}

impl Serialize for Coords {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.as_slice().serialize(s)
    }
}

impl<'de> Deserialize<'de> for Coords {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::{Error, SeqAccess, Visitor};
        struct Numbers;
        impl<'de> Visitor<'de> for Numbers {
            type Value = Coords;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("2 numbers [x, y], or 3 [x, y, z] in a 3D scene")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Coords, A::Error> {
                let (c, len) = up_to_three(seq, &self)?;
                if len < 2 {
                    return Err(A::Error::invalid_length(len, &self));
                }
                Ok(Coords { len: len as u8, c })
            }
        }
        d.deserialize_seq(Numbers)
    }
}

/// At most three numbers of a JSON array and how many there were; a fourth is refused
/// (`expected` says what the field takes) before anything is stored.
fn up_to_three<'de, A: serde::de::SeqAccess<'de>>(mut seq: A, expected: &dyn serde::de::Expected) -> Result<([f64; 3], usize), A::Error> {
    let mut c = [0.0; 3];
    let mut len = 0;
    while let Some(x) = seq.next_element::<f64>()? {
        if len == 3 {
            return Err(serde::de::Error::invalid_length(4, expected));
        }
        c[len] = x;
        len += 1;
    }
    Ok((c, len))
}

impl JsonSchema for Coords {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Coords".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({ "type": "array", "items": { "type": "number" }, "minItems": 2, "maxItems": 3 })
    }
}

/// A grain's spin (rad/s): a number, about z (in the plane, or in space), or in a 3D
/// scene three components `[wx, wy, wz]`.
#[derive(Clone, Copy, PartialEq)]
pub enum SpinSpec {
    AboutZ(f64),
    Vector([f64; 3]),
}

impl SpinSpec {
    pub fn iter(&self) -> std::slice::Iter<'_, f64> {
        match self {
            SpinSpec::AboutZ(w) => std::slice::from_ref(w).iter(),
            SpinSpec::Vector(w) => w.iter(),
        }
    }
    /// The spin about z (the plane's; a 3D spin's z component).
    pub fn z(&self) -> f64 {
        match *self {
            SpinSpec::AboutZ(w) => w,
            SpinSpec::Vector(w) => w[2],
        }
    }
    /// Its magnitude, rad/s.
    pub fn norm(&self) -> f64 {
        match *self {
            SpinSpec::AboutZ(w) => w.abs(),
            SpinSpec::Vector(w) => w[0].hypot(w[1]).hypot(w[2]),
        }
    }
    /// Given as three components.
    pub fn is_vector(&self) -> bool {
        matches!(self, SpinSpec::Vector(_))
    }
    /// The spin in dimension `D` (space: `[0, 0, w]` for a number).
    pub fn lift<D: Dim>(&self) -> D::Spin<f64> {
        match *self {
            SpinSpec::AboutZ(w) => D::spin_about_z(w),
            SpinSpec::Vector(w) => D::spin_of(w),
        }
    }
}

impl Default for SpinSpec {
    fn default() -> Self {
        SpinSpec::AboutZ(0.0)
    }
}

impl From<f64> for SpinSpec {
    fn from(w: f64) -> Self {
        SpinSpec::AboutZ(w)
    }
}

impl std::fmt::Debug for SpinSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            SpinSpec::AboutZ(w) => w.fmt(f),
            SpinSpec::Vector(w) => w.fmt(f),
        }
    }
}

/// As the scene writes it: a number, or `[wx, wy, wz]`.
impl std::fmt::Display for SpinSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        std::fmt::Debug::fmt(self, f)
    }
}

impl Serialize for SpinSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            SpinSpec::AboutZ(w) => s.serialize_f64(*w),
            SpinSpec::Vector(w) => w.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for SpinSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::{Error, SeqAccess, Visitor};
        struct Spin;
        impl<'de> Visitor<'de> for Spin {
            type Value = SpinSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a spin about z (a number), or 3 numbers [wx, wy, wz] in a 3D scene")
            }
            fn visit_f64<E: Error>(self, w: f64) -> Result<SpinSpec, E> {
                Ok(SpinSpec::AboutZ(w))
            }
            fn visit_i64<E: Error>(self, w: i64) -> Result<SpinSpec, E> {
                Ok(SpinSpec::AboutZ(w as f64))
            }
            fn visit_u64<E: Error>(self, w: u64) -> Result<SpinSpec, E> {
                Ok(SpinSpec::AboutZ(w as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<SpinSpec, A::Error> {
                let (w, len) = up_to_three(seq, &self)?;
                if len < 3 {
                    return Err(A::Error::invalid_length(len, &self));
                }
                Ok(SpinSpec::Vector(w))
            }
        }
        d.deserialize_any(Spin)
    }
}

impl JsonSchema for SpinSpec {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "SpinSpec".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({ "anyOf": [{ "type": "number" }, { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3 }] })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_read_two_or_three_numbers_and_write_them_back() {
        for text in ["[1.5,-2.0]", "[1.5,-2.0,3.0]"] {
            let c: Coords = serde_json::from_str(text).unwrap();
            assert_eq!(serde_json::to_string(&c).unwrap(), text);
        }
        for bad in ["[1.0]", "[]", "[1.0,2.0,3.0,4.0]", "3.0", "[1.0,\"a\"]"] {
            assert!(serde_json::from_str::<Coords>(bad).is_err(), "{bad}");
        }
        let c: Coords = serde_json::from_str("[1.0, 2.0]").unwrap();
        assert_eq!(c.lift::<crate::physics::dim::Space>(), nalgebra::Vector3::new(1.0, 2.0, 0.0));
        assert_eq!(format!("{c:?}"), format!("{:?}", [1.0, 2.0]));
    }

    #[test]
    fn a_spin_is_a_number_about_z_or_three_components() {
        let w: SpinSpec = serde_json::from_str("2").unwrap();
        assert_eq!(w.lift::<crate::physics::dim::Space>(), nalgebra::Vector3::new(0.0, 0.0, 2.0));
        assert_eq!(serde_json::to_string(&w).unwrap(), "2.0");
        let w: SpinSpec = serde_json::from_str("[1, 2, 3]").unwrap();
        assert_eq!(w.lift::<crate::physics::dim::Space>(), nalgebra::Vector3::new(1.0, 2.0, 3.0));
        for bad in ["[1, 2]", "[1, 2, 3, 4]", "\"a\""] {
            assert!(serde_json::from_str::<SpinSpec>(bad).is_err(), "{bad}");
        }
        let d: Dimension = serde_json::from_str("3").unwrap();
        assert_eq!(d, Dimension::Three);
        for bad in ["1", "4", "2.5", "-3", "\"3\""] {
            assert!(serde_json::from_str::<Dimension>(bad).is_err(), "{bad}");
        }
    }
}
