//! World snapshots: the whole state a step reads, stored so that a restored world steps on to
//! the bit as the original would have (docs/snapshots.md).
//!
//! What is kept: the bodies (every field of [`Bodies`], shapes through Parry's own serde
//! support), the handles with their generations and free list, gravity, dt, settings, the step
//! count, the narrow phase's pairs (Parry's manifolds with their points, feature ids, normals
//! and our warm-start impulses and friction directions, Parry's per-pair work space, and what
//! the last manifold update was asked, so that the same updates are skipped), the broad
//! phase's leaf boxes and last pairs, the energy check's reference, the contact-event state,
//! and the last step's diagnostics. What is rebuilt: the broad phase's tree (from the leaf
//! boxes; the pairs do not depend on its shape), the islands (a function of the pairs), the
//! solvers' work spaces and SIMD layouts (functions of this step's rows), the speculative
//! margins and the inertia tensors (recomputed every step). `tests/snapshot.rs` checks that
//! a restored world's snapshot after N more steps is byte for byte the uninterrupted one's.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::shape::{Shape, SharedShape, TypedShape};
use serde::{Deserialize, Serialize};

use super::World;
use super::contact_events::ContactEvents;
use super::step::EnergyCheck;
use super::step::kinematic_script::Script;
use crate::body::{Bodies, BodyKind, Handles};
use crate::collision::broad_phase::{BroadPhase, BroadPhaseState};
use crate::collision::narrow_phase::{NarrowPhase, PairState};
use crate::diagnostics::StepDiagnostics;
use crate::error::SnapshotError;
use crate::joint::Joints;
use crate::scene::MeshData;
use crate::scene::validate::mesh_problem;
use crate::settings::SolverSettings;

/// The snapshot format this build writes. Raised whenever the stored state changes shape; a
/// snapshot of a version this build cannot read is refused ([`SnapshotError::VersionMismatch`]).
/// Version 3 added the joints; version 4 stores each distinct shape once, with each body's
/// index into them (a shape per body before); version 5 compresses the payload (DEFLATE).
/// It reads versions 2 ([`OLDEST_SNAPSHOT_FORMAT_VERSION`], as a world without joints) to 4.
pub const SNAPSHOT_FORMAT_VERSION: u32 = 5;

/// The first format version whose payload is compressed.
const FIRST_COMPRESSED_VERSION: u32 = 5;

/// The oldest snapshot format this build reads: version 2, the format before joints, whose
/// payload is version 3's without the `joints` field.
pub const OLDEST_SNAPSHOT_FORMAT_VERSION: u32 = 2;

/// Whether this build reads snapshots of format `version`.
fn readable(version: u32) -> bool {
    (OLDEST_SNAPSHOT_FORMAT_VERSION..=SNAPSHOT_FORMAT_VERSION).contains(&version)
}

/// The first bytes of a snapshot file.
const MAGIC: &[u8; 16] = b"IMPULSE-WORLD\0\0\0";
/// Magic, format version (u32), payload length (u64), payload CRC-32 (u32), little-endian.
const HEADER_LEN: usize = 16 + 4 + 8 + 4;

/// Everything that decides a world's future steps, as plain data: what [`World::snapshot`]
/// takes and [`World::from_snapshot`] restores. It implements serde's `Serialize` and
/// `Deserialize`, so any serde format can hold it; [`WorldSnapshot::to_bytes`] and
/// [`WorldSnapshot::write_file`] use impulse's own file format (a 32-byte header with the
/// format version and a CRC-32, then the snapshot in CBOR, RFC 8949, compressed by DEFLATE,
/// RFC 1951), which stores every `f32` with its exact bits.
///
/// A restored world steps on to the bit as the original would have, with the same build of
/// impulse on the same kind of CPU, on any number of threads (docs/snapshots.md says what is
/// and is not promised).
///
/// ```
/// use impulse::glam::Vec3;
/// use impulse::{BodyBuilder, SharedShape, SolverSettings, World, WorldSnapshot};
///
/// let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, SolverSettings::default())?;
/// world.insert(BodyBuilder::fixed(SharedShape::cuboid(5.0, 0.5, 5.0)))?;
/// world.insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).translation(Vec3::new(0.0, 2.0, 0.0)))?;
/// for _ in 0..30 {
///     world.step()?;
/// }
/// let bytes = world.snapshot()?.to_bytes()?;
/// let mut restored = World::from_snapshot(WorldSnapshot::from_bytes(&bytes)?)?;
/// world.step()?;
/// restored.step()?;
/// assert_eq!(world.poses()[1], restored.poses()[1]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Serialize, Deserialize)]
pub struct WorldSnapshot {
    format_version: u32,
    /// The `impulse` crate version that wrote the snapshot.
    engine_version: String,
    metadata: BTreeMap<String, String>,
    gravity: Vec3,
    dt: f32,
    settings: SolverSettings,
    step_count: u64,
    /// The world's seed (absent before it existed: 0).
    #[serde(default)]
    seed: u64,
    bodies: Bodies,
    handles: Handles,
    forces_pending: bool,
    broad_phase: BroadPhaseState,
    narrow_phase: Vec<PairState>,
    energy: EnergyCheck,
    contact_events: ContactEvents,
    diagnostics: StepDiagnostics,
    /// Simulated time (s), the clock of kinematic keyframes.
    time: f64,
    /// The position-based kinematic bodies' keyframes and pending targets.
    scripts: Vec<Script>,
    /// The joints, with their handles and warm-start impulses (absent from version 2: no
    /// joints).
    #[serde(default)]
    joints: Joints,
}

