//! Chains hanging at rest.
