//! The variation options of the commands that load a scene (`run`, `render`, `export`,
//! `lcp dump`): field overrides and a seeded jitter, applied by
//! `impulse::scene::Variation` (docs/scene-format.md, "Overrides and variations").

use std::path::Path;

use anyhow::Result;
use clap::Args;
use impulse::Scene;
use impulse::scene::{Jitter, ORIGIN_PREFIX, Override, SceneError, Variation};

/// Overrides and seeded jitter of a scene.
#[derive(Args, Clone, Debug, Default)]
pub struct VariationArgs {
    /// Change a field of the scene by its JSON path, validated as the scene file is, e.g.
    /// `--set materials.wood.friction=0.2`, `--set 'bodies[3].linear_velocity=[0,0,-5]'`,
    /// `--set solver.substeps=12`. VALUE is JSON, or else a string. Repeatable; applied in
    /// order, after the command's `--preset` and solver options where it has them, so it wins
    /// over them.
    #[arg(long = "set", value_name = "PATH=VALUE", allow_hyphen_values = true)]
    pub set: Vec<String>,
    /// Seed of the jitter and, when not 0, the scene's `seed` (the draws of rough and
    /// impact-perturbed materials), as `--set seed=K` sets it: the same seed gives the same
    /// scene to the bit on any machine.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Move each dynamic body by an offset uniform in a ball of this radius (m).
    #[arg(
        long,
        value_name = "M",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub jitter_position: f32,
    /// Turn each dynamic body by an angle uniform in [0, DEG] (degrees, ≤ 180) about a
    /// uniformly random axis.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub jitter_angle: f32,
    /// Add to each dynamic body's velocity an offset uniform in a ball of this radius (m/s).
    #[arg(
        long,
        value_name = "V",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub jitter_velocity: f32,
}

impl VariationArgs {
    /// Whether no option was given (the scene is used as it is).
    pub fn is_empty(&self) -> bool {
        self.set.is_empty() && self.seed == 0 && Jitter::is_none(&self.jitter())
    }

    fn jitter(&self) -> Jitter {
        Jitter {
            position: self.jitter_position,
            angle_degrees: self.jitter_angle,
            velocity: self.jitter_velocity,
        }
    }

    /// `scene` (loaded from the argument `scene_arg`: a file, whose directory mesh files
    /// are read from, or a built-in name) with the overrides and the jitter applied.
    ///
    /// # Errors
    /// A malformed `--set`, an override the scene format refuses, or a jitter out of range:
    /// the message names the `--set` (or `--jitter-…` option) and the field.
    pub fn apply(&self, scene: Scene, scene_arg: &str) -> Result<Scene> {
        if self.is_empty() {
            return Ok(scene);
        }
        let overrides = self
            .set
            .iter()
            .map(|text| Override::parse(text))
            .collect::<Result<Vec<_>, _>>()
            .map_err(command_line_error)?;
        let variation = Variation {
            overrides,
            seed: self.seed,
            jitter: self.jitter(),
        };
        let path = Path::new(scene_arg);
        let directory = if path.is_file() {
            path.parent().unwrap_or(Path::new(""))
        } else {
            Path::new("")
        };
        variation
            .apply_in(&scene, directory)
            .map_err(command_line_error)
    }
}

/// `error` as the command line names its cause: `--set PATH=VALUE` for an override
/// (`--set A --set B` when several may be the cause), `--jitter-position` and so on for the
/// jitter.
fn command_line_error(mut error: SceneError) -> anyhow::Error {
    if let Some(origin) = &error.origin {
        let renamed = if let Some(list) = origin.strip_prefix(&format!("{ORIGIN_PREFIX}s ")) {
            Some(
                list.split(", ")
                    .map(|text| format!("--set {text}"))
                    .collect::<Vec<_>>()
                    .join(" "),
            )
        } else if let Some(text) = origin.strip_prefix(&format!("{ORIGIN_PREFIX} ")) {
            Some(format!("--set {text}"))
        } else {
            origin.strip_prefix("jitter ").map(|name| match name {
                "angle_degrees" => "--jitter-angle".to_string(),
                other => format!("--jitter-{other}"),
            })
        };
        if renamed.is_some() {
            error.origin = renamed;
        }
    }
    anyhow::Error::new(error)
}
