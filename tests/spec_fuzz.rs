//! Damaged experiment specs never crash mltbench: every shipped `experiments/*.toml` is
//! mutated many times with a fixed seed (`fuzz_support`). Each mutant must either parse (in
//! both full and `--quick` form), with its cells and checkpoint budgets computable, or fail
//! with an error that names the spec file.

mod fuzz_support;
mod loader_support;

use std::panic::catch_unwind;
use std::path::Path;

use fuzz_support::{check_mutants, shipped_files};
use loader_support::scratch;
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

#[test]
fn damaged_specs_parse_or_fail_cleanly() {
    let scratch = scratch("spec-fuzz").join("mutant.toml");
    let specs = shipped_files("experiments", "toml");
    let (parsed, total) = check_mutants(&specs, MUTANTS, 0x5bec_f022, &scratch, check_mutant);
    println!("{parsed} of {total} mutants parsed; the others were refused");
    assert!(
        parsed > total / 10,
        "only {parsed} of {total} mutants parsed"
    );
}
