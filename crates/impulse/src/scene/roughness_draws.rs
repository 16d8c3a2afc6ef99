//! The reader of a body's `roughness_draws` field: pairs `[a, b]` of standard-normal
//! coordinates, with an error that names the count when a draw is not a pair.

use serde::Deserialize;

/// Reads `roughness_draws`: a list of pairs `[a, b]`, each refused with "each draw is a pair
/// [a, b]" and the count it has when it is not two numbers (serde's fixed-size array reader
/// says only "trailing characters").
pub(super) fn draw_pairs<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<Vec<[f32; 2]>, D::Error> {
    /// One draw `[a, b]`.
    struct Pair([f32; 2]);
    impl<'de> Deserialize<'de> for Pair {
        fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
            struct PairVisitor;
            impl<'de> serde::de::Visitor<'de> for PairVisitor {
                type Value = Pair;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("a draw: a pair [a, b] of numbers")
                }
                fn visit_seq<A: serde::de::SeqAccess<'de>>(
                    self,
                    mut seq: A,
                ) -> Result<Pair, A::Error> {
                    let mut numbers = Vec::with_capacity(2);
                    while let Some(x) = seq.next_element::<f32>()? {
                        numbers.push(x);
                        if numbers.len() > 16 {
                            break;
                        }
                    }
                    match numbers[..] {
                        [a, b] => Ok(Pair([a, b])),
                        _ => Err(serde::de::Error::custom(format!(
                            "each draw is a pair [a, b] of numbers, got {}{} numbers",
                            numbers.len(),
                            if numbers.len() > 16 { " or more" } else { "" }
                        ))),
                    }
                }
            }
            deserializer.deserialize_seq(PairVisitor)
        }
    }
    let pairs = Vec::<Pair>::deserialize(deserializer)?;
    Ok(pairs.into_iter().map(|Pair(pair)| pair).collect())
}
