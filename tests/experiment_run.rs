//! The experiment harness end to end on a 32×32 Cornell box: files and plots written, an
//! interrupted run resumed to the same rows, cells run one by one and merged by `report`
//! to the same summary as one `run`, and bad specs or results files give errors.

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;
use mltbench::experiment::runner::read_rows;
use mltbench::experiment::{self, Experiment, RunOptions};

mod scratch_support;
use scratch_support::ScratchDir;

fn temp_dir(name: &str) -> ScratchDir {
    ScratchDir::new(&format!("exp-{name}"))
}

fn scene_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/scenes/cbox.xml")
}

/// A tiny experiment with a pass budget (reproducible bit for bit).
fn tiny_spec(dir: &Path, budget: &str) -> PathBuf {
    tiny_spec_with_reference(dir, budget, 64)
}

fn tiny_spec_with_reference(dir: &Path, budget: &str, reference_passes: u32) -> PathBuf {
    let spec = format!(
        r#"description = "tiny test experiment"
scene = "{}"
scene_params = {{ res = 32, max_depth = 4 }}
budget = {budget}
checkpoints = 6
runs = 2
seed = 3

[reference]
estimator = "pt"
budget = {{ passes = {reference_passes} }}

[[estimator]]
name = "pt"

[[estimator]]
name = "eyelight"
label = "preview (biased)"

[[region]]
label = "light"
x = 12
y = 0
width = 8
height = 4
"#,
        scene_path().display()
    );
    let path = dir.join("tiny.toml");
    std::fs::write(&path, spec).unwrap();
    path
}

fn options(results: &Path) -> RunOptions {
    RunOptions {
        results_root: results.to_path_buf(),
        fresh: false,
        cell: None,
        stop_after_checkpoints: None,
    }
}

/// metrics.csv without the seconds column (timing differs between any two runs).
fn rows_without_time(results: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(results.join("tiny/metrics.csv")).unwrap();
    text.lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(3);
            f.join(",")
        })
        .collect()
}

#[test]
fn a_tiny_experiment_runs_end_to_end_and_its_plots_decode() {
    let dir = temp_dir("e2e");
    // A reference far longer than the runs, so that their error is not the reference's.
    let spec = tiny_spec_with_reference(&dir, "{ seconds = 0.1 }", 4096);
    let exp = Experiment::load(&spec, false).unwrap();
    let results = dir.join("results");
    let summary = experiment::run(&exp, &options(&results), &ProgressBar::hidden())
        .unwrap()
        .unwrap();
    let out = results.join("tiny");
    for f in [
        "metrics.csv",
        "regions.csv",
        "summary.csv",
        "summary.json",
        "README.md",
        "convergence.svg",
        "convergence-passes.svg",
        "bias.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    for png in [
        "convergence.png",
        "convergence-passes.png",
        "bias.png",
        "contact.png",
    ] {
        let file = std::fs::File::open(out.join(png)).unwrap();
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert!(info.width > 100 && info.height > 100, "{png}");
    }
    // 2 estimators × 2 runs × 6 checkpoints.
    assert_eq!(read_rows_count(&out.join("metrics.csv")), 24);
    let pt = &summary.estimators[0];
    let preview = &summary.estimators[1];
    // Two runs: t = 12.7, yet no interval of a positive quantity goes below 0.
    for e in &summary.estimators {
        for i in [e.relmse, e.rmse, e.mape, e.efficiency] {
            assert!(
                i.lo >= 0.0 && i.lo <= i.mean && i.mean <= i.hi,
                "{}: {i:?}",
                e.label
            );
        }
        for (_, i) in &e.regions {
            assert!(i.lo >= 0.0, "{}: {i:?}", e.label);
        }
    }
    // The preview is biased: far larger error, and its error does not fall with time.
    assert!(preview.relmse.mean > 10.0 * pt.relmse.mean);
    assert!(pt.slope_passes.unwrap().slope < -0.5);
    assert!(preview.slope_passes.unwrap().slope.abs() < 0.2);
    let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
    assert!(readme.contains("convergence.png") && readme.contains("preview (biased)"));
}