impl WorldSnapshot {
    /// Steps the world had taken when the snapshot was taken.
    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// The time step (s).
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// The version of the `impulse` crate that took the snapshot.
    pub fn engine_version(&self) -> &str {
        &self.engine_version
    }

    /// The caller's own notes, kept with the snapshot and never read by the engine (the
    /// `impulse` command stores the scene's name and the run's last step here).
    pub fn metadata(&self) -> &BTreeMap<String, String> {
        &self.metadata
    }

    /// The notes, to add to before writing.
    pub fn metadata_mut(&mut self) -> &mut BTreeMap<String, String> {
        &mut self.metadata
    }

    /// The snapshot in impulse's file format: the 16-byte magic `IMPULSE-WORLD\0\0\0`, the
    /// format version (u32), the payload's length in bytes (u64) and its CRC-32 (u32, the
    /// IEEE polynomial), all little-endian, then the payload: the snapshot in CBOR, compressed
    /// by DEFLATE (RFC 1951, `flate2`'s default level). The checksum is of the compressed
    /// bytes, so a damaged file is caught before anything is inflated.
    pub fn to_bytes(&self) -> Result<Vec<u8>, SnapshotError> {
        let mut bytes = Vec::with_capacity(HEADER_LEN + 64 * self.bodies.len());
        bytes.extend_from_slice(&[0; HEADER_LEN]);
        let cannot =
            |e: &dyn std::fmt::Display| SnapshotError::Decode(format!("cannot encode: {e}"));
        // CBOR comes in writes of a few bytes: buffered, the compressor sees large blocks.
        let encoder = flate2::write::DeflateEncoder::new(bytes, flate2::Compression::default());
        let mut writer = std::io::BufWriter::with_capacity(1 << 16, encoder);
        ciborium::into_writer(self, &mut writer).map_err(|e| cannot(&e))?;
        let encoder = writer.into_inner().map_err(|e| cannot(e.error()))?;
        let mut bytes = encoder.finish().map_err(|e| cannot(&e))?;
        let payload = &bytes[HEADER_LEN..];
        let (length, checksum) = (payload.len() as u64, crc32fast::hash(payload));
        let mut header = Vec::with_capacity(HEADER_LEN);
        header.extend_from_slice(MAGIC);
        header.extend_from_slice(&self.format_version.to_le_bytes());
        header.extend_from_slice(&length.to_le_bytes());
        header.extend_from_slice(&checksum.to_le_bytes());
        bytes[..HEADER_LEN].copy_from_slice(&header);
        Ok(bytes)
    }

