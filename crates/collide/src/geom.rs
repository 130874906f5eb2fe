//! Small geometry shared by the collision stages: the vector type and axis-aligned boxes.

/// 3-vector (m, m/s).
pub type V3 = nalgebra::Vector3<f64>;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: V3,
    /// Largest corner.
    pub max: V3,
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: V3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        max: V3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    };

    /// The box of some points.
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a V3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.including(p))
    }

    /// This box grown to include `p`.
    #[must_use]
    pub fn including(self, p: &V3) -> Self {
        Self {
            min: self.min.inf(p),
            max: self.max.sup(p),
        }
    }

    /// This box grown by `r` on every side.
    #[must_use]
    pub fn grown(self, r: f64) -> Self {
        let d = V3::repeat(r);
        Self {
            min: self.min - d,
            max: self.max + d,
        }
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(self, other: &Aabb) -> Self {
        Self {
            min: self.min.inf(&other.min),
            max: self.max.sup(&other.max),
        }
    }

    /// Whether the boxes overlap (touching counts).
    pub fn overlaps(&self, other: &Aabb) -> bool {
        (0..3).all(|k| self.min[k] <= other.max[k] && other.min[k] <= self.max[k])
    }
}
