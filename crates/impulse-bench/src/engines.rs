//! Starts a run of any engine setting with the engines compiled in: the one place that knows
//! which peer modules a build has.

use anyhow::{Result, bail};
use impulse::Scene;

use crate::peer::EngineRun;
use crate::peer_settings::{PeerSetting, missing_peer};

/// A run of `scene` for `steps` steps with the peer `setting`, named `engine` in its row; an
/// error naming the feature when the peer is not compiled in.
pub(crate) fn start_peer(
    scene: &Scene,
    steps: u32,
    setting: &PeerSetting,
    engine: &str,
) -> Result<Box<dyn EngineRun>> {
    // Each arm is compiled only with its engine; the names are unused otherwise.
    let _ = (scene, steps, engine);
    match setting {
        #[cfg(feature = "rapier")]
        PeerSetting::Rapier(variant) => Ok(Box::new(crate::rapier_engine::rapier_run(
            scene,
            steps,
            &variant.integration_parameters(),
            engine,
        )?)),
        #[cfg(feature = "box3d")]
        PeerSetting::Box3d(setting) => Ok(Box::new(crate::box3d_engine::box3d_run(
            scene, steps, setting, engine,
        )?)),
        #[cfg(feature = "jolt")]
        PeerSetting::Jolt(setting) => Ok(Box::new(crate::jolt_engine::jolt_run(
            scene, steps, setting, engine,
        )?)),
        #[allow(unreachable_patterns)]
        other => bail!("{}", missing_peer(other.engine())),
    }
}
