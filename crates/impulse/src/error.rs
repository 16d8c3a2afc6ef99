//! Errors of building a world and of stepping it.

use thiserror::Error;

/// A body or setting that cannot be simulated. Raised before any step is taken.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum WorldError {
    /// A body's description is invalid (`body` is its index in scene order).
    #[error("body {body}{}: {field}: {message}", name.as_ref().map(|n| format!(" (\"{n}\")")).unwrap_or_default())]
    InvalidBody {
        /// Index of the body in scene order.
        body: usize,
        /// The body's name, if it has one.
        name: Option<String>,
        /// Field path inside the body, e.g. `shape.radius`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A joint's description is invalid (`joint` is its index in insertion or scene order).
    #[error("joint {joint}{}: {field}: {message}", name.as_ref().map(|n| format!(" (\"{n}\")")).unwrap_or_default())]
    InvalidJoint {
        /// Index of the joint (the scene's `joints` order, or the number of joints before it).
        joint: usize,
        /// The joint's name, if it has one.
        name: Option<String>,
        /// Field path inside the joint, e.g. `limits.lower`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A handle names no joint of this world (removed, or another world's handle).
    #[error("no joint {0:?} in this world (removed, or another world's handle)")]
    UnknownJoint(crate::joint::JointHandle),
    /// A handle names no body of this world (the body was removed, or the handle is another
    /// world's).
    #[error("no body {0:?} in this world (removed, or another world's handle)")]
    UnknownBody(crate::body::BodyHandle),
    /// The bodies start piled into one another: their bounding boxes overlap in more pairs than
    /// [`crate::settings::MAX_PAIRS_PER_BODY`] per body ([`crate::World::from_scene`]), e.g. 3,000
    /// coincident spheres. Displayed as `3000 bodies overlap at (0, 0, 0) (around body 0): …`.
    #[error(
        "{bodies} bodies overlap at ({}, {}, {}) (around body {body}): their bounding boxes \
         overlap in more than {limit} pairs ({} per body), a pile no step can take apart; \
         spread the bodies out",
        at[0], at[1], at[2], crate::settings::MAX_PAIRS_PER_BODY
    )]
    Crowded {
        /// Bodies whose boxes meet the densest body's box, that body included.
        bodies: usize,
        /// The densest body's index.
        body: usize,
        /// Its centre of mass `[x, y, z]` (m).
        at: [f32; 3],
        /// The most pairs allowed: [`crate::settings::MAX_PAIRS_PER_BODY`] × the bodies.
        limit: usize,
    },
    /// A setting is out of range: the time step or gravity (displayed as `<field>: <message>`,
    /// e.g. `dt: must be finite and > 0, got 0`), or a solver setting
    /// ([`crate::SolverSettings::validate`]; displayed as `solver.<field>: <message>`).
    #[error(transparent)]
    InvalidSettings(#[from] crate::settings::SettingError),
}