fn read_rows_count(path: &Path) -> usize {
    std::fs::read_to_string(path).unwrap().lines().count() - 1
}

#[test]
fn an_interrupted_run_resumes_to_the_same_rows() {
    let dir = temp_dir("resume");
    let exp = Experiment::load(&tiny_spec(&dir, "{ passes = 12 }"), false).unwrap();
    let whole = dir.join("whole");
    experiment::run(&exp, &options(&whole), &ProgressBar::hidden()).unwrap();

    let interrupted = dir.join("interrupted");
    let mut stop = options(&interrupted);
    stop.stop_after_checkpoints = Some(2);
    let err = experiment::run(&exp, &stop, &ProgressBar::hidden()).unwrap_err();
    assert!(err.to_string().contains("interrupted"), "{err}");
    // The two finished checkpoints are on disk.
    let cell = interrupted.join("tiny/cells/pt-run0.csv");
    assert_eq!(
        read_rows(&cell)
            .unwrap()
            .iter()
            .filter(|r| r.region.is_empty())
            .count(),
        2
    );

    experiment::run(&exp, &options(&interrupted), &ProgressBar::hidden()).unwrap();
    assert_eq!(rows_without_time(&whole), rows_without_time(&interrupted));

    // Interrupted in the second cell: the finished first cell is kept as it is (not
    // rendered again), the second starts over and comes out the same.
    let later = dir.join("later");
    let mut stop = options(&later);
    stop.stop_after_checkpoints = Some(exp.checkpoint_budgets().len() + 1);
    experiment::run(&exp, &stop, &ProgressBar::hidden()).unwrap_err();
    let first = [
        later.join("tiny/cells/pt-run0.csv"),
        later.join("tiny/images/pt-run0.exr"),
    ];
    let stamps = |files: &[PathBuf]| -> Vec<std::time::SystemTime> {
        files
            .iter()
            .map(|f| std::fs::metadata(f).unwrap().modified().unwrap())
            .collect()
    };
    let before = stamps(&first);
    std::thread::sleep(std::time::Duration::from_millis(20));
    experiment::run(&exp, &options(&later), &ProgressBar::hidden()).unwrap();
    assert_eq!(stamps(&first), before);
    assert_eq!(rows_without_time(&whole), rows_without_time(&later));
}

#[test]
fn cells_run_one_by_one_then_reported_match_a_single_run() {
    let dir = temp_dir("cells");
    let exp = Experiment::load(&tiny_spec(&dir, "{ passes = 8 }"), false).unwrap();
    let single = dir.join("single");
    let one = experiment::run(&exp, &options(&single), &ProgressBar::hidden())
        .unwrap()
        .unwrap();

    let split = dir.join("split");
    for k in 0..exp.cells().len() {
        let mut o = options(&split);
        o.cell = Some(k);
        assert!(
            experiment::run(&exp, &o, &ProgressBar::hidden())
                .unwrap()
                .is_none()
        );
    }
    let merged = experiment::report_only(&exp, &split, &ProgressBar::hidden()).unwrap();
    assert_eq!(rows_without_time(&single), rows_without_time(&split));
    assert!(merged.missing_cells.is_empty());
    for (a, b) in one.estimators.iter().zip(&merged.estimators) {
        assert_eq!(a.label, b.label);
        assert_eq!(a.relmse, b.relmse);
        assert_eq!(a.rmse, b.rmse);
        assert_eq!(a.mape, b.mape);
        assert_eq!(a.slope_passes, b.slope_passes);
        assert_eq!(a.bias_variance, b.bias_variance);
        assert_eq!(a.regions, b.regions);
    }
}

