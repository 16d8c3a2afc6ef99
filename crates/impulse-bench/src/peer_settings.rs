//! The settings each peer engine runs with: plain data, named and listed without the engines
//! compiled in (the command line parses them and the front lists its grids in any build); each
//! engine's module turns them into the engine's own parameters.

/// Engine name of Rapier's rows and front points.
pub const RAPIER: &str = "rapier";
/// Engine name of Box3D's rows and front points.
pub const BOX3D: &str = "box3d";
/// Engine name of Jolt's rows and front points.
pub const JOLT: &str = "jolt";

/// The peer engines, in the order tables list them.
pub const PEERS: [&str; 3] = [RAPIER, BOX3D, JOLT];

/// Cargo feature of impulse-bench that compiles each peer in, by engine name.
pub fn peer_feature(engine: &str) -> &'static str {
    match engine {
        BOX3D => "box3d",
        JOLT => "jolt",
        _ => "rapier",
    }
}

/// True when impulse-bench was built with `engine`'s feature.
pub fn peer_compiled(engine: &str) -> bool {
    let compiled = [
        (RAPIER, cfg!(feature = "rapier")),
        (BOX3D, cfg!(feature = "box3d")),
        (JOLT, cfg!(feature = "jolt")),
    ];
    compiled.iter().any(|&(peer, on)| on && peer == engine)
}

/// The error when a peer is asked for in a build without its feature.
pub fn missing_peer(engine: &str) -> String {
    let feature = peer_feature(engine);
    format!(
        "{engine} was asked for, but impulse-bench was built without the `{feature}` feature; \
         build it with `--features {feature}`, e.g. \
         `cargo run --release -p impulse-bench --features rapier,box3d,jolt -- ...`"
    )
}

/// Rapier with other settings than its defaults, to compare the engines at similar quality.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RapierVariant {
    /// `IntegrationParameters::num_solver_iterations` (Rapier's substeps; default 4).
    pub substeps: usize,
    /// `contact_softness.natural_frequency` (Hz; default 30); contacts with a fixed body get
    /// twice this (`static_contact_softness`), as in Rapier's defaults.
    pub contact_hz: f32,
    /// `FrictionModel::Coulomb` (one friction disc per contact point, impulse's formulation)
    /// instead of Rapier's default `Simplified` (one per manifold of up to four points, plus a
    /// twist row).
    pub coulomb_friction: bool,
}

impl RapierVariant {
    /// Engine name of its rows, e.g. `rapier 8×120Hz` or `rapier 4×30Hz coulomb`.
    pub fn engine_name(&self) -> String {
        format!("rapier {}", self.setting_name())
    }

    /// The settings alone, e.g. `8×120Hz` or `4×30Hz coulomb` (substeps × contact spring
    /// frequency, and the friction model when it is Coulomb).
    pub fn setting_name(&self) -> String {
        let friction = if self.coulomb_friction {
            " coulomb"
        } else {
            ""
        };
        format!("{}×{}Hz{friction}", self.substeps, self.contact_hz)
    }
}

#[cfg(feature = "rapier")]
impl RapierVariant {
    /// Rapier's default integration parameters with this variant's substeps and springs.
    pub fn integration_parameters(&self) -> rapier3d::prelude::IntegrationParameters {
        let mut params = rapier3d::prelude::IntegrationParameters {
            num_solver_iterations: self.substeps,
            ..Default::default()
        };
        params.contact_softness.natural_frequency = self.contact_hz;
        params.static_contact_softness.natural_frequency = 2.0 * self.contact_hz;
        if self.coulomb_friction {
            params.friction_model = rapier3d::prelude::FrictionModel::Coulomb;
        }
        params
    }
}

impl std::str::FromStr for RapierVariant {
    type Err = String;

    /// `SUBSTEPS:HZ[:coulomb]`, e.g. `8:120` or `4:30:coulomb`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (s, coulomb_friction) = match s.rsplit_once(':') {
            Some((rest, "coulomb")) => (rest, true),
            _ => (s, false),
        };
        let (substeps, hz) = s.split_once(':').ok_or_else(|| {
            format!("expected SUBSTEPS:HZ[:coulomb] (e.g. 8:120 or 4:30:coulomb), got \"{s}\"")
        })?;
        let substeps: usize = substeps
            .trim()
            .parse()
            .map_err(|e| format!("substeps \"{substeps}\": {e}"))?;
        let contact_hz: f32 = hz.trim().parse().map_err(|e| format!("hz \"{hz}\": {e}"))?;
        if substeps == 0 || !(contact_hz.is_finite() && contact_hz > 0.0) {
            return Err(format!("substeps must be ≥ 1 and hz > 0, got \"{s}\""));
        }
        Ok(Self {
            substeps,
            contact_hz,
            coulomb_friction,
        })
    }
}

