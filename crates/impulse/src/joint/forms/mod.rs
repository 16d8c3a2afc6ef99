//! Joint forms, one file each ([`JointForm`], `form.rs`), and their registration: the list
//! below makes each a [`JointKind`] variant, which names it in the builder, the scene format
//! (the joint's `"type"`, read and written by its form's name), snapshots and Python.
//!
//! Adding a form: a file here with a unit type implementing [`JointForm`], its `mod` line and
//! one entry in the list (docs/architecture.md, "Adding a joint form").

mod distance;
mod fixed;
mod form;
mod generic;
mod prismatic;
mod revolute;
mod spherical;

use std::fmt;
use std::sync::LazyLock;

use serde::de::{self, DeserializeSeed, EnumAccess, Unexpected, VariantAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

pub(crate) use form::{AnchorGeometry, JointForm, JointProblem};

/// Defines [`JointKind`] from the registered forms: one variant per form, in this order (the
/// order of [`JointKind::ALL`] and of the variant indices in snapshots).
macro_rules! register_forms {
    ($($(#[$doc:meta])* $variant:ident => $form:expr,)*) => {
        /// The kind of a joint: which of its six degrees of freedom (three translations and
        /// three rotations of body B's frame relative to body A's, along and about A's frame
        /// axes x, y, z) it constrains, and how. The joint's axis is its frame's x axis. Each
        /// kind is a form of `joint/forms/`; in scene files it is the joint's `"type"`, its
        /// [`JointKind::name`].
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum JointKind {
            $($(#[$doc])* $variant,)*
        }

        impl JointKind {
            /// Every kind, in registration order.
            pub const ALL: &'static [JointKind] = &[$(JointKind::$variant,)*];

            /// Its form.
            pub(crate) fn form(self) -> &'static dyn JointForm {
                match self {
                    $(JointKind::$variant => &$form,)*
                }
            }
        }
    };
}

register_forms! {
    /// All six degrees of freedom locked: the bodies move as one (Blender's "fixed", Box2D's
    /// weld joint).
    Fixed => fixed::Fixed,
    /// The anchors coincide; rotation is free (a ball-and-socket joint, Blender's "point").
    Spherical => spherical::Spherical,
    /// The anchors coincide and the only rotation is about the frame's x axis (a hinge), with
    /// an optional angle limit, spring and motor on it.
    Revolute => revolute::Revolute,
    /// The frames keep their orientation and the only translation is along the frame's x axis
    /// (a slider), with an optional distance limit, spring and motor on it.
    Prismatic => prismatic::Prismatic,
    /// The distance between the anchors stays within [min, max] (a rod when min = max, a rope
    /// when min = 0), with an optional spring towards a rest length; rotation is free.
    Distance => distance::Distance,
    /// Each of the six degrees of freedom locked, limited or free on its own
    /// ([`JointBuilder::dof`](crate::JointBuilder::dof)), with springs and motors on the
    /// free ones (PhysX's D6 joint, Jolt's six-DOF constraint, Blender's "generic").
    Generic => generic::Generic,
}

impl JointKind {
    /// Lower-case name, as in scene files (`"fixed"`, `"revolute"`, …).
    pub fn name(self) -> &'static str {
        self.form().name()
    }

    /// The kind of this name ([`JointKind::name`]), or `None`.
    pub fn from_name(name: &str) -> Option<JointKind> {
        Self::ALL.iter().copied().find(|kind| kind.name() == name)
    }
}

/// Every kind's name, in registration order (serde's list of variants).
static NAMES: LazyLock<Vec<&'static str>> =
    LazyLock::new(|| JointKind::ALL.iter().map(|kind| kind.name()).collect());

// Serialized and read as serde's derive does a unit-variant enum (the same bytes in scene files
// and snapshots, the same errors: "unknown variant `x`, expected one of …"), by form name.
impl Serialize for JointKind {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_unit_variant("JointKind", *self as u32, self.name())
    }
}

impl<'de> Deserialize<'de> for JointKind {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_enum("JointKind", NAMES.as_slice(), KindVisitor)
    }
}

struct KindVisitor;

impl<'de> Visitor<'de> for KindVisitor {
    type Value = JointKind;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("enum JointKind")
    }

    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<JointKind, A::Error> {
        let (kind, variant) = data.variant_seed(KindName)?;
        variant.unit_variant()?;
        Ok(kind)
    }
}

/// A kind's identifier: its name, or its index.
struct KindName;

impl<'de> DeserializeSeed<'de> for KindName {
    type Value = JointKind;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<JointKind, D::Error> {
        deserializer.deserialize_identifier(self)
    }
}

impl<'de> Visitor<'de> for KindName {
    type Value = JointKind;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("variant identifier")
    }

    fn visit_u64<E: de::Error>(self, index: u64) -> Result<JointKind, E> {
        usize::try_from(index)
            .ok()
            .and_then(|i| JointKind::ALL.get(i).copied())
            .ok_or_else(|| {
                E::invalid_value(
                    Unexpected::Unsigned(index),
                    &format!("variant index 0 <= i < {}", JointKind::ALL.len()).as_str(),
                )
            })
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<JointKind, E> {
        JointKind::from_name(name).ok_or_else(|| E::unknown_variant(name, NAMES.as_slice()))
    }

    fn visit_bytes<E: de::Error>(self, name: &[u8]) -> Result<JointKind, E> {
        self.visit_str(&String::from_utf8_lossy(name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_read_back_as_serde_derives_them() {
        for (index, &kind) in JointKind::ALL.iter().enumerate() {
            assert_eq!(kind as usize, index);
            assert_eq!(JointKind::from_name(kind.name()), Some(kind));
            let json = serde_json::to_string(&kind).unwrap();
            assert_eq!(json, format!("\"{}\"", kind.name()));
            assert_eq!(serde_json::from_str::<JointKind>(&json).unwrap(), kind);
            let mut cbor = Vec::new();
            ciborium::into_writer(&kind, &mut cbor).unwrap();
            assert_eq!(
                ciborium::from_reader::<JointKind, _>(&cbor[..]).unwrap(),
                kind
            );
        }
        let error = serde_json::from_str::<JointKind>("\"hinge\"").unwrap_err();
        assert!(
            error.to_string().starts_with(
                "unknown variant `hinge`, expected one of `fixed`, `spherical`, `revolute`, \
                 `prismatic`, `distance`, `generic`"
            ),
            "{error}"
        );
    }

    #[test]
    fn every_form_starts_with_its_main_dof_free() {
        for &kind in JointKind::ALL {
            let form = kind.form();
            if let Some(dof) = form.main_dof() {
                assert_eq!(
                    form.dofs()[dof.index()].mode,
                    crate::joint::AxisMode::Free,
                    "{}",
                    kind.name()
                );
            }
        }
    }
}