    /// Reads a snapshot written by [`Self::to_bytes`]. Errors: [`SnapshotError::NotASnapshot`]
    /// (wrong magic), [`SnapshotError::VersionMismatch`], [`SnapshotError::Truncated`],
    /// [`SnapshotError::ChecksumMismatch`] (damaged), [`SnapshotError::Decode`] (bytes that
    /// pass the checksum but are not a snapshot, or a payload of another version than the
    /// header's). Never panics, whatever the bytes. A snapshot of an older readable format
    /// comes back as the current format ([`OLDEST_SNAPSHOT_FORMAT_VERSION`]).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, SnapshotError> {
        let magic_len = bytes.len().min(MAGIC.len());
        if bytes[..magic_len] != MAGIC[..magic_len] || bytes.is_empty() {
            return Err(SnapshotError::NotASnapshot);
        }
        let truncated = |expected: usize| SnapshotError::Truncated {
            expected: expected as u64,
            found: bytes.len() as u64,
        };
        if bytes.len() < 20 {
            return Err(truncated(HEADER_LEN));
        }
        let found = u32::from_le_bytes(bytes[16..20].try_into().unwrap_or_default());
        if !readable(found) {
            return Err(SnapshotError::VersionMismatch {
                found,
                oldest: OLDEST_SNAPSHOT_FORMAT_VERSION,
                supported: SNAPSHOT_FORMAT_VERSION,
            });
        }
        if bytes.len() < HEADER_LEN {
            return Err(truncated(HEADER_LEN));
        }
        let length = u64::from_le_bytes(bytes[20..28].try_into().unwrap_or_default());
        let expected = u32::from_le_bytes(bytes[28..32].try_into().unwrap_or_default());
        let payload = &bytes[HEADER_LEN..];
        if (payload.len() as u64) < length {
            return Err(SnapshotError::Truncated {
                expected: HEADER_LEN as u64 + length,
                found: bytes.len() as u64,
            });
        }
        if payload.len() as u64 > length {
            return Err(SnapshotError::Decode(format!(
                "{} bytes after the payload",
                payload.len() as u64 - length
            )));
        }
        let checksum = crc32fast::hash(payload);
        if checksum != expected {
            return Err(SnapshotError::ChecksumMismatch {
                expected,
                found: checksum,
            });
        }
        let decoded = if found >= FIRST_COMPRESSED_VERSION {
            ciborium::from_reader(std::io::BufReader::with_capacity(
                1 << 16,
                flate2::read::DeflateDecoder::new(payload),
            ))
        } else {
            ciborium::from_reader(payload)
        };
        let mut snapshot: WorldSnapshot =
            decoded.map_err(|e| SnapshotError::Decode(e.to_string()))?;
        // The header's version is outside the checksum: a payload of another version than the
        // header's is a damaged header (versions 2 and 3 differ in one bit).
        if snapshot.format_version != found {
            return Err(SnapshotError::Decode(format!(
                "the header says format version {found}, the payload {}",
                snapshot.format_version
            )));
        }
        // An older format decodes to the current one (version 2: no joints).
        snapshot.format_version = SNAPSHOT_FORMAT_VERSION;
        Ok(snapshot)
    }

    /// Writes [`Self::to_bytes`] to `path` atomically: to a temporary file beside it, which is
    /// flushed to disk and then renamed over `path`, so a reader (or a crash) never sees half
    /// a snapshot.
    pub fn write_file(&self, path: &Path) -> Result<(), SnapshotError> {
        let bytes = self.to_bytes()?;
        let io = |source| SnapshotError::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut temporary = path.as_os_str().to_owned();
        temporary.push(format!(".tmp{}", std::process::id()));
        let temporary = std::path::PathBuf::from(temporary);
        let written = std::fs::File::create(&temporary).and_then(|mut file| {
            file.write_all(&bytes)?;
            file.sync_all()
        });
        if let Err(e) = written.and_then(|()| std::fs::rename(&temporary, path)) {
            let _ = std::fs::remove_file(&temporary);
            return Err(io(e));
        }
        Ok(())
    }

    /// Reads a snapshot file written by [`Self::write_file`]; errors as
    /// [`Self::from_bytes`], or [`SnapshotError::Io`].
    pub fn read_file(path: &Path) -> Result<Self, SnapshotError> {
        let bytes = std::fs::read(path).map_err(|source| SnapshotError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_bytes(&bytes)
    }
}

impl World {
    /// The world's whole state between steps ([`WorldSnapshot`]). Errors only for a body whose
    /// shape is a user-defined Parry shape ([`SnapshotError::UnsupportedShape`]).
    pub fn snapshot(&self) -> Result<WorldSnapshot, SnapshotError> {
        if let Some(body) = self
            .bodies
            .shape
            .iter()
            .position(|s| matches!(s.as_typed_shape(), TypedShape::Custom(_)))
        {
            return Err(SnapshotError::UnsupportedShape { body });
        }
        Ok(WorldSnapshot {
            format_version: SNAPSHOT_FORMAT_VERSION,
            engine_version: env!("CARGO_PKG_VERSION").to_string(),
            metadata: BTreeMap::new(),
            gravity: self.gravity,
            dt: self.dt,
            settings: self.settings.clone(),
            step_count: self.step_count,
            seed: self.seed,
            bodies: self.bodies.clone(),
            handles: self.handles.clone(),
            forces_pending: self.forces_pending,
            broad_phase: self.broad_phase.state(),
            narrow_phase: self.narrow_phase.state(&self.bodies),
            energy: self.energy,
            contact_events: self.contact_events.clone(),
            diagnostics: self.diagnostics.clone(),
            time: self.time,
            scripts: self.scripts.clone(),
            joints: self.joints.clone(),
        })
    }