#[test]
fn bad_specs_and_corrupt_results_are_errors_naming_the_file() {
    let dir = temp_dir("bad");
    let good = std::fs::read_to_string(tiny_spec(&dir, "{ passes = 4 }")).unwrap();
    // (what, text, the text on the line the error must name: a key's line, or the header
    // of the table the bad entry is in).
    let cases = [
        (
            "unknown key",
            good.replace("runs = 2", "runs = 2\nrunz = 3"),
            "runz = 3",
        ),
        (
            "unknown estimator",
            good.replace("name = \"eyelight\"", "name = \"nope\""),
            "[[estimator]]\nname = \"nope\"",
        ),
        (
            "both budgets",
            good.replace("{ passes = 4 }", "{ passes = 4, seconds = 1 }"),
            "budget = { passes = 4, seconds = 1 }",
        ),
        (
            "duplicate label",
            good.replace("label = \"preview (biased)\"", "label = \"pt\""),
            "[[estimator]]\nname = \"eyelight\"",
        ),
        (
            "no reference",
            good.replace("budget = { passes = 64 }", ""),
            "[reference]",
        ),
        (
            "zero runs",
            good.replace("runs = 2", "runs = 0"),
            "runs = 0",
        ),
        (
            "malformed",
            good.replace("checkpoints = 6", "checkpoints = = 6"),
            "checkpoints = = 6",
        ),
        (
            "dot-dot label",
            good.replace("label = \"preview (biased)\"", "label = \"..\""),
            "label = \"..\"",
        ),
        (
            "dot label",
            good.replace("label = \"preview (biased)\"", "label = \".\""),
            "label = \".\"",
        ),
        (
            "hidden label",
            good.replace("label = \"preview (biased)\"", "label = \".preview\""),
            "label = \".preview\"",
        ),
    ];
    for (what, text, on_line) in cases {
        let path = dir.join(format!("{}.toml", what.replace(' ', "_")));
        std::fs::write(&path, &text).unwrap();
        let err = Experiment::load(&path, false).unwrap_err().to_string();
        let line = 1 + text[..text.find(on_line).expect(what)]
            .matches('\n')
            .count();
        let named = path.display().to_string();
        // Checks by the loader name `file:line`; the TOML parser says "at line N".
        assert!(
            err.contains(&format!("{named}:{line}:"))
                || (err.contains(&named) && err.contains(&format!("at line {line},"))),
            "{what}: expected line {line}: {err}"
        );
    }

    // A parameter the estimator does not have: refused before anything renders.
    let path = dir.join("bad_param.toml");
    std::fs::write(
        &path,
        good.replace(
            "[[estimator]]\nname = \"pt\"",
            "[[estimator]]\nname = \"pt\"\nparams = { rr_dpeth = 3 }",
        ),
    )
    .unwrap();
    let exp = Experiment::load(&path, false).unwrap();
    let err = experiment::run(&exp, &options(&dir.join("none")), &ProgressBar::hidden())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bad_param.toml") && err.contains("rr_dpeth"),
        "{err}"
    );
    assert!(
        !dir.join("none/references").exists(),
        "nothing was rendered"
    );

    // A region outside the film: refused naming the spec, the region's line and its label,
    // before the reference renders.
    let path = dir.join("bad_region.toml");
    let text = good.replace("x = 12", "x = 100");
    std::fs::write(&path, &text).unwrap();
    let exp = Experiment::load(&path, false).unwrap();
    let line = 1 + text[..text.find("[[region]]").unwrap()]
        .matches('\n')
        .count();
    for outcome in [
        experiment::run(&exp, &options(&dir.join("none")), &ProgressBar::hidden()).map(|_| ()),
        experiment::prepare(&exp, &options(&dir.join("none")), &ProgressBar::hidden()),
    ] {
        let err = outcome.unwrap_err().to_string();
        assert!(
            err.contains(&format!("bad_region.toml:{line}:"))
                && err.contains("\"light\"")
                && err.contains("32×32"),
            "{err}"
        );
    }
    assert!(
        !dir.join("none/references").exists(),
        "nothing was rendered"
    );

    // A corrupt cell file in the results: an error naming it, not a panic.
    let spec = tiny_spec(&dir, "{ passes = 4 }");
    let exp = Experiment::load(&spec, false).unwrap();
    let results = dir.join("results");
    experiment::run(&exp, &options(&results), &ProgressBar::hidden()).unwrap();
    let cell = results.join("tiny/cells/pt-run1.csv");
    let intact = std::fs::read_to_string(&cell).unwrap();
    std::fs::write(&cell, "garbage,\u{0}\n1,2,3\n").unwrap();
    let err = experiment::report_only(&exp, &results, &ProgressBar::hidden())
        .unwrap_err()
        .to_string();
    assert!(err.contains("pt-run1.csv"), "{err}");
    // Rows that parse but cannot be results: refused naming the file and the row's line
    // (line 3 is the second row: checkpoint 0 of the region).
    let second: Vec<&str> = intact.lines().nth(2).unwrap().split(',').collect();
    let with = |i: usize, value: &str| {
        let mut f = second.clone();
        f[i] = value;
        f.join(",")
    };
    let duplicate = intact.lines().nth(1).unwrap().to_string();
    for (bad, what) in [
        (with(7, "nan"), "relmse"),
        (with(8, "-1e-3"), "rmse"),
        (with(9, "inf"), "mape"),
        (with(3, "-0.5"), "seconds"),
        (with(1, "4294967297"), "run must be"),
        (with(2, "99999999999"), "checkpoint must be"),
        (with(1, "0"), "names pt run 0"),
        (with(0, "eyelight"), "names eyelight"),
        (with(2, "6"), "out of range"),
        (with(6, "nowhere"), "region \"nowhere\""),
        (duplicate, "appears twice"),
    ] {
        let mut lines: Vec<&str> = intact.lines().collect();
        lines[2] = &bad;
        std::fs::write(&cell, lines.join("\n") + "\n").unwrap();
        let err = experiment::report_only(&exp, &results, &ProgressBar::hidden())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("pt-run1.csv:3:") && err.contains(what),
            "{bad}: {err}"
        );
    }
    std::fs::write(&cell, &intact).unwrap();
    experiment::report_only(&exp, &results, &ProgressBar::hidden()).unwrap();

    // A changed experiment does not mix with earlier results.
    let changed = spec.with_file_name("tiny.toml");
    std::fs::write(&changed, good.replace("seed = 3", "seed = 4")).unwrap();
    let exp2 = Experiment::load(&changed, false).unwrap();
    let err = experiment::run(&exp2, &options(&results), &ProgressBar::hidden())
        .unwrap_err()
        .to_string();
    assert!(err.contains("--fresh"), "{err}");
}

