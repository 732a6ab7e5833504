//! `<transform>`: translate, rotate, scale, matrix and lookat, composed as Mitsuba does —
//! each operation is applied after the ones written before it, M = C_n · … · C_1.

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::values::{parse_f32, parse_floats, parse_xyz};
use super::xml::{ElemId, Tree};
use crate::error::Result;
use crate::math::Transform;

pub(super) fn parse_transform(tree: &Tree, elem: ElemId) -> Result<Transform> {
    let mut matrix = Mat4::IDENTITY;
    for &op in &tree.elem(elem).children {
        let step = match tree.tag(op) {
            "translate" => Mat4::from_translation(parse_xyz(tree, op, 0.0)?),
            "scale" => Mat4::from_scale(parse_xyz(tree, op, 1.0)?),
            "rotate" => {
                let axis = parse_xyz(tree, op, 0.0)?;
                let angle = parse_f32(tree, op, "angle", tree.attr(op, "angle").unwrap_or(""))?;
                if axis.length_squared() == 0.0 || !axis.is_finite() {
                    return Err(tree.error(op, "rotation axis must not be zero"));
                }
                rotation_as_mitsuba(axis, angle.to_radians())
            }
            "matrix" => {
                let v = parse_floats(
                    tree,
                    op,
                    "matrix",
                    tree.attr(op, "value").unwrap_or(""),
                    &[16, 9],
                )?;
                if v.len() == 16 {
                    // Written row by row; glam stores columns.
                    Mat4::from_cols_array(&v.try_into().expect("16 values")).transpose()
                } else {
                    Mat4::from_mat3(
                        Mat3::from_cols_array(&v.try_into().expect("9 values")).transpose(),
                    )
                }
            }
            "lookat" => look_at(tree, op)?,
            other => return Err(tree.error(op, format!("<{other}> is not a transform operation"))),
        };
        if !step.is_finite() {
            return Err(tree.error(op, "transform operation is not finite"));
        }
        matrix = step * matrix;
    }
    Transform::new(matrix).ok_or_else(|| {
        tree.error(
            elem,
            "transform is singular (e.g. a zero scale) or not finite",
        )
    })
}

/// Right-handed rotation by `angle` radians about `axis`, by Rodrigues' formula
/// R = cos θ·I + (1 − cos θ)·a·aᵀ + sin θ·[a]× applied to the axis as written: Mitsuba 3
/// does not normalise it either, so a non-unit axis also scales (`<rotate x="2" .../>`
/// stretches x by 4 at 90°), and scenes load to the same matrices in both renderers.
fn rotation_as_mitsuba(a: Vec3, angle: f32) -> Mat4 {
    let (s, c) = angle.sin_cos();
    let cross = Mat3::from_cols(
        Vec3::new(0.0, a.z, -a.y),
        Vec3::new(-a.z, 0.0, a.x),
        Vec3::new(a.y, -a.x, 0.0),
    );
    let outer = Mat3::from_cols(a * a.x, a * a.y, a * a.z);
    Mat4::from_mat3(Mat3::IDENTITY * c + outer * (1.0 - c) + cross * s)
}

/// Mitsuba's look-at camera frame: the camera looks down +z from `origin` towards `target`;
/// columns (left, up, dir, origin).
fn look_at(tree: &Tree, op: ElemId) -> Result<Mat4> {
    let vec3 = |name: &str| -> Result<Vec3> {
        let v = parse_floats(tree, op, name, tree.attr(op, name).unwrap_or(""), &[3])?;
        Ok(Vec3::new(v[0], v[1], v[2]))
    };
    let origin = vec3("origin")?;
    let target = vec3("target")?;
    let dir = (target - origin).normalize();
    let mut up = match tree.attr(op, "up") {
        Some(_) => vec3("up")?,
        None => Vec3::ZERO,
    };
    if up.length_squared() == 0.0 {
        up = coordinate_system(dir).0;
    }
    let left = up.cross(dir).normalize();
    let new_up = dir.cross(left);
    let m = Mat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        Vec4::new(origin.x, origin.y, origin.z, 1.0),
    );
    if !m.is_finite() {
        return Err(tree.error(
            op,
            "invalid lookat: origin equals target, or up is parallel to the viewing direction",
        ));
    }
    Ok(m)
}

/// Two unit vectors completing `n` to an orthonormal basis (Duff et al. 2017, "Building an
/// Orthonormal Basis, Revisited", JCGT 6(1)), the construction Mitsuba uses.
pub(super) fn coordinate_system(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}