    /// The world a snapshot describes, which steps on exactly as the world it was taken from
    /// would have. [`World::parallel`] is `true` (threading never changes results); the last
    /// step's constraints, LCP and profile are empty until the next step. Errors:
    /// [`SnapshotError::VersionMismatch`], or [`SnapshotError::Invalid`] naming what would
    /// make the world unsteppable: a body array of the wrong length, a non-finite or
    /// out-of-range body value or shape, inconsistent handles, a pair naming a missing body,
    /// an invalid setting.
    pub fn from_snapshot(snapshot: WorldSnapshot) -> Result<World, SnapshotError> {
        if !readable(snapshot.format_version) {
            return Err(SnapshotError::VersionMismatch {
                found: snapshot.format_version,
                oldest: OLDEST_SNAPSHOT_FORMAT_VERSION,
                supported: SNAPSHOT_FORMAT_VERSION,
            });
        }
        let invalid = SnapshotError::Invalid;
        let mut world = World::new(snapshot.gravity, snapshot.dt, snapshot.settings)
            .map_err(|e| invalid(e.to_string()))?;
        let mut bodies = snapshot.bodies;
        if bodies.roughness.is_empty() {
            // Written before roughness existed: every surface smooth.
            bodies.roughness = vec![0.0; bodies.len()];
        }
        if bodies.impact_perturbation.is_empty() {
            // Written before impact perturbations existed: none.
            bodies.impact_perturbation = vec![0.0; bodies.len()];
        }
        if bodies.roughness_draws.is_empty() && bodies.roughness_draws_given.is_empty() {
            // Written before explicit roughness draws existed: none.
            bodies.roughness_draws = vec![Vec::new(); bodies.len()];
            bodies.roughness_draws_given = vec![0; bodies.len()];
        }
        bodies.check_lengths().map_err(invalid)?;
        // Bodies that share a shape (the table's) share its rebuilt one too.
        let mut rebuilt = std::collections::HashMap::new();
        for i in 0..bodies.len() {
            let address = std::sync::Arc::as_ptr(&bodies.shape[i].0) as *const () as usize;
            let shape = match rebuilt.get(&address) {
                Some(shape) => shape,
                None => {
                    let shape = rebuilt_composite(&bodies.shape[i])
                        .map_err(|e| invalid(format!("body {i}: shape: {e}")))?;
                    rebuilt.entry(address).or_insert(shape)
                }
            };
            if let Some(shape) = shape {
                bodies.shape[i] = shape.clone();
            }
        }
        check_bodies(&bodies).map_err(invalid)?;
        snapshot.handles.check(bodies.len()).map_err(invalid)?;
        world.broad_phase =
            BroadPhase::from_state(snapshot.broad_phase, bodies.len()).map_err(invalid)?;
        world.narrow_phase =
            NarrowPhase::from_state(snapshot.narrow_phase, &bodies).map_err(invalid)?;
        world.bodies = bodies;
        world.handles = snapshot.handles;
        world.step_count = snapshot.step_count;
        world.seed = snapshot.seed;
        world.forces_pending = snapshot.forces_pending;
        world.energy = snapshot.energy;
        world.contact_events = snapshot.contact_events;
        world.diagnostics = snapshot.diagnostics;
        if !snapshot.time.is_finite() || snapshot.time < 0.0 {
            return Err(invalid(format!(
                "the time {} is not finite and ≥ 0",
                snapshot.time
            )));
        }
        world.time = snapshot.time;
        for script in &snapshot.scripts {
            let Some(body) = world.handles.body(script.handle) else {
                return Err(invalid(format!(
                    "keyframes name a body that is not in the world ({:?})",
                    script.handle
                )));
            };
            if world.bodies.kind[body] != BodyKind::Kinematic {
                return Err(invalid(format!(
                    "body {body}: keyframes on a non-kinematic body"
                )));
            }
            let finite_pose = |p: &Pose| p.translation.is_finite() && p.rotation.is_finite();
            let mut last = 0.0f32;
            for k in &script.keyframes {
                let ordered = k.time.is_finite() && k.time > last;
                if !ordered || !k.translation.is_finite() || !k.rotation.is_finite() {
                    return Err(invalid(format!(
                        "body {body}: keyframes must have finite poses and increasing times > 0"
                    )));
                }
                last = k.time;
            }
            let poses = [
                Some(&script.initial),
                script.target.as_ref(),
                script.step_target.as_ref(),
            ];
            if !poses.into_iter().flatten().all(finite_pose) {
                return Err(invalid(format!(
                    "body {body}: a kinematic pose is not finite"
                )));
            }
        }
        world.scripts = snapshot.scripts;
        check_joints(&world, &snapshot.joints).map_err(invalid)?;
        world.joints = snapshot.joints;
        Ok(world)
    }

