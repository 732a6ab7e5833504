//! Damaged scene files never crash mltbench. Every shipped scene is mutated many times, with
//! a fixed seed: numbers replaced by NaN, infinities, negatives, huge or empty values;
//! attribute values and plugin types swapped; lines deleted or duplicated; bytes deleted,
//! garbage (non-UTF-8 too) inserted; the file truncated. Each mutant must either load or
//! fail with an error that names the file; a mutant that loads must build and render a
//! small image with `pt` and `eyelight` without panicking and without a non-finite pixel.

mod loader_support;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use loader_support::{scratch, write};
use mltbench::estimator::{self, Params};
use mltbench::render::{Budget, render};
use mltbench::scene::{Scene, mitsuba};

/// Mutants per shipped scene.
const MUTANTS: usize = 1000;
/// Largest film side rendered for a mutant that loads (the loader caps sides far higher).
const RENDER_SIDE: u32 = 12;

/// SplitMix64 (Steele et al. 2014): a small, seedable generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn pick<'a>(&mut self, options: &[&'a str]) -> &'a str {
        options[self.below(options.len())]
    }
}

const BAD_NUMBERS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "-0",
    "1e39",
    "1e-45",
    "",
    "x",
    "3,4",
    "99999",
    "1e300",
    "0x10",
    "2147483648",
    "-2147483649",
];
const BAD_VALUES: &[&str] = &[
    "",
    "nan",
    "bogus",
    "1, 2",
    "$undefined",
    "-5",
    "../../missing.obj",
    "0 0 0 0",
    "true",
];
const PLUGIN_TYPES: &[&str] = &[
    "diffuse",
    "dielectric",
    "thindielectric",
    "roughdielectric",
    "conductor",
    "roughconductor",
    "plastic",
    "roughplastic",
    "twosided",
    "null",
    "phong",
    "blinn",
    "ward",
    "area",
    "point",
    "spot",
    "directional",
    "constant",
    "envmap",
    "sphere",
    "rectangle",
    "cube",
    "disk",
    "obj",
    "ply",
    "perspective",
    "thinlens",
    "hdrfilm",
    "box",
    "gaussian",
    "independent",
    "stratified",
    "path",
    "direct",
    "moment",
    "volpath",
    "unknown",
];

/// Byte ranges of the numbers in `text` (digits with an optional sign, point and exponent).
fn number_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if text[i].is_ascii_digit() {
            let start = if i > 0 && text[i - 1] == b'-' {
                i - 1
            } else {
                i
            };
            let mut end = i;
            while end < text.len()
                && (text[end].is_ascii_digit() || matches!(text[end], b'.' | b'e' | b'E'))
            {
                end += 1;
            }
            spans.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    spans
}

/// Byte ranges of the attribute values (between double quotes) in `text`.
fn quoted_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let quotes: Vec<usize> = (0..text.len()).filter(|&i| text[i] == b'"').collect();
    quotes.chunks_exact(2).map(|q| (q[0] + 1, q[1])).collect()
}

