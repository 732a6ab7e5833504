//! Damaged experiment specs never crash mltbench: every shipped `experiments/*.toml` is
//! mutated many times with a fixed seed (`fuzz_support`). Each mutant must either parse (in
//! both full and `--quick` form; lecture specs with `kind` through their own checks), with
//! its cells and checkpoint budgets computable, or fail with an error that names the spec
//! file. Lecture specs with counts out of range or degenerate sides fail naming the line.

mod fuzz_support;
mod loader_support;

use std::panic::catch_unwind;
use std::path::Path;

use fuzz_support::{check_mutants, shipped_files};
use loader_support::scratch;
use mltbench::experiment::spec::Experiment;
use mltbench::lecture;
use mltbench::render::Budget;

/// Mutants per shipped spec.
const MUTANTS: usize = 1000;

/// Parses one mutant both ways; Err(what went wrong) if something panicked, an error did
/// not name the file, or a parsed spec is unusable.
fn check_mutant(path: &Path) -> Result<bool, String> {
    let text = std::fs::read(path).map_err(|e| e.to_string())?;
    let text = String::from_utf8_lossy(&text);
    if lecture::is_lecture(&text) {
        return match catch_unwind(|| lecture::check(path, &text)) {
            Err(_) => Err("checking the lecture spec panicked".into()),
            Ok(Ok(_)) => Ok(true),
            Ok(Err(e)) if e.to_string().contains(&path.display().to_string()) => Ok(false),
            Ok(Err(e)) => Err(format!("the error does not name the file: {e}")),
        };
    }
    let mut parsed = false;
    for quick in [false, true] {
        let result = catch_unwind(|| {
            Experiment::load(path, quick).map(|e| {
                let budgets = e.checkpoint_budgets();
                (e.cells().len(), e.runs, e.estimators.len(), budgets)
            })
        })
        .map_err(|_| format!("parsing (quick {quick}) panicked"))?;
        match result {
            Ok((cells, runs, estimators, budgets)) => {
                parsed = true;
                if cells != runs as usize * estimators || budgets.is_empty() {
                    return Err(format!("{cells} cells, {} budgets", budgets.len()));
                }
                let usable = |b: &Budget| match b {
                    Budget::Seconds(s) => s.is_finite() && *s > 0.0,
                    Budget::Passes(p) => *p > 0,
                };
                if !budgets.iter().all(usable) {
                    return Err(format!("unusable budgets {budgets:?}"));
                }
            }
            Err(e) if e.to_string().contains(&path.display().to_string()) => {}
            Err(e) => return Err(format!("the error does not name the file: {e}")),
        }
    }
    Ok(parsed)
}

#[test]
fn damaged_specs_parse_or_fail_cleanly() {
    let folder = scratch("spec-fuzz");
    let scratch = folder.join("mutant.toml");
    let specs = shipped_files("experiments", "toml");
    let (parsed, total) = check_mutants(&specs, MUTANTS, 0x5bec_f022, &scratch, check_mutant);
    println!("{parsed} of {total} mutants parsed; the others were refused");
    assert!(
        parsed > total / 10,
        "only {parsed} of {total} mutants parsed"
    );
}

/// A shipped lecture spec with `from` replaced by `to`: the error of `lecture::check` (or
/// "ok"), and the line of `to` in the changed text.
fn lecture_error(dir: &Path, name: &str, from: &str, to: &str) -> (String, String, usize) {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("experiments/{name}.toml"));
    let text = std::fs::read_to_string(shipped).unwrap();
    assert!(text.contains(from), "{name}: {from}");
    let text = text.replacen(from, to, 1);
    let line = 1 + text[..text.find(to).unwrap()].matches('\n').count();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, &text).unwrap();
    let err = match lecture::check(&path, &text) {
        Ok(_) => "ok".to_string(),
        Err(e) => e.to_string(),
    };
    (err, path.display().to_string(), line)
}

#[test]
fn lecture_spec_errors_name_the_file_and_line() {
    let dir = scratch("lecture-spec");
    let huge = "9223372036854775807";
    // (spec, replaced, replacement, words the message must contain)
    let cases = [
        (
            "mc-basics",
            "samples = 1000000",
            format!("samples = {huge}"),
            "samples must be between",
        ),
        (
            "mc-basics",
            "samples = 1000000",
            "samples = 10".into(),
            "samples must be between",
        ),
        (
            "mc-basics",
            "kind = \"mc-basics\"",
            "kind = 3".into(),
            "kind must be a string",
        ),
        (
            "mc-basics",
            "kind = \"mc-basics\"",
            "kind = \"mc\"".into(),
            "unknown experiment kind",
        ),
        (
            "sampling-spectra",
            "points = 1024",
            format!("points = {huge}"),
            "points must be between",
        ),
        (
            "sampling-spectra",
            "points = 1024",
            "points = 2".into(),
            "points must be between",
        ),
        (
            "sampling-spectra",
            "realisations = 16",
            format!("realisations = {huge}"),
            "realisations must be between",
        ),
        (
            "sampling-spectra",
            "max_frequency = 64",
            "max_frequency = 1000".into(),
            "max_frequency must be between",
        ),
        (
            "sampling-rates",
            "realisations = 64",
            format!("realisations = {huge}"),
            "realisations must be between",
        ),
        (
            "sampling-rates",
            "shifts = 64",
            format!("shifts = {huge}"),
            "shifts must be between",
        ),
        (
            "sampling-rates",
            "sides = [4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128, 181]",
            format!("sides = [4, 6, 8, 11, 16, {huge}]"),
            "every side must be between",
        ),
        (
            "sampling-rates",
            "sides = [4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128, 181]",
            "sides = [2, 2, 2, 2, 2, 2]".into(),
            "must increase strictly",
        ),
        (
            "sampling-rates",
            "sides = [4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128, 181]",
            "sides = [64, 32, 16, 8, 4, 2]".into(),
            "must increase strictly",
        ),
        (
            "sampling-rates",
            "sides = [4, 6, 8, 11, 16, 23, 32, 45, 64, 91, 128, 181]",
            "sides = [4, 6, 8]".into(),
            "between 6 and",
        ),
        (
            "sampling-rates",
            "ccvt = [4, 6, 8, 11, 16, 23, 32, 45]",
            "ccvt = [4, 6, 8, 8, 16, 23]".into(),
            "pattern_sides.ccvt must increase strictly",
        ),
        (
            "sampling-rates",
            "seed = 1",
            "seed = 1\npatterns = [\"independent\"]".into(),
            "ccvt is not among the patterns run",
        ),
    ];
    for (name, from, to, words) in cases {
        let (err, file, line) = lecture_error(&dir, name, from, &to);
        // The line of the offending key; for `patterns`, the unused [pattern_sides] entry.
        let line = if words.contains("not among") {
            line + 4
        } else {
            line
        };
        assert!(
            err.contains(&format!("{file}:{line}:")) && err.contains(words),
            "{name} with {to}: expected {file}:{line}: … {words}; got {err}"
        );
    }
    // The shipped specs pass.
    for name in ["mc-basics", "sampling-rates", "sampling-spectra"] {
        let (err, _, _) = lecture_error(&dir, name, "seed = 1", "seed = 1");
        assert_eq!(err, "ok", "{name}");
    }
}
