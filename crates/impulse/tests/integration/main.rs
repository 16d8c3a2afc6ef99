//! The crate's integration tests, as one test binary: one binary links the crate once, where a
//! binary per file would link it once per file (the build's time and disk grow with each).
//! Run one file's tests with a filter on its module, e.g.
//! `cargo test -p impulse --test integration api::`.

mod api;
mod auto_policy;
mod blow_up;
mod body_options;
mod cards_on_meshes;
mod ccd;
mod common;
mod concave;
mod curved_meshes;
mod dead_impacts;
mod determinism;
mod edge_passes;
mod extreme_values;
mod fast_impacts;
mod fast_pairs;
mod fuzz_regressions;
mod golden;
mod guards;
mod gyroscopic;
mod heavy_on_light;
mod height_fields;
mod hulls;
mod impact_perturbation;
mod impacts;
mod islands;
mod joints;
mod kinematic;
mod local_impacts;
mod locked_axes;
mod malformed_meshes;
mod malformed_scenes;
mod material_combine;
mod meshes;
mod mug_pour;
mod phantom_and_tunnel;
mod physics;
mod profile;
mod roughness;
mod roughness_draws;
mod round_hulls;
mod scene_files;
mod seams;
mod shapes;
mod simultaneous_impacts;
mod snapshot;
mod soak;
mod solver2d_scenes;
mod speculative;
mod split_steps;
mod standard_scenes;
mod thin_shapes;
mod tumbling_hulls;
mod variation;
