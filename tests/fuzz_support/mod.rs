//! Seeded mutations of input files for the robustness tests: numbers replaced by NaN,
//! infinities, negatives, huge or empty values; quoted values and plugin types swapped;
//! lines deleted or doubled; bytes deleted; garbage (non-UTF-8 too) inserted; truncation.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// SplitMix64 (Steele et al. 2014): a small, seedable generator.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub fn below(&mut self, n: usize) -> usize {
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

/// Byte ranges of the values of `type="…"` attributes in `text`.
fn type_spans(text: &[u8]) -> Vec<(usize, usize)> {
    quoted_spans(text)
        .into_iter()
        .filter(|&(s, _)| s >= 6 && &text[s - 6..s] == b"type=\"")
        .collect()
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
pub fn mutate(text: &[u8], rng: &mut Rng) -> (Vec<u8>, String) {
    let at = |rng: &mut Rng| rng.below(text.len() + 1);
    let kind = rng.below(8);
    // Texts without numbers, quotes or `type="…"` get a byte-level mutation instead.
    let has = |spans: Vec<(usize, usize)>| !spans.is_empty();
    let kind = match kind {
        0 if !has(number_spans(text)) => 5,
        1 if !has(quoted_spans(text)) => 5,
        2 if !has(type_spans(text)) => 5,
        k => k,
    };
    match kind {
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
            let spans = type_spans(text);
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

/// The files `*.EXT` in the crate's folder `dir` (e.g. `experiments/scenes`), sorted.
pub fn shipped_files(dir: &str, ext: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort();
    files
}

/// Writes `mutants` mutations of each of `files` (seeded with `seed`) to `scratch`, one at a
/// time, and runs `check` on each: Ok(whether it was accepted) or Err(what went wrong).
/// Returns (accepted, total), and panics listing every mutant that went wrong.
pub fn check_mutants(
    files: &[PathBuf],
    mutants: usize,
    seed: u64,
    scratch: &Path,
    check: impl Fn(&Path) -> Result<bool, String>,
) -> (usize, usize) {
    let mut rng = Rng(seed);
    let mut failures = Vec::new();
    let (mut accepted, mut total) = (0, 0);
    for file in files {
        let text = std::fs::read(file).expect("shipped file");
        for k in 0..mutants {
            let (mutant, what) = mutate(&text, &mut rng);
            std::fs::write(scratch, &mutant).expect("write mutant");
            total += 1;
            match check(scratch) {
                Ok(ok) => accepted += ok as usize,
                Err(e) => failures.push(format!(
                    "{} mutant {k} ({what}): {e}",
                    file.file_name().unwrap().to_string_lossy()
                )),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    (accepted, total)
}