    /// Writes [`World::snapshot`] to `path` ([`WorldSnapshot::write_file`]: atomically).
    pub fn write_snapshot(&self, path: &Path) -> Result<(), SnapshotError> {
        self.snapshot()?.write_file(path)
    }

    /// Restores the world a snapshot file holds ([`WorldSnapshot::read_file`], then
    /// [`World::from_snapshot`]).
    pub fn read_snapshot(path: &Path) -> Result<World, SnapshotError> {
        World::from_snapshot(WorldSnapshot::read_file(path)?)
    }
}

/// A snapshot's joints before they are trusted: handles consistent, bodies in the world,
/// frames, impulses and reactions finite, degrees of freedom, stiffness and break thresholds
/// within the rules of `World::insert_joint`.
fn check_joints(world: &World, joints: &Joints) -> Result<(), String> {
    joints.handles.check(joints.joints.len())?;
    for (k, joint) in joints.joints.iter().enumerate() {
        let mut indices = [0; 2];
        for (index, body) in indices.iter_mut().zip([joint.body_a, joint.body_b]) {
            *index = world.handles.body(body).ok_or_else(|| {
                format!("joint {k} names a body that is not in the world ({body:?})")
            })?;
        }
        if indices[0] == indices[1] {
            return Err(format!("joint {k} joins a body to itself"));
        }
        let finite = joint.anchor_a.is_finite()
            && joint.anchor_b.is_finite()
            && joint.impulses.iter().flatten().all(|x| x.is_finite())
            && joint.break_sums.iter().all(|s| s.is_finite())
            && joint.force.is_finite()
            && joint.torque.is_finite();
        if !finite {
            return Err(format!(
                "joint {k}: an anchor, impulse or reaction is not finite"
            ));
        }
        // `insert_joint` stores unit quaternions; a rotation far from one would scale the rows.
        for rotation in [joint.rotation_a, joint.rotation_b] {
            if !(rotation.is_finite() && (rotation.length() - 1.0).abs() < 1e-3) {
                return Err(format!(
                    "joint {k}: a frame rotation is not a unit quaternion ({:?})",
                    rotation.to_array()
                ));
            }
        }
        crate::joint::rules::check_dofs(joint.kind, &joint.dofs)
            .and_then(|()| {
                crate::joint::rules::check_options(
                    joint.stiffness,
                    joint.break_force,
                    joint.break_torque,
                    (joint.break_window != 0.0).then_some(joint.break_window),
                )
            })
            .map_err(|p| format!("joint {k}: {}: {}", p.field, p.message))?;
    }
    Ok(())
}