/// Runs the mltbench binary in `dir`.
fn mltbench_in(dir: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_mltbench"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

#[test]
fn lecture_specs_say_they_run_whole() {
    let dir = temp_dir("lecture-cli");
    let spec = dir.join("spectra.toml");
    std::fs::write(
        &spec,
        "kind = \"sampling-spectra\"\ndescription = \"x\"\npoints = 64\nrealisations = 1\n\
         max_frequency = 4\n",
    )
    .unwrap();
    let report = mltbench_in(&dir, &["report", "spectra.toml"]);
    let err = String::from_utf8_lossy(&report.stderr);
    assert!(!report.status.success());
    assert!(
        err.contains("spectra.toml") && err.contains("no separate report") && err.contains("run"),
        "{err}"
    );
    assert!(!err.contains("unknown field"), "{err}");
    let cell = mltbench_in(&dir, &["run", "spectra.toml", "--cell", "0"]);
    let err = String::from_utf8_lossy(&cell.stderr);
    assert!(
        !cell.status.success() && err.contains("runs whole"),
        "{err}"
    );
    // A kind that is not a string is a lecture spec with a bad kind, not an estimator race.
    std::fs::write(&spec, "kind = 3\ndescription = \"x\"\n").unwrap();
    let run = mltbench_in(&dir, &["run", "spectra.toml", "--results", "res"]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && err.contains("spectra.toml:1: kind: kind must be a string"),
        "{err}"
    );
}

/// The names of the files under `dir` (recursively, relative to it), sorted.
fn files_under(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                out.push(path.strip_prefix(dir).unwrap().display().to_string());
            }
        }
    }
    out.sort();
    out
}

