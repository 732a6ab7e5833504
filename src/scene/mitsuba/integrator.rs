//! `<integrator>`: only the path-length settings and `hide_emitters` are read; mltbench
//! chooses the estimator.

use super::Builder;
use super::values::Props;
use super::xml::ElemId;
use crate::error::Result;
use crate::scene::IntegratorDesc;

/// Mitsuba integrators whose `max_depth`/`rr_depth` mean what mltbench's do.
const PATH_LIKE: &[&str] = &[
    "path",
    "volpath",
    "volpathmis",
    "ptracer",
    "prb",
    "prb_basic",
    "prbvolpath",
];

impl Builder<'_> {
    pub(super) fn parse_integrator(&mut self, elem: ElemId) -> Result<IntegratorDesc> {
        self.guarded(elem, |b| b.parse_integrator_unguarded(elem))
    }

    fn parse_integrator_unguarded(&mut self, elem: ElemId) -> Result<IntegratorDesc> {
        let tree = self.tree;
        let kind = tree.type_of(elem);
        let props = Props::collect(tree, elem)?;
        let desc = match kind {
            k if PATH_LIKE.contains(&k) => {
                props.ignore(&["samples_per_pass", "timeout"]);
                IntegratorDesc {
                    hide_emitters: hide_emitters(&props)?,
                    ..depths(&props)?
                }
            }
            // Direct illumination: emitters seen directly plus one bounce (Mitsuba's
            // `direct` has no depth parameters).
            "direct" => {
                props.ignore(&[
                    "emitter_samples",
                    "bsdf_samples",
                    "shading_samples",
                    "timeout",
                ]);
                let hide = hide_emitters(&props)?;
                if hide {
                    // Measured against Mitsuba 3.9.1 (llvm_ad_rgb): its `direct` shows the
                    // environment through a null surface, its `path` does not.
                    let w = tree.warning(
                        props.elem_of("hide_emitters"),
                        "hide_emitters follows Mitsuba's path integrator: the environment \
                         seen only through null surfaces is hidden too (Mitsuba's direct \
                         integrator shows it)",
                    );
                    self.desc.warnings.push(w);
                }
                IntegratorDesc {
                    max_depth: 2,
                    hide_emitters: hide,
                    ..IntegratorDesc::default()
                }
            }
            // Wrappers: what matters is the integrator inside.
            "moment" | "aov" => {
                props.ignore(&["aovs", "timeout"]);
                if kind == "aov" {
                    let w = tree.warning(
                        elem,
                        "AOV channels are not produced; using the nested integrator",
                    );
                    self.desc.warnings.push(w);
                }
                let mut inner = None;
                for (i, object) in props.objects().iter().enumerate() {
                    if tree.tag(object.target) != "integrator" {
                        continue;
                    }
                    props.use_object(i);
                    let nested = self.parse_integrator(object.target)?;
                    if inner.is_none() {
                        inner = Some(nested);
                    } else {
                        let w = tree.warning(
                            object.via,
                            "only the first integrator nested in a wrapper is used",
                        );
                        self.desc.warnings.push(w);
                    }
                }
                inner.ok_or_else(|| {
                    tree.error(
                        elem,
                        format!("<integrator type=\"{kind}\"> needs a nested <integrator>"),
                    )
                })?
            }
            other => {
                let desc = depths(&props)?;
                props.ignore_all();
                let w = tree.warning(
                    elem,
                    &format!(
                        "integrator type \"{other}\" is not a Mitsuba 3 path tracer: only its \
                         max_depth ({}) and rr_depth ({}) are used",
                        desc.max_depth, desc.rr_depth
                    ),
                );
                self.desc.warnings.push(w);
                desc
            }
        };
        props.finish()?;
        Ok(desc)
    }
}

/// `max_depth` (-1 = unbounded, default) and `rr_depth` (default 5), checked as Mitsuba does.
fn depths(props: &Props) -> Result<IntegratorDesc> {
    let tree = props.tree();
    let defaults = IntegratorDesc::default();
    let max_depth = match props.integer("max_depth")? {
        None => defaults.max_depth,
        Some(d) if d >= -1 && d <= i32::MAX as i64 => d as i32,
        Some(d) => {
            return Err(tree.error(
                props.elem_of("max_depth"),
                format!("max_depth must be -1 (unbounded) or at least 0, got {d}"),
            ));
        }
    };
    let rr_depth = match props.integer("rr_depth")? {
        None => defaults.rr_depth,
        Some(d) if d > 0 && d <= u32::MAX as i64 => d as u32,
        Some(d) => {
            return Err(tree.error(
                props.elem_of("rr_depth"),
                format!("rr_depth must be greater than zero, got {d}"),
            ));
        }
    };
    Ok(IntegratorDesc {
        max_depth,
        rr_depth,
        hide_emitters: false,
    })
}

/// `hide_emitters` (default false).
fn hide_emitters(props: &Props) -> Result<bool> {
    Ok(props.boolean("hide_emitters")?.unwrap_or(false))
}