/// A step that could not be completed. Settings and bodies are checked when they enter the
/// world ([`WorldError`]), never by the step. The world is left as it was after the last good
/// step only for errors raised before integration; a blow-up is detected after integration and the
/// offending state is kept so it can be inspected.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StepError {
    /// A body's position became non-finite, or its linear or angular speed non-finite or
    /// beyond its bound ([`crate::settings::WorldLimits::max_linear_speed`] in m/s,
    /// [`crate::settings::WorldLimits::max_angular_speed`] in rad/s). Displayed as, e.g.,
    /// `simulation blew up at step 3: body 1 has angular speed = 2e7 rad/s, not finite or
    /// beyond solver.max_angular_speed = 10000000 rad/s`.
    #[error(
        "simulation blew up at step {step}: body {body} has {quantity} = {value} {unit}, not \
         finite or beyond solver.{setting} = {bound} {unit}"
    )]
    BlowUp {
        /// The step (counted from 1) during which the blow-up happened.
        step: u64,
        /// The first offending body.
        body: crate::body::BodyHandle,
        /// `position` (its distance from the origin), `linear speed` or `angular speed`.
        quantity: &'static str,
        /// The offending magnitude (may be NaN or infinite).
        value: f32,
        /// The quantity's unit: `m`, `m/s` or `rad/s`.
        unit: &'static str,
        /// The solver setting that holds the bound: `max_distance` (a position only blows up
        /// when it is not finite; beyond the bound a body leaves the world),
        /// `max_linear_speed` or `max_angular_speed`.
        setting: &'static str,
        /// The bound (in `unit`).
        bound: f32,
    },
    /// The bodies' mechanical energy (kinetic + gravitational) rose more than
    /// [`crate::world::BLOW_UP_ENERGY_PER_KG`] per kilogram of moving mass above its lowest
    /// since the last edit: the solve created energy, which contacts cannot.
    #[error(
        "simulation blew up at step {step}: mechanical energy rose {gain_per_kg} J per kg of \
         moving mass above its lowest (bound {bound}); fastest body {} at {speed} m/s",
        fastest_body.map_or("none".to_string(), |h| h.to_string())
    )]
    EnergyBlowUp {
        /// The step (counted from 1) during which the bound was crossed.
        step: u64,
        /// Energy gained per kilogram of moving mass (J/kg); may be NaN.
        gain_per_kg: f32,
        /// The bound it crossed (J/kg).
        bound: f32,
        /// The fastest body, where to start looking (`None` in a world without bodies).
        fastest_body: Option<crate::body::BodyHandle>,
        /// Its speed (m/s).
        speed: f32,
    },
    /// Parry cannot generate contacts for this pair of shapes.
    #[error("no contact generator for the shapes of bodies {body1} and {body2}")]
    UnsupportedShapePair {
        /// The first body.
        body1: crate::body::BodyHandle,
        /// The second body.
        body2: crate::body::BodyHandle,
    },
}

/// A world snapshot that cannot be written or restored ([`crate::world::WorldSnapshot`]).
#[derive(Debug, Error)]
pub enum SnapshotError {
    /// The snapshot file could not be read or written.
    #[error("snapshot file {path}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The bytes do not start with the snapshot header: not a snapshot file.
    #[error("not an impulse world snapshot (the file does not start with \"IMPULSE-WORLD\")")]
    NotASnapshot,
    /// The snapshot was written in a format version this build does not read (it reads
    /// `oldest` to `supported`).
    #[error(
        "snapshot format version {found}, but this build of impulse reads versions {oldest} to \
         {supported} (snapshots are not portable across impulse versions)"
    )]
    VersionMismatch {
        /// The file's format version.
        found: u32,
        /// The oldest version this build reads
        /// ([`crate::world::OLDEST_SNAPSHOT_FORMAT_VERSION`]).
        oldest: u32,
        /// The version this build writes, the newest it reads
        /// ([`crate::world::SNAPSHOT_FORMAT_VERSION`]).
        supported: u32,
    },
    /// Fewer bytes than the header promised: the file was cut short.
    #[error("snapshot truncated: {found} bytes where the header promises {expected}")]
    Truncated {
        /// Bytes the file should have: the header's 32, and then the payload length it gives.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// The payload's CRC-32 differs from the header's: the file was damaged.
    #[error("snapshot corrupt: payload checksum {found:08x}, header says {expected:08x}")]
    ChecksumMismatch {
        /// CRC-32 in the header.
        expected: u32,
        /// CRC-32 of the payload as read.
        found: u32,
    },
    /// The payload is not a valid encoding of a snapshot.
    #[error("snapshot corrupt: cannot decode the payload: {0}")]
    Decode(String),
    /// The snapshot decodes but describes a world that cannot be stepped (a body index out
    /// of range, a non-finite pose, an invalid setting, …); the message says what.
    #[error("snapshot invalid: {0}")]
    Invalid(String),
    /// A body's shape cannot be stored (a user-defined Parry shape has no serialised form).
    #[error("body {body}: its shape has no serialised form (a user-defined Parry shape)")]
    UnsupportedShape {
        /// Dense index of the body.
        body: usize,
    },
}