#[test]
fn fresh_with_one_cell_discards_only_that_cells_files() {
    let dir = temp_dir("fresh-cell");
    let spec = tiny_spec(&dir, "{ passes = 4 }");
    let exp = Experiment::load(&spec, false).unwrap();
    let results = dir.join("results");
    experiment::run(&exp, &options(&results), &ProgressBar::hidden()).unwrap();
    let out = results.join("tiny");
    let before = files_under(&out);
    let rows_before = rows_without_time(&results);
    // A stale checkpoint of cell 0 (pt run 0) and one of cell 1 (pt run 1).
    std::fs::write(out.join("checkpoints/pt/run0-cp99.exr"), b"stale").unwrap();
    std::fs::write(out.join("checkpoints/pt/run1-cp99.exr"), b"other").unwrap();

    // `--cells --fresh` only lists.
    let cells = mltbench_in(
        &dir,
        &[
            "run",
            "tiny.toml",
            "--cells",
            "--fresh",
            "--results",
            "results",
        ],
    );
    assert!(cells.status.success());
    assert!(out.join("checkpoints/pt/run0-cp99.exr").exists());

    let mut fresh = options(&results);
    fresh.cell = Some(0);
    fresh.fresh = true;
    let cell_csv = out.join("cells/pt-run0.csv");
    let other_csv = out.join("cells/pt-run1.csv");
    let other_text = std::fs::read(&other_csv).unwrap();
    std::fs::write(&cell_csv, "stale\n").unwrap();
    experiment::run(&exp, &fresh, &ProgressBar::hidden()).unwrap();
    // Cell 0 was redone from nothing; every other cell's files are untouched.
    assert!(!out.join("checkpoints/pt/run0-cp99.exr").exists());
    assert!(out.join("checkpoints/pt/run1-cp99.exr").exists());
    assert_eq!(std::fs::read(&other_csv).unwrap(), other_text);
    std::fs::remove_file(out.join("checkpoints/pt/run1-cp99.exr")).unwrap();
    assert_eq!(files_under(&out), before);
    let summary = experiment::report_only(&exp, &results, &ProgressBar::hidden()).unwrap();
    assert!(summary.missing_cells.is_empty());
    assert_eq!(rows_without_time(&results), rows_before);

    // Results of a different experiment: --cell K --fresh refuses and deletes nothing.
    let changed = dir.join("changed");
    std::fs::create_dir_all(&changed).unwrap();
    let text = std::fs::read_to_string(&spec).unwrap();
    let changed_spec = changed.join("tiny.toml");
    std::fs::write(&changed_spec, text.replace("seed = 3", "seed = 4")).unwrap();
    let exp2 = Experiment::load(&changed_spec, false).unwrap();
    let err = experiment::run(&exp2, &fresh, &ProgressBar::hidden())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("fingerprint.txt") && err.contains("--prepare --fresh"),
        "{err}"
    );
    assert_eq!(files_under(&out), before);
}

/// A stand-in `sbatch` for `experiments/slurm/run-array.sh`: it refuses what a real one would
/// refuse or do wrong (an `--output` file whose folder does not exist, a dependency without
/// `--kill-on-invalid-dep=yes`, an unknown option), records every call's arguments, then
/// runs the job script at once (each `--array` index in turn) in its `--chdir` with its output
/// in the `--output` file. A job that depends `afterok` on a failed job is not run, as Slurm
/// cancels it.
const FAKE_SBATCH: &str = r#"#!/usr/bin/env bash
state="$(dirname "$0")"
id=$(( $(cat "$state/last-id" 2>/dev/null || echo 100) + 1 ))
echo "$id" >"$state/last-id"
{ printf '%s\n' "$@"; echo '-- end of call --'; } >>"$state/calls"
output=""; array=""; dependency=""; kill=""; chdir="$PWD"
while (($#)); do
    case "$1" in
        --parsable) ;;
        --output) output="$2"; shift ;;
        --array) array="$2"; shift ;;
        --dependency) dependency="$2"; shift ;;
        --kill-on-invalid-dep=yes) kill=yes ;;
        --chdir) chdir="$2"; shift ;;
        --job-name | --cpus-per-task | --time | --partition) shift ;;
        --account=* | --mem=* | --qos=* | --time=*) ;;
        -*) echo "sbatch: unrecognized option '$1'" >&2; exit 1 ;;
        *) break ;;
    esac
    shift