/// Byte ranges of the lines of `text`, newline included.
fn line_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, &b) in text.iter().enumerate() {
        if b == b'\n' {
            spans.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < text.len() {
        spans.push((start, text.len()));
    }
    spans
}

fn splice(text: &[u8], (start, end): (usize, usize), with: &[u8]) -> Vec<u8> {
    [&text[..start], with, &text[end..]].concat()
}

/// One random mutation of `text`, and what it did (for the failure message).
fn mutate(text: &[u8], rng: &mut Rng) -> (Vec<u8>, String) {
    let at = |rng: &mut Rng| rng.below(text.len() + 1);
    match rng.below(8) {
        0 => {
            let spans = number_spans(text);
            let span = spans[rng.below(spans.len())];
            let with = rng.pick(BAD_NUMBERS);
            (
                splice(text, span, with.as_bytes()),
                format!("number at byte {} -> {with:?}", span.0),
            )
        }
        1 => {
            let spans = quoted_spans(text);
            let span = spans[rng.below(spans.len())];
            let with = rng.pick(BAD_VALUES);
            (
                splice(text, span, with.as_bytes()),
                format!("value at byte {} -> {with:?}", span.0),
            )
        }
        2 => {
            // A plugin type swapped for another (or an unknown one).
            let spans: Vec<(usize, usize)> = quoted_spans(text)
                .into_iter()
                .filter(|&(s, _)| s >= 6 && &text[s - 6..s] == b"type=\"")
                .collect();
            let span = spans[rng.below(spans.len())];
            let with = rng.pick(PLUGIN_TYPES);
            (
                splice(text, span, with.as_bytes()),
                format!("type at byte {} -> {with:?}", span.0),
            )
        }
        3 => {
            let lines = line_spans(text);
            let span = lines[rng.below(lines.len())];
            (
                splice(text, span, b""),
                format!("line at byte {} deleted", span.0),
            )
        }
        4 => {
            let lines = line_spans(text);
            let span = lines[rng.below(lines.len())];
            let line = text[span.0..span.1].to_vec();
            (
                splice(text, (span.0, span.0), &line),
                format!("line at byte {} doubled", span.0),
            )
        }
        5 => {
            let start = at(rng);
            let end = (start + 1 + rng.below(40)).min(text.len());
            (
                splice(text, (start, end), b""),
                format!("bytes {start}..{end} deleted"),
            )
        }
        6 => {
            let start = at(rng);
            let garbage: Vec<u8> = (0..1 + rng.below(12)).map(|_| rng.next() as u8).collect();
            (
                splice(text, (start, start), &garbage),
                format!("garbage {garbage:?} at {start}"),
            )
        }
        _ => {
            let end = at(rng);
            (text[..end].to_vec(), format!("truncated at byte {end}"))
        }
    }
}

/// Loads, builds and renders one mutant; Err(what went wrong) if it panicked, failed without
/// naming the file, or rendered a non-finite pixel.
fn check_mutant(path: &Path) -> Result<(), String> {
    let loaded = catch_unwind(|| mitsuba::load_file(path)).map_err(|_| "the loader panicked")?;
    let mut desc = match loaded {
        Ok(desc) => desc,
        Err(e) => {
            let message = e.to_string();
            return if message.contains(&path.display().to_string()) {
                Ok(())
            } else {
                Err(format!("the error does not name the file: {message}"))
            };
        }
    };
    let film = &mut desc.sensor.film;
    film.width = film.width.min(RENDER_SIDE);
    film.height = film.height.min(RENDER_SIDE);
    let built = catch_unwind(AssertUnwindSafe(|| Scene::build(desc)))
        .map_err(|_| "building the scene panicked")?;
    let scene = match built {
        Ok(scene) => scene,
        Err(e) if e.to_string().contains(&path.display().to_string()) => return Ok(()),
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
    Ok(())
}

fn shipped_scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("experiments/scenes")
        .map(|e| e.expect("folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    scenes.sort();
    scenes
}

#[test]
fn damaged_scenes_load_or_fail_cleanly() {
    let dir = scratch("fuzz");
    let mut rng = Rng(0xf022_5eed);
    let mut failures = Vec::new();
    let (mut loaded, mut total) = (0, 0);
    for scene in shipped_scenes() {
        let text = std::fs::read(&scene).expect("shipped scene");
        for k in 0..MUTANTS {
            let (mutant, what) = mutate(&text, &mut rng);
            let path = write(&dir, "mutant.xml", &mutant);
            total += 1;
            match check_mutant(&path) {
                Ok(()) => loaded += mitsuba::load_file(&path).is_ok() as usize,
                Err(e) => failures.push(format!(
                    "{} mutant {k} ({what}): {e}",
                    scene.file_name().unwrap().to_string_lossy()
                )),
            }
        }
    }
    println!("{loaded} of {total} mutants loaded and rendered; the others were refused");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The mutations must leave some scenes loadable, or the render half would test nothing.
    assert!(
        loaded > total / 10,
        "only {loaded} of {total} mutants loaded"
    );
}
