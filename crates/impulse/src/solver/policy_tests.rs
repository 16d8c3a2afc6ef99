//! Unit tests of `method: auto`'s escalation policy ([`super`]).

use crate::solver::EscalationLevel;

/// `name` is the level as the summary JSON writes it (serde's snake case), one per level.
#[test]
fn names_are_the_serialized_levels() {
    let levels = [
        EscalationLevel::Pgs,
        EscalationLevel::Nncg,
        EscalationLevel::Apgd,
        EscalationLevel::NncgExtended,
        EscalationLevel::Exact,
    ];
    for level in levels {
        let serialized = serde_json::to_value(level).unwrap();
        assert_eq!(
            serialized,
            serde_json::Value::from(level.name()),
            "{level:?}"
        );
    }
    assert_eq!(EscalationLevel::NncgExtended.name(), "nncg_extended");
}