done
script="$1"; shift
if [[ -n "$dependency" && "$kill" != yes ]]; then
    echo "sbatch: --dependency $dependency without --kill-on-invalid-dep=yes" >&2; exit 1
fi
if [[ -z "$output" || ! -d "$(dirname "$output")" ]]; then
    echo "sbatch: the folder of --output '$output' does not exist" >&2; exit 1
fi
echo "$id"
if [[ "$dependency" == afterok:* ]] && grep -qx "${dependency#afterok:}" "$state/failed" 2>/dev/null; then
    exit 0
fi
cd "$chdir"
run() { # $1: the array index, or empty
    local out="${output//%j/$id}"; out="${out//%A/$id}"; out="${out//%a/$1}"; out="${out//%%/%}"
    SLURM_JOB_ID="$id" SLURM_ARRAY_TASK_ID="$1" bash "$script" "${@:2}" >"$out" 2>&1 ||
        echo "$id" >>"$state/failed"
}
if [[ -n "$array" ]]; then
    IFS=, read -r -a parts <<<"$array"
    for part in "${parts[@]}"; do
        for ((i = ${part%-*}; i <= ${part#*-}; i++)); do run "$i" "$@"; done
    done
else
    run "" "$@"
fi
"#;

/// Runs `experiments/slurm/run-array.sh SPEC EXTRA...` in `dir` with the stand-in `sbatch`
/// (state in `dir/fake-bin`) and `MLTBENCH` set to `mltbench`.
fn slurm_run(dir: &Path, spec: &Path, extra: &[&str], mltbench: &Path) -> std::process::Output {
    let fake = dir.join("fake-bin");
    std::fs::create_dir_all(&fake).unwrap();
    let sbatch = fake.join("sbatch");
    std::fs::write(&sbatch, FAKE_SBATCH).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&sbatch, std::fs::Permissions::from_mode(0o755)).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/slurm/run-array.sh");
    let path = format!("{}:{}", fake.display(), std::env::var("PATH").unwrap());
    std::process::Command::new("bash")
        .arg(script)
        .arg(spec)
        .args(extra)
        .env("PATH", path)
        .env("MLTBENCH", mltbench)
        .env("CPUS_PER_CELL", "1")
        .env("REPORT_TIME_LIMIT", "00:07:00")
        .current_dir(dir)
        .output()
        .unwrap()
}

/// The stand-in sbatch's calls since the last `take_calls`, each as its arguments.
fn take_calls(dir: &Path) -> Vec<Vec<String>> {
    let file = dir.join("fake-bin/calls");
    let text = std::fs::read_to_string(&file).unwrap_or_default();
    let _ = std::fs::remove_file(&file);
    text.split_terminator("-- end of call --\n")
        .map(|call| call.lines().map(str::to_string).collect())
        .collect()
}

/// The value after `option` in a call.
fn option<'a>(call: &'a [String], option: &str) -> Option<&'a str> {
    let i = call.iter().position(|a| a == option)?;
    call.get(i + 1).map(String::as_str)
}

