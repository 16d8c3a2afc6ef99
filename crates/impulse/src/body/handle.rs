//! Generational body handles and the slots that map them to dense body indices.

use serde::{Deserialize, Serialize};

/// A body's name in a [`crate::World`] that stays valid while the body lives and never names
/// another body afterwards: the index of a slot and the slot's generation, which grows each
/// time the slot is reused (Rapier's and Box2D's handles work the same way). A handle of a
/// removed body is refused by every call that takes one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BodyHandle {
    index: u32,
    generation: u32,
}

impl BodyHandle {
    /// The slot index: for a world built from a scene and never edited, the body's index in
    /// scene order.
    pub fn index(self) -> u32 {
        self.index
    }

    /// How many bodies used this slot before.
    pub fn generation(self) -> u32 {
        self.generation
    }
}

/// The slot index, and the generation after a `v` when the slot was reused (`3`, `3v1`): as
/// errors name a body.
impl std::fmt::Display for BodyHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.generation {
            0 => write!(f, "{}", self.index),
            generation => write!(f, "{}v{generation}", self.index),
        }
    }
}

/// Handle slots of a world: which dense body index each handle names, and the free slots.
#[derive(Clone, Default, Serialize, Deserialize)]
pub(crate) struct Handles {
    /// Per slot: its generation, and the body's dense index (`u32::MAX` when free).
    slots: Vec<(u32, u32)>,
    /// Free slots, reused last in, first out.
    free: Vec<u32>,
    /// Per dense body index, its handle.
    pub(crate) of_body: Vec<BodyHandle>,
}

impl Handles {
    /// A handle for a new body at dense index `body` (the end of the storage).
    pub(crate) fn insert(&mut self, body: usize) -> BodyHandle {
        let handle = match self.free.pop() {
            Some(index) => {
                let slot = &mut self.slots[index as usize];
                slot.1 = body as u32;
                BodyHandle {
                    index,
                    generation: slot.0,
                }
            }
            None => {
                self.slots.push((0, body as u32));
                BodyHandle {
                    index: self.slots.len() as u32 - 1,
                    generation: 0,
                }
            }
        };
        debug_assert_eq!(self.of_body.len(), body);
        self.of_body.push(handle);
        handle
    }

    /// Checks that the slots, the free list and the per-body handles agree, for a world of
    /// `bodies` bodies (a snapshot's handles before they are trusted): every body's handle
    /// names a slot that names the body back, and every other slot is free exactly once.
    pub(crate) fn check(&self, bodies: usize) -> Result<(), String> {
        if self.of_body.len() != bodies {
            return Err(format!(
                "{} body handles for {bodies} bodies",
                self.of_body.len()
            ));
        }
        for (body, handle) in self.of_body.iter().enumerate() {
            if self.slots.get(handle.index as usize) != Some(&(handle.generation, body as u32)) {
                return Err(format!("the handle of body {body} names another slot"));
            }
        }
        let mut free = vec![false; self.slots.len()];
        for &index in &self.free {
            match self.slots.get(index as usize) {
                Some(&(_, u32::MAX)) if !free[index as usize] => free[index as usize] = true,
                _ => return Err(format!("free handle slot {index} is not a free slot")),
            }
        }
        if self.free.len() + bodies != self.slots.len() {
            return Err(format!(
                "{} handle slots, {} free, for {bodies} bodies",
                self.slots.len(),
                self.free.len()
            ));
        }
        Ok(())
    }

    /// The dense index of `handle`'s body, or `None` for a removed body or a foreign handle.
    pub(crate) fn body(&self, handle: BodyHandle) -> Option<usize> {
        let &(generation, body) = self.slots.get(handle.index as usize)?;
        (generation == handle.generation && body != u32::MAX).then_some(body as usize)
    }

    /// Frees `handle`'s slot after its body (dense index `body`) was swap-removed: the body
    /// that was last now sits at `body`.
    pub(crate) fn remove(&mut self, handle: BodyHandle, body: usize) {
        let slot = &mut self.slots[handle.index as usize];
        slot.0 = slot.0.wrapping_add(1);
        slot.1 = u32::MAX;
        self.free.push(handle.index);
        self.of_body.swap_remove(body);
        if let Some(&moved) = self.of_body.get(body) {
            self.slots[moved.index as usize].1 = body as u32;
        }
    }
}