/// The body values a step relies on, checked before a snapshot's bodies are trusted: finite
/// poses, velocities, forces and mass properties, materials in range, shapes valid for their
/// kind.
fn check_bodies(b: &Bodies) -> Result<(), String> {
    let finite3 = |v: &Vec3| v.is_finite();
    for i in 0..b.len() {
        let bad = |what: &str| Err(format!("body {i}: {what}"));
        let pose = &b.pose[i];
        if !pose.translation.is_finite()
            || !pose.rotation.is_finite()
            || (pose.rotation.length() - 1.0).abs() > 1e-3
        {
            return bad("the pose is not finite or its rotation not a unit quaternion");
        }
        let vectors = [
            &b.local_center_of_mass[i],
            &b.linear_velocity[i],
            &b.angular_velocity[i],
            &b.force[i],
            &b.torque[i],
        ];
        if !vectors.into_iter().all(finite3) || !b.local_inverse_inertia[i].is_finite() {
            return bad("a velocity, force or mass property is not finite");
        }
        let non_negative = [
            b.inverse_mass[i],
            b.friction[i],
            b.sleep_time[i],
            b.linear_damping[i],
            b.angular_damping[i],
        ];
        if !non_negative.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return bad("inverse mass, friction, sleep time or damping is negative or not finite");
        }
        if !(0.0..=1.0).contains(&b.restitution[i]) {
            return bad("restitution is outside [0, 1]");
        }
        if !(0.0..=crate::body::MAX_ROUGHNESS_DEGREES.to_radians()).contains(&b.roughness[i]) {
            return bad("roughness is outside [0, 30] degrees");
        }
        if !(0.0..=crate::body::MAX_IMPACT_PERTURBATION).contains(&b.impact_perturbation[i]) {
            return bad("impact_perturbation is outside [0, 1]");
        }
        if crate::body::rules::roughness_draws(&b.roughness_draws[i]).is_err() {
            return bad("roughness_draws are too many or not finite");
        }
        if b.roughness_draws_given[i] as usize > b.roughness_draws[i].len() {
            return bad("roughness_draws_given exceeds the roughness draws");
        }
        let shape = &b.shape[i];
        if b.kind[i] != BodyKind::Static && shape.as_halfspace().is_some() {
            return bad("a half-space must be a static body");
        }
        if b.kind[i] == BodyKind::Particle && shape.as_ball().is_none() {
            return bad("a particle must be a sphere");
        }
        check_shape(shape)
            .and_then(|()| crate::body::rules::shape_extent(shape))
            .map_err(|e| format!("body {i}: shape: {e}"))?;
        // The step keeps locked velocity components at zero only if they start there.
        let locked = b.locked_axes[i];
        if !locked.is_empty() && !b.kind[i].is_dynamic() {
            return bad("only a dynamic body or a particle may have locked axes");
        }
        if locked.lock_linear_velocity(b.linear_velocity[i]) != b.linear_velocity[i]
            || locked.lock_angular_velocity(b.angular_velocity[i]) != b.angular_velocity[i]
        {
            return bad("a velocity has a non-zero component along a locked axis");
        }
    }
    Ok(())
}

/// A composite shape (triangle mesh, height field, compound) built again from its defining
/// data once that data is checked; `None` for any other shape. Parry decodes a composite
/// shape's derived data too (its BVH, topology, pseudo-normals), which a damaged snapshot could
/// leave inconsistent with the triangles or parts it indexes; built again, it cannot be.
/// Parry's builders are deterministic, so an intact snapshot gives back the same shape.
fn rebuilt_composite(shape: &SharedShape) -> Result<Option<SharedShape>, String> {
    use parry3d::shape::{Compound, HeightField, TriMesh};
    let rebuilt = match shape.as_typed_shape() {
        TypedShape::TriMesh(mesh) => {
            let data = MeshData {
                vertices: mesh.vertices().iter().map(|v| v.to_array()).collect(),
                indices: mesh.indices().to_vec(),
            };
            if let Some(problem) = mesh_problem(&data) {
                return Err(format!("triangle mesh: {}", problem.message()));
            }
            let rebuilt = TriMesh::with_flags(mesh.vertices().to_vec(), data.indices, mesh.flags())
                .map_err(|e| format!("triangle mesh: {e}"))?;
            SharedShape::new(rebuilt)
        }
        TypedShape::HeightField(field) => {
            let heights = field.heights();
            let scale = field.scale();
            if heights.nrows() < 2
                || heights.ncols() < 2
                || heights.nrows().checked_mul(heights.ncols()) != Some(heights.data().len())
                || !heights.data().iter().all(|h| h.is_finite())
                || !(scale.is_finite() && scale.cmpgt(Vec3::ZERO).all())
            {
                return Err(
                    "height field: fewer than 2 × 2 heights, a grid whose size is not its \
                     rows times its columns, a height not finite, or a scale not finite and \
                     positive"
                        .into(),
                );
            }
            SharedShape::new(HeightField::with_flags(
                heights.clone(),
                scale,
                field.flags(),
            ))
        }
        TypedShape::Compound(compound) => {
            let parts = compound.shapes();
            if parts.is_empty() {
                return Err("a compound without parts".into());
            }
            for (k, (pose, part)) in parts.iter().enumerate() {
                let pose_ok = pose.translation.is_finite()
                    && pose.rotation.is_finite()
                    && (pose.rotation.length() - 1.0).abs() <= 1e-3;
                if !pose_ok || part.as_composite_shape().is_some() {
                    return Err(format!(
                        "compound part {k}: a pose not finite, or a composite part"
                    ));
                }
                check_shape(part).map_err(|e| format!("compound part {k}: {e}"))?;
            }
            SharedShape::new(Compound::with_flags(parts.to_vec(), compound.flags(), None))
        }
        _ => return Ok(None),
    };
    Ok(Some(rebuilt))
}