impl Default for RapierVariant {
    /// Rapier's defaults: 4 substeps, 30 Hz, simplified friction.
    fn default() -> Self {
        Self {
            substeps: 4,
            contact_hz: 30.0,
            coulomb_friction: false,
        }
    }
}

/// Box3D's settings: what `b3World_Step` and `b3WorldDef` take. Everything else is Box3D's
/// default (`b3DefaultWorldDef`: contact damping ratio 10, contact push-out speed 3 m/s,
/// continuous collision on, warm starting on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Box3dSetting {
    /// `subStepCount` of `b3World_Step` (Box3D's default 4).
    pub substeps: u32,
    /// `b3WorldDef::contactHertz` (Hz; default 30). Box3D clamps it to an eighth of the substep
    /// rate, min(hertz, substeps / (8 dt)), and gives contacts with a static body twice the
    /// clamped value (with half the damping ratio).
    pub contact_hz: f32,
}

impl Default for Box3dSetting {
    /// Box3D's defaults: 4 substeps, 30 Hz.
    fn default() -> Self {
        Self {
            substeps: 4,
            contact_hz: 30.0,
        }
    }
}

impl Box3dSetting {
    /// The setting's name, e.g. `4×30Hz` (substeps × contact hertz asked for).
    pub fn setting_name(&self) -> String {
        format!("{}×{}Hz", self.substeps, self.contact_hz)
    }

    /// The contact hertz Box3D runs with at time step `dt` (s): the asked-for hertz, clamped
    /// to an eighth of the substep rate.
    pub fn effective_contact_hz(&self, dt: f32) -> f32 {
        // As Box3D computes it (physics_world.c): the substep rate is substeps × (1 / dt).
        let substep_rate = self.substeps.max(1) as f32 * (1.0 / dt);
        self.contact_hz.min(0.125 * substep_rate)
    }
}

/// Jolt's settings: the collision steps of `PhysicsSystem::Update` and the solver iterations of
/// `PhysicsSettings`. Everything else is Jolt's default (Baumgarte 0.2, penetration slop 2 cm,
/// speculative contact distance 2 cm, warm starting on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JoltSetting {
    /// `inCollisionSteps` of `PhysicsSystem::Update`: collision detection and solve rounds per
    /// step, each over dt / collision_steps (Jolt's default 1 at 60 Hz).
    pub collision_steps: u32,
    /// `PhysicsSettings::mNumVelocitySteps` (default 10).
    pub velocity_steps: u32,
    /// `PhysicsSettings::mNumPositionSteps` (default 2).
    pub position_steps: u32,
}

impl Default for JoltSetting {
    /// Jolt's defaults: 1 collision step, 10 velocity and 2 position iterations.
    fn default() -> Self {
        Self {
            collision_steps: 1,
            velocity_steps: 10,
            position_steps: 2,
        }
    }
}

impl JoltSetting {
    /// The setting's name, e.g. `c1 v10 p2` (collision steps, velocity and position
    /// iterations).
    pub fn setting_name(&self) -> String {
        format!(
            "c{} v{} p{}",
            self.collision_steps, self.velocity_steps, self.position_steps
        )
    }
}

/// One peer engine with one setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PeerSetting {
    /// Rapier.
    Rapier(RapierVariant),
    /// Box3D.
    Box3d(Box3dSetting),
    /// Jolt.
    Jolt(JoltSetting),
}

impl PeerSetting {
    /// The engine's name: [`RAPIER`], [`BOX3D`] or [`JOLT`].
    pub fn engine(&self) -> &'static str {
        match self {
            PeerSetting::Rapier(_) => RAPIER,
            PeerSetting::Box3d(_) => BOX3D,
            PeerSetting::Jolt(_) => JOLT,
        }
    }

    /// The setting's name in its engine's grid.
    pub fn setting_name(&self) -> String {
        match self {
            PeerSetting::Rapier(v) => v.setting_name(),
            PeerSetting::Box3d(s) => s.setting_name(),
            PeerSetting::Jolt(s) => s.setting_name(),
        }
    }
}
