//! Generational joint handles and the slots that map them to dense joint indices.

use serde::{Deserialize, Serialize};

/// A joint's name in a [`crate::World`] that stays valid while the joint lives and never names
/// another joint afterwards: a slot index and the slot's generation, as [`crate::BodyHandle`].
/// A handle of a removed joint is refused by every call that takes one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct JointHandle {
    index: u32,
    generation: u32,
}

impl JointHandle {
    /// The slot index: for a world built from a scene and never edited, the joint's index in
    /// the scene's `joints`.
    pub fn index(self) -> u32 {
        self.index
    }

    /// How many joints used this slot before.
    pub fn generation(self) -> u32 {
        self.generation
    }
}

/// Handle slots of a world's joints: which dense joint index each handle names.
#[derive(Clone, Default, Debug, Serialize, Deserialize)]
pub(crate) struct JointHandles {
    /// Per slot: its generation, and the joint's dense index (`u32::MAX` when free).
    slots: Vec<(u32, u32)>,
    /// Free slots, reused last in, first out.
    free: Vec<u32>,
    /// Per dense joint index, its handle.
    pub(crate) of_joint: Vec<JointHandle>,
}

impl JointHandles {
    /// A handle for a new joint at dense index `joint` (the end of the storage).
    pub(crate) fn insert(&mut self, joint: usize) -> JointHandle {
        let handle = match self.free.pop() {
            Some(index) => {
                let slot = &mut self.slots[index as usize];
                slot.1 = joint as u32;
                JointHandle {
                    index,
                    generation: slot.0,
                }
            }
            None => {
                self.slots.push((0, joint as u32));
                JointHandle {
                    index: self.slots.len() as u32 - 1,
                    generation: 0,
                }
            }
        };
        self.of_joint.push(handle);
        handle
    }

    /// The dense index of `handle`'s joint, or `None` for a removed joint or a foreign handle.
    pub(crate) fn joint(&self, handle: JointHandle) -> Option<usize> {
        let &(generation, joint) = self.slots.get(handle.index as usize)?;
        (generation == handle.generation && joint != u32::MAX).then_some(joint as usize)
    }

    /// Frees `handle`'s slot after its joint (dense index `joint`) was swap-removed.
    pub(crate) fn remove(&mut self, handle: JointHandle, joint: usize) {
        let slot = &mut self.slots[handle.index as usize];
        slot.0 = slot.0.wrapping_add(1);
        slot.1 = u32::MAX;
        self.free.push(handle.index);
        self.of_joint.swap_remove(joint);
        if let Some(&moved) = self.of_joint.get(joint) {
            self.slots[moved.index as usize].1 = joint as u32;
        }
    }

    /// Checks that slots, free list and per-joint handles agree for `joints` joints (a
    /// snapshot's handles before they are trusted): each joint's handle names its slot, each
    /// free slot is listed once and holds no joint, and no slot is neither.
    pub(crate) fn check(&self, joints: usize) -> Result<(), String> {
        if self.of_joint.len() != joints {
            return Err(format!(
                "{} joint handles for {joints} joints",
                self.of_joint.len()
            ));
        }
        for (joint, handle) in self.of_joint.iter().enumerate() {
            if self.slots.get(handle.index as usize) != Some(&(handle.generation, joint as u32)) {
                return Err(format!("the handle of joint {joint} names another slot"));
            }
        }
        let mut seen = vec![false; self.slots.len()];
        for &index in &self.free {
            match self.slots.get(index as usize) {
                Some(&(_, u32::MAX)) if !seen[index as usize] => seen[index as usize] = true,
                _ => return Err(format!("free joint handle slot {index} is not a free slot")),
            }
        }
        if self.free.len() + joints != self.slots.len() {
            return Err(format!(
                "{} joint handle slots, {} free, for {joints} joints",
                self.slots.len(),
                self.free.len()
            ));
        }
        Ok(())
    }
}