/// Checks the sizes of the shapes impulse builds (positive and finite), rounded shapes'
/// border radii and inner shapes, and a convex polyhedron's index arrays (every index in
/// range), so that contact generation cannot index out of bounds. Composite shapes are checked
/// and built again by [`rebuilt_composite`]; other Parry shapes are taken as Parry decoded
/// them.
fn check_shape(shape: &SharedShape) -> Result<(), String> {
    match crate::body::rules::rounded_parts(shape.as_ref()) {
        Some((inner, border_radius)) if border_radius.is_finite() && border_radius > 0.0 => {
            check_shape_of(inner)
        }
        Some(_) => Err("a border radius is not finite and positive".to_string()),
        None => check_shape_of(shape.as_ref()),
    }
}

/// [`check_shape`] of a shape that is not rounded.
fn check_shape_of(shape: &dyn Shape) -> Result<(), String> {
    let positive = |x: f32| x.is_finite() && x > 0.0;
    let ok = match shape.as_typed_shape() {
        TypedShape::Ball(ball) => positive(ball.radius),
        TypedShape::Cuboid(cuboid) => cuboid.half_extents.to_array().into_iter().all(positive),
        TypedShape::Capsule(capsule) => {
            positive(capsule.radius)
                && capsule.segment.a.is_finite()
                && capsule.segment.b.is_finite()
        }
        TypedShape::Cylinder(c) => positive(c.half_height) && positive(c.radius),
        TypedShape::Cone(c) => positive(c.half_height) && positive(c.radius),
        TypedShape::HalfSpace(h) => h.normal.is_finite() && (h.normal.length() - 1.0).abs() < 1e-3,
        TypedShape::ConvexPolyhedron(hull) => return check_polyhedron(hull),
        _ => true,
    };
    if ok {
        Ok(())
    } else {
        Err("a size is not finite and positive".into())
    }
}

fn check_polyhedron(hull: &parry3d::shape::ConvexPolyhedron) -> Result<(), String> {
    let (points, faces, edges) = (hull.points(), hull.faces(), hull.edges());
    let faces_of_vertex = hull.faces_adj_to_vertex();
    let (vertices_of_face, edges_of_face) = (hull.vertices_adj_to_face(), hull.edges_adj_to_face());
    let within = |first: u32, count: u32, len: usize| first as usize + count as usize <= len;
    let all_below = |indices: &[u32], len: usize| indices.iter().all(|&k| (k as usize) < len);
    let ok = points.len() >= 4
        && points.iter().all(|p| p.is_finite())
        && hull.vertices().len() == points.len()
        && hull.vertices().iter().all(|v| {
            within(
                v.first_adj_face_or_edge,
                v.num_adj_faces_or_edge,
                faces_of_vertex.len(),
            )
        })
        && faces.iter().all(|f| {
            f.normal.is_finite()
                && f.num_vertices_or_edges > 0
                && within(
                    f.first_vertex_or_edge,
                    f.num_vertices_or_edges,
                    vertices_of_face.len(),
                )
                && within(
                    f.first_vertex_or_edge,
                    f.num_vertices_or_edges,
                    edges_of_face.len(),
                )
        })
        // An edge's face indices are not checked: Parry's own hull of points all but
        // coplanar can leave one past the faces (beside a degenerate triangle), and the
        // engine's edge search leaves such edges out (`collision::faces`).
        && edges
            .iter()
            .all(|e| e.dir.is_finite() && all_below(&e.vertices, points.len()))
        && all_below(faces_of_vertex, faces.len())
        && all_below(vertices_of_face, points.len())
        && all_below(edges_of_face, edges.len());
    if ok {
        Ok(())
    } else {
        Err("the convex polyhedron's points or index arrays are inconsistent".into())
    }
}
