//! The 17 body parts of the thesis's Fig. 35 and their tree (rooted at the pelvis).

use serde::{Deserialize, Serialize};

/// A body part. "Left" and "right" are the body's own (its left is world +x).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Part {
    /// Head (cap: closed at the crown).
    Head,
    /// Neck.
    Neck,
    /// Chest with the shoulders (from the waist to the neck base and the arm roots).
    Chest,
    /// Abdomen (waist to hip line).
    Abdomen,
    /// Pelvis (hip line to the thigh roots); the root of the tree.
    Pelvis,
    /// Left upper arm.
    UpperArmLeft,
    /// Right upper arm.
    UpperArmRight,
    /// Left forearm.
    ForearmLeft,
    /// Right forearm.
    ForearmRight,
    /// Left hand (cap).
    HandLeft,
    /// Right hand (cap).
    HandRight,
    /// Left thigh.
    ThighLeft,
    /// Right thigh.
    ThighRight,
    /// Left shin (lower leg).
    ShinLeft,
    /// Right shin.
    ShinRight,
    /// Left foot (cap).
    FootLeft,
    /// Right foot (cap).
    FootRight,
}

impl Part {
    /// All parts, in the order of their index.
    pub const ALL: [Part; 17] = [
        Part::Head,
        Part::Neck,
        Part::Chest,
        Part::Abdomen,
        Part::Pelvis,
        Part::UpperArmLeft,
        Part::UpperArmRight,
        Part::ForearmLeft,
        Part::ForearmRight,
        Part::HandLeft,
        Part::HandRight,
        Part::ThighLeft,
        Part::ThighRight,
        Part::ShinLeft,
        Part::ShinRight,
        Part::FootLeft,
        Part::FootRight,
    ];

    /// Index in [`Part::ALL`] (also the label stored per triangle and vertex).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The part of index `i`, if any.
    pub fn from_index(i: usize) -> Option<Part> {
        Part::ALL.get(i).copied()
    }

    /// The parent in the tree (rooted at the pelvis); `None` for the pelvis.
    pub fn parent(self) -> Option<Part> {
        use Part::*;
        Some(match self {
            Pelvis => return None,
            Abdomen | ThighLeft | ThighRight => Pelvis,
            Chest => Abdomen,
            Neck | UpperArmLeft | UpperArmRight => Chest,
            Head => Neck,
            ForearmLeft => UpperArmLeft,
            ForearmRight => UpperArmRight,
            HandLeft => ForearmLeft,
            HandRight => ForearmRight,
            ShinLeft => ThighLeft,
            ShinRight => ThighRight,
            FootLeft => ShinLeft,
            FootRight => ShinRight,
        })
    }

    /// A short lower-case name (`upper_arm_left`).
    pub fn name(self) -> &'static str {
        use Part::*;
        match self {
            Head => "head",
            Neck => "neck",
            Chest => "chest",
            Abdomen => "abdomen",
            Pelvis => "pelvis",
            UpperArmLeft => "upper_arm_left",
            UpperArmRight => "upper_arm_right",
            ForearmLeft => "forearm_left",
            ForearmRight => "forearm_right",
            HandLeft => "hand_left",
            HandRight => "hand_right",
            ThighLeft => "thigh_left",
            ThighRight => "thigh_right",
            ShinLeft => "shin_left",
            ShinRight => "shin_right",
            FootLeft => "foot_left",
            FootRight => "foot_right",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tree_is_rooted_at_the_pelvis() {
        for p in Part::ALL {
            assert_eq!(Part::from_index(p.index()), Some(p));
            let mut q = p;
            let mut steps = 0;
            while let Some(up) = q.parent() {
                q = up;
                steps += 1;
                assert!(steps < 17);
            }
            assert_eq!(q, Part::Pelvis);
        }
    }
}
