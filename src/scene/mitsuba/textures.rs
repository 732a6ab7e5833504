//! `<texture>` elements: Mitsuba 3's `bitmap` and `checkerboard`, with its parameter names
//! and defaults (`bitmap`: `filter_type` bilinear, `wrap_mode` repeat, `raw` false;
//! `checkerboard`: `color0` 0.4, `color1` 0.2; both: `to_uv` identity).
//!
//! A texture is read only where mltbench uses it, a diffuse BSDF's `reflectance`
//! (`values::Props::collect` refuses it elsewhere), and once however often it is referenced.

use std::sync::Arc;

use super::Builder;
use super::values::Props;
use super::xml::ElemId;
use crate::error::Result;
use crate::io::texture_file::read_texture_image;
use crate::math::Transform;
use crate::texture::{Bitmap, Checkerboard, Texture, TextureFilter, UvTransform, WrapMode};

impl Builder<'_> {
    /// The texture written at `elem`.
    pub(super) fn texture(&mut self, elem: ElemId) -> Result<Texture> {
        if let Some(texture) = self.parsed_textures.get(&elem) {
            return Ok(texture.clone());
        }
        let texture = self.guarded(elem, |b| b.parse_texture(elem))?;
        self.parsed_textures.insert(elem, texture.clone());
        Ok(texture)
    }

    fn parse_texture(&mut self, elem: ElemId) -> Result<Texture> {
        let tree = self.tree;
        let props = Props::collect(tree, elem)?;
        let to_uv = props
            .transform("to_uv")?
            .map_or(UvTransform::IDENTITY, |t| uv_transform(&t));
        let texture = match tree.type_of(elem) {
            "bitmap" => Texture::Bitmap(Arc::new(self.bitmap(&props, to_uv)?)),
            "checkerboard" => Texture::Checkerboard(Checkerboard {
                color0: self.reflectance(&props, "color0", 0.4)?,
                color1: self.reflectance(&props, "color1", 0.2)?,
                to_uv,
            }),
            other => {
                return Err(tree.error(
                    elem,
                    format!(
                        "texture type \"{other}\" is not supported (mltbench reads bitmap and \
                         checkerboard)"
                    ),
                ));
            }
        };
        props.finish()?;
        Ok(texture)
    }

    fn bitmap(&mut self, props: &Props, to_uv: UvTransform) -> Result<Bitmap> {
        let tree = self.tree;
        let owner = props.owner();
        let Some(filename) = props.string("filename")? else {
            return Err(tree.error(owner, "a bitmap texture needs a \"filename\""));
        };
        let filter = match props.string("filter_type")?.unwrap_or("bilinear") {
            "bilinear" => TextureFilter::Bilinear,
            "nearest" => TextureFilter::Nearest,
            other => {
                return Err(tree.error(
                    props.elem_of("filter_type"),
                    format!("filter_type \"{other}\": expected bilinear or nearest"),
                ));
            }
        };
        let wrap = match props.string("wrap_mode")?.unwrap_or("repeat") {
            "repeat" => WrapMode::Repeat,
            "mirror" => WrapMode::Mirror,
            "clamp" => WrapMode::Clamp,
            other => {
                return Err(tree.error(
                    props.elem_of("wrap_mode"),
                    format!("wrap_mode \"{other}\": expected repeat, mirror or clamp"),
                ));
            }
        };
        let raw = props.boolean("raw")?.unwrap_or(false);
        // Whether Mitsuba keeps the texture in GPU-style texture memory: no effect here.
        props.boolean("accel")?;
        let named_at = props.elem_of("filename");
        let path = tree
            .find_file(filename, tree.elem(named_at).file, "texture")
            .map_err(|message| tree.error(named_at, message))?;
        self.note_file(path.clone());
        let image = read_texture_image(&path, raw)
            .map_err(|e| tree.error(owner, format!("could not read the texture: {e}")))?;
        let width = image.width as usize;
        if let Some(i) = image
            .pixels
            .iter()
            .position(|t| !t.0.iter().all(|c| c.is_finite() && *c >= 0.0))
        {
            return Err(tree.error(
                owner,
                format!(
                    "texel ({}, {}) of \"{}\" is {:?}: a reflectance must be finite and not \
                     negative",
                    i % width,
                    i / width,
                    path.display(),
                    image.pixels[i].0
                ),
            ));
        }
        let bitmap = Bitmap {
            width: image.width,
            height: image.height,
            texels: image.pixels,
            filter,
            wrap,
            to_uv,
        };
        let max = bitmap.max_value();
        if max > 1.0 {
            let w = tree.warning(
                owner,
                &format!(
                    "\"{}\" has texels up to {max} (above 1): as a reflectance it reflects more \
                     light than it receives; used as it is, as Mitsuba 3 does",
                    path.display()
                ),
            );
            self.desc.warnings.push(w);
        }
        Ok(bitmap)
    }
}

/// The 2D part of a `to_uv` transform: rows (m00, m01, m03) and (m10, m11, m13), as Mitsuba
/// 3 reads it.
fn uv_transform(t: &Transform) -> UvTransform {
    let m = t.matrix;
    UvTransform {
        rows: [
            [m.x_axis.x, m.y_axis.x, m.w_axis.x],
            [m.x_axis.y, m.y_axis.y, m.w_axis.y],
        ],
    }
}