#[test]
fn a_slurm_array_runs_the_missing_cells_and_reports() {
    let dir = temp_dir("slurm");
    // NAME as a path and a results folder with a space in it.
    let spec = dir.join("experiments dir/tiny.toml");
    std::fs::create_dir_all(spec.parent().unwrap()).unwrap();
    std::fs::rename(tiny_spec(&dir, "{ passes = 4 }"), &spec).unwrap();
    let mltbench = Path::new(env!("CARGO_BIN_EXE_mltbench"));
    let results = dir.join("my res");
    let logs = results.join("slurm-logs");
    let site = ["--sbatch-arg=--account=proj42", "--sbatch-arg", "--mem=1G"];
    let run = |extra: &[&str]| {
        let mut args = vec!["--results", "my res", "--threads", "1"];
        args.extend_from_slice(&site);
        args.extend_from_slice(extra);
        let out = slurm_run(&dir, &spec, &args, mltbench);
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        assert!(
            out.status.success(),
            "{extra:?}: {stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        stdout
    };
    let summary = || std::fs::read_to_string(results.join("tiny/summary.json")).unwrap();

    for extra in [&[][..], &["--fresh"]] {
        let stdout = run(extra);
        assert!(
            stdout.contains("4 of 4 cells as array 102 (0-3)"),
            "{stdout}"
        );
        assert!(summary().contains("\"missing_cells\": []"), "{extra:?}");
        assert_eq!(files_under(&results.join("tiny/cells")).len(), 4);
        let calls = take_calls(&dir.join(""));
        assert_eq!(calls.len(), 3);
        let (prepare, cells, report) = (&calls[0], &calls[1], &calls[2]);
        for call in &calls {
            // Site options reach every job, after the script's own.
            let script = call.iter().position(|a| a.ends_with("job.sh")).unwrap();
            assert!(call[..script].ends_with(&["--account=proj42".into(), "--mem=1G".into()]));
        }
        assert_eq!(option(cells, "--dependency"), Some("afterok:101"));
        assert_eq!(option(report, "--dependency"), Some("afterany:102"));
        assert_eq!(option(report, "--time"), Some("00:07:00"));
        // The prepare job gets only what it needs; --threads is given once.
        let prepare_args = &prepare[prepare.iter().position(|a| a == "--").unwrap()..];
        assert!(!prepare_args.iter().any(|a| a == "--cell"));
        assert_eq!(prepare_args.iter().filter(|a| *a == "--threads").count(), 1);
        assert_eq!(
            prepare_args.contains(&"--fresh".to_string()),
            extra == ["--fresh"]
        );
        let cell_args = &cells[cells.iter().position(|a| a == "--").unwrap()..];
        assert_eq!(cell_args.iter().filter(|a| *a == "--threads").count(), 1);
        assert!(!cell_args.iter().any(|a| a == "--fresh"));
        // Logs under the results folder, named by job (array: array id and index).
        for log in [
            "tiny-prepare-101.out",
            "tiny-cell-102_0.out",
            "tiny-cell-102_3.out",
            "tiny-report-103.out",
        ] {
            assert!(logs.join(log).is_file(), "{log} missing");
        }
        let cell_log = std::fs::read_to_string(logs.join("tiny-cell-102_2.out")).unwrap();
        assert!(
            cell_log.contains("cell 2 done") && cell_log.contains("--results 'my res'"),
            "{cell_log}"
        );
        std::fs::remove_dir_all(&logs).unwrap();
        std::fs::remove_file(dir.join("fake-bin/last-id")).unwrap();
        std::fs::remove_file(results.join("tiny/summary.json")).unwrap();
    }

    // A resubmission queues only the cells not complete: none, then one that was cut short.
    let stdout = run(&[]);
    assert!(stdout.contains("all 4 cells are complete"), "{stdout}");
    assert_eq!(take_calls(&dir).len(), 1);
    assert!(summary().contains("\"missing_cells\": []"));
    std::fs::remove_file(results.join("tiny/images/pt-run1.exr")).unwrap();
    let stdout = run(&[]);
    assert!(stdout.contains("1 of 4 cells as array"), "{stdout}");
    let calls = take_calls(&dir);
    assert_eq!(option(&calls[1], "--array"), Some("1"));
    assert!(summary().contains("\"missing_cells\": []"));

    // Cells 0 and 3 missing, and a folder of builds for MLTBENCH: a list of indices, and each
    // job runs the build its CPU supports (every x86-64 CPU has level v2).
    for cell in ["pt-run0", "preview__biased_-run1"] {
        std::fs::remove_file(results.join(format!("tiny/cells/{cell}.csv"))).unwrap();
    }
    let builds = dir.join("builds");
    std::fs::create_dir_all(builds.join("x86-64-v2/release")).unwrap();
    std::os::unix::fs::symlink(mltbench, builds.join("x86-64-v2/release/mltbench")).unwrap();
    let out = slurm_run(&dir, &spec, &["--results", "my res"], &builds);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains("2 of 4 cells as array"), "{stdout}");
    assert_eq!(option(&take_calls(&dir)[1], "--array"), Some("0,3"));
    assert!(summary().contains("\"missing_cells\": []"));
}

