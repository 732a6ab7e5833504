//! Damaged experiment specs never crash mltbench: every shipped `experiments/*.toml` is
//! mutated many times with a fixed seed (`fuzz_support`). Each mutant must either parse (in
//! both full and `--quick` form), with its cells and checkpoint budgets computable, or fail
//! with an error that names the spec file.

mod fuzz_support;
mod loader_support;

use std::panic::catch_unwind;
use std::path::{Path, PathBuf};

use fuzz_support::{Rng, mutate};
use loader_support::{scratch, write};
use mltbench::experiment::spec::Experiment;
use mltbench::render::Budget;

/// Mutants per shipped spec.
const MUTANTS: usize = 1000;

/// Parses one mutant both ways; Err(what went wrong) if something panicked, an error did
/// not name the file, or a parsed spec is unusable.
fn check_mutant(path: &Path) -> Result<bool, String> {
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

fn shipped_specs() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    let mut specs: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("experiments")
        .map(|e| e.expect("folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    specs.sort();
    specs
}

#[test]
fn damaged_specs_parse_or_fail_cleanly() {
    let dir = scratch("spec-fuzz");
    let mut rng = Rng(0x5bec_f022);
    let mut failures = Vec::new();
    let (mut parsed, mut total) = (0, 0);
    for spec in shipped_specs() {
        let text = std::fs::read(&spec).expect("shipped spec");
        for k in 0..MUTANTS {
            let (mutant, what) = mutate(&text, &mut rng);
            let path = write(&dir, "mutant.toml", &mutant);
            total += 1;
            match check_mutant(&path) {
                Ok(ok) => parsed += ok as usize,
                Err(e) => failures.push(format!(
                    "{} mutant {k} ({what}): {e}",
                    spec.file_name().unwrap().to_string_lossy()
                )),
            }
        }
    }
    println!("{parsed} of {total} mutants parsed; the others were refused");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(
        parsed > total / 10,
        "only {parsed} of {total} mutants parsed"
    );
}
