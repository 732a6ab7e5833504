//! Affine transforms with their inverse, as Mitsuba's `to_world`.

use glam::{Mat4, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub matrix: Mat4,
    pub inverse: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        matrix: Mat4::IDENTITY,
        inverse: Mat4::IDENTITY,
    };

    /// None when the matrix is singular or not finite.
    pub fn new(matrix: Mat4) -> Option<Self> {
        let det = matrix.determinant();
        if !det.is_finite() || det == 0.0 || !matrix.is_finite() {
            return None;
        }
        Some(Transform {
            matrix,
            inverse: matrix.inverse(),
        })
    }

    /// `then` applied after `self`: the composition other · self.
    pub fn then(&self, other: &Transform) -> Transform {
        Transform {
            matrix: other.matrix * self.matrix,
            inverse: self.inverse * other.inverse,
        }
    }

    pub fn point(&self, p: Vec3) -> Vec3 {
        self.matrix.transform_point3(p)
    }

    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.matrix.transform_vector3(v)
    }

    /// Normals transform with the inverse transpose (not normalised).
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.inverse.transpose().transform_vector3(n)
    }

    pub fn inverse(&self) -> Transform {
        Transform {
            matrix: self.inverse,
            inverse: self.matrix,
        }
    }

    /// True when the transform flips orientation (negative determinant).
    pub fn flips_handedness(&self) -> bool {
        self.matrix.determinant() < 0.0
    }
}
