//! Damaged scene files never crash mltbench. Every shipped scene is mutated many times, with
//! a fixed seed: numbers replaced by NaN, infinities, negatives, huge or empty values;
//! attribute values and plugin types swapped; lines deleted or duplicated; bytes deleted,
//! garbage (non-UTF-8 too) inserted; the file truncated. Each mutant must either load or
//! fail with an error that names the file; a mutant that loads must build and render a
//! small image with `pt` and `eyelight` without panicking and without a non-finite pixel.

mod fuzz_support;
mod loader_support;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use fuzz_support::{check_mutants, shipped_files};
use loader_support::scratch;
use mltbench::estimator::{self, Params};
use mltbench::render::{Budget, render};
use mltbench::scene::{Scene, mitsuba};

/// Mutants per shipped scene.
const MUTANTS: usize = 1000;
/// Largest film side rendered for a mutant that loads (the loader caps sides far higher).
const RENDER_SIDE: u32 = 12;

/// Loads, builds and renders one mutant: Ok(whether it loaded), or Err(what went wrong) if
/// something panicked, an error did not name the file, or a pixel came out non-finite.
fn check_mutant(path: &Path) -> Result<bool, String> {
    let loaded = catch_unwind(|| mitsuba::load_file(path)).map_err(|_| "the loader panicked")?;
    let mut desc = match loaded {
        Ok(desc) => desc,
        Err(e) => {
            let message = e.to_string();
            return if message.contains(&path.display().to_string()) {
                Ok(false)
            } else {
                Err(format!("the error does not name the file: {message}"))
            };
        }
    };
    let film = &mut desc.sensor.film;
    film.width = film.width.min(RENDER_SIDE);
    film.height = film.height.min(RENDER_SIDE);
    film.crop = None;
    let built = catch_unwind(AssertUnwindSafe(|| Scene::build(desc)))
        .map_err(|_| "building the scene panicked")?;
    let scene = match built {
        Ok(scene) => scene,
        Err(e) if e.to_string().contains(&path.display().to_string()) => return Ok(false),
        Err(e) => return Err(format!("the build error does not name the file: {e}")),
    };
    for name in ["pt", "eyelight"] {
        let rendered = catch_unwind(AssertUnwindSafe(|| {
            let mut est = estimator::create(name, &Params::default(), &scene, 7)
                .map_err(|e| format!("{name} cannot be made: {e}"))?;
            Ok::<_, String>(render(&scene, est.as_mut(), Budget::Passes(1), |_, _| {}).image)
        }))
        .map_err(|_| format!("{name} panicked"))?;
        let image = rendered?;
        if image
            .pixels
            .iter()
            .any(|p| !p.0.iter().all(|v| v.is_finite()))
        {
            return Err(format!("{name} wrote a non-finite pixel"));
        }
    }
    Ok(true)
}

#[test]
fn damaged_scenes_load_or_fail_cleanly() {
    let folder = scratch("fuzz");
    let scratch = folder.join("mutant.xml");
    let scenes = shipped_files("experiments/scenes", "xml");
    let (loaded, total) = check_mutants(&scenes, MUTANTS, 0xf022_5eed, &scratch, check_mutant);
    println!("{loaded} of {total} mutants loaded and rendered; the others were refused");
    // The mutations must leave some scenes loadable, or the render half would test nothing.
    assert!(
        loaded > total / 10,
        "only {loaded} of {total} mutants loaded"
    );
}