#[test]
fn a_failed_slurm_prepare_job_cancels_the_array_and_the_report_says_why() {
    let dir = temp_dir("slurm-fail");
    // A region off the film: the cells list, but `--prepare` fails before rendering.
    let spec = tiny_spec(&dir, "{ passes = 4 }");
    let text = std::fs::read_to_string(&spec).unwrap();
    std::fs::write(&spec, text.replace("x = 12", "x = 100")).unwrap();
    let out = slurm_run(
        &dir,
        &spec,
        &["--results", "res"],
        Path::new(env!("CARGO_BIN_EXE_mltbench")),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains("the report job's log says why"), "{stdout}");
    let logs = dir.join("res/slurm-logs");
    assert!(!logs.join("tiny-cell-102_0.out").exists(), "the array ran");
    let report = std::fs::read_to_string(logs.join("tiny-report-103.out")).unwrap();
    let prepare_log = logs.join("tiny-prepare-101.out");
    assert!(
        report.contains("the prepare job 101 did not succeed")
            && report.contains(&prepare_log.display().to_string())
            && report.contains("tiny.toml")
            && report.contains("\"light\""),
        "{report}"
    );
}

#[test]
fn the_cli_lists_cell_status_and_its_hints_name_quick_and_results() {
    let dir = temp_dir("cli-quick");
    let spec = tiny_spec(&dir, "{ passes = 4 }");
    let mut text = std::fs::read_to_string(&spec).unwrap();
    text.push_str("\n[quick]\nscale = 1\nruns = 1\n");
    std::fs::write(&spec, text).unwrap();
    let stderr = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).to_string();
    fn with<'a>(args: &[&'a str]) -> Vec<&'a str> {
        [args, &["--quick", "--results", "my res"][..]].concat()
    }

    let cell = mltbench_in(&dir, &with(&["run", "tiny.toml", "--cell", "1"]));
    assert!(cell.status.success(), "{}", stderr(&cell));
    let hint = "`mltbench report tiny.toml --quick --results 'my res'` merges the cells";
    assert!(
        stderr(&cell).contains(&format!("cell 1 done; {hint}")),
        "{}",
        stderr(&cell)
    );
    let again = mltbench_in(&dir, &with(&["run", "tiny.toml", "--cell", "1"]));
    assert!(
        stderr(&again).contains(&format!(
            "cell 1 was already complete (kept as it was); {hint}"
        )),
        "{}",
        stderr(&again)
    );
    let cells = mltbench_in(&dir, &with(&["run", "tiny.toml", "--cells"]));
    let listing = String::from_utf8_lossy(&cells.stdout);
    let rows: Vec<&str> = listing.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(
        rows,
        ["0\tpt\t0\ttodo", "1\tpreview (biased)\t0\tcomplete"],
        "{listing}"
    );

    // One run per estimator under --quick: the README says how to reproduce it, and the
    // relMSE has no interval, as the other columns that need two runs.
    let run = mltbench_in(&dir, &with(&["run", "tiny.toml"]));
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stderr(&run).contains("relMSE") && stderr(&run).contains(" [–] after"));
    let readme = std::fs::read_to_string(dir.join("my res/tiny-quick/README.md")).unwrap();
    assert!(readme.contains("Reproduce with `cargo run --release -- run tiny --quick`"));
    let row = readme.lines().find(|l| l.starts_with("| pt |")).unwrap();
    assert!(row.contains(" [–] |") && !row.contains(", "), "{row}");
    let region = readme.lines().find(|l| l.starts_with("- pt: ")).unwrap();
    assert!(region.ends_with(" [–]"), "{region}");
}
