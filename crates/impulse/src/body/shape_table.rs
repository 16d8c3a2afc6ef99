//! The bodies' shapes as serde stores them: each distinct shape once, and per body the index
//! of its shape. Bodies of one mesh share its convex decomposition (one compound of a few
//! dozen hulls, hundreds of kilobytes), so storing a shape per body made a snapshot of 500 mugs
//! hundreds of megabytes; the table stores the mug once, and a restored world shares it in
//! memory as the original did.
//!
//! Shapes are one when they are the same allocation or serialize to the same bytes (CBOR, the
//! snapshot's own encoding: every `f32` exact), so equal shapes built apart (the cubes of a
//! pour) are stored once too. Reads the older form, a shape per body, as well.

use std::collections::HashMap;
use std::sync::Arc;

use parry3d::shape::SharedShape;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The stored form: `shapes` the distinct shapes in order of first use, `of_body[i]` body i's
/// index into them.
#[derive(Serialize, Deserialize)]
struct ShapeTable {
    shapes: Vec<SharedShape>,
    of_body: Vec<u32>,
}

/// What a snapshot holds: the table, or (written before the table existed) a shape per body.
#[derive(Deserialize)]
#[serde(untagged)]
enum StoredShapes {
    Table(ShapeTable),
    PerBody(Vec<SharedShape>),
}

/// Serde's `serialize_with` for [`super::Bodies`]' shapes: the table of distinct shapes.
pub(super) fn serialize<S: Serializer>(
    shapes: &[SharedShape],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    let mut table = ShapeTable {
        shapes: Vec::new(),
        of_body: Vec::with_capacity(shapes.len()),
    };
    let mut by_address: HashMap<usize, u32> = HashMap::new();
    let mut by_bytes: HashMap<Vec<u8>, u32> = HashMap::new();
    for shape in shapes {
        let address = Arc::as_ptr(&shape.0) as *const () as usize;
        let index = match by_address.get(&address) {
            Some(&index) => index,
            None => {
                let mut bytes = Vec::new();
                ciborium::into_writer(shape, &mut bytes).map_err(serde::ser::Error::custom)?;
                let next = table.shapes.len() as u32;
                let index = *by_bytes.entry(bytes).or_insert(next);
                if index == next {
                    table.shapes.push(shape.clone());
                }
                by_address.insert(address, index);
                index
            }
        };
        table.of_body.push(index);
    }
    table.serialize(serializer)
}

/// Serde's `deserialize_with` for [`super::Bodies`]' shapes: a body per index of the table,
/// bodies of one index sharing one shape. An index out of range is an error.
pub(super) fn deserialize<'de, D: Deserializer<'de>>(
    deserializer: D,
) -> Result<Vec<SharedShape>, D::Error> {
    match StoredShapes::deserialize(deserializer)? {
        StoredShapes::PerBody(shapes) => Ok(shapes),
        StoredShapes::Table(table) => table
            .of_body
            .iter()
            .enumerate()
            .map(|(body, &index)| {
                table.shapes.get(index as usize).cloned().ok_or_else(|| {
                    serde::de::Error::custom(format!(
                        "body {body}: shape index {index} is not below the {} stored shapes",
                        table.shapes.len()
                    ))
                })
            })
            .collect(),
    }
}
