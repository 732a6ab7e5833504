//! The files a command will write, checked before it does any work: an EXR with the right
//! extension, every file written beside it (PNG preview, JSON description) writable, and
//! none of them one of the command's inputs (the scene, its meshes and images), which a
//! finished render would otherwise overwrite.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::atomic::check_writable;

/// The files written beside `exr` (`exr` with each of `sidecar_extensions`, in that
/// order), after checking that `exr` ends in `.exr` and that it and each of them can be
/// written. Cheap: for commands to call before they read anything.
pub fn check_outputs(exr: &Path, sidecar_extensions: &[&str]) -> Result<Vec<PathBuf>> {
    if exr.extension().and_then(|e| e.to_str()) != Some("exr") {
        return Err(Error::usage(format!(
            "output {} must end in .exr",
            exr.display()
        )));
    }
    let sidecars: Vec<PathBuf> = sidecar_extensions
        .iter()
        .map(|ext| exr.with_extension(ext))
        .collect();
    check_writable(exr)?;
    for path in &sidecars {
        check_writable(path)?;
    }
    Ok(sidecars)
}

/// Fails, naming both, when one of `outputs` is one of `inputs` (once the inputs are known,
/// e.g. the files a scene read).
pub fn check_not_inputs<'a>(
    outputs: impl IntoIterator<Item = &'a Path>,
    inputs: &[PathBuf],
) -> Result<()> {
    for path in outputs {
        if let Some(input) = inputs.iter().find(|input| same_file(path, input)) {
            return Err(Error::usage(format!(
                "output {} would overwrite the input {}",
                path.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

/// True when `a` and `b` name the same existing file (through links, `..` or a relative
/// path). A file that does not exist yet is no input.
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("mltbench-outputs-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn sidecars_follow_the_exr() {
        let dir = temp_dir("sidecars");
        let sidecars = check_outputs(&dir.join("a.exr"), &["json", "png"]).unwrap();
        assert_eq!(sidecars, vec![dir.join("a.json"), dir.join("a.png")]);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn other_extensions_are_refused() {
        let dir = temp_dir("extension");
        for name in ["a.json", "a.png", "a", "a.EXR.txt"] {
            let err = check_outputs(&dir.join(name), &["png"]).unwrap_err();
            assert!(
                err.to_string().contains("must end in .exr"),
                "{name}: {err}"
            );
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn an_input_is_never_an_output() {
        let dir = temp_dir("inputs");
        let scene = dir.join("scene.exr");
        let sky = dir.join("sky.png");
        std::fs::write(&scene, "x").unwrap();
        std::fs::write(&sky, "x").unwrap();
        let inputs = [scene.clone(), sky.clone()];
        // The same file through another spelling of its path.
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let other_spelling = dir.join("sub/../scene.exr");
        let err = check_not_inputs([other_spelling.as_path()], &inputs).unwrap_err();
        assert!(
            err.to_string().contains("would overwrite the input"),
            "{err}"
        );
        let outputs = [dir.join("sky.exr"), dir.join("sky.png")];
        let err = check_not_inputs(outputs.iter().map(PathBuf::as_path), &inputs).unwrap_err();
        assert!(
            err.to_string().contains(&sky.display().to_string()),
            "{err}"
        );
        // Unrelated outputs, existing or not, pass.
        let outputs = [dir.join("out.exr"), dir.join("out.png")];
        std::fs::write(&outputs[0], "old").unwrap();
        check_not_inputs(outputs.iter().map(PathBuf::as_path), &inputs).unwrap();
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_folder_in_place_of_a_sidecar_is_refused() {
        let dir = temp_dir("folder");
        std::fs::create_dir_all(dir.join("b.json")).unwrap();
        let err = check_outputs(&dir.join("b.exr"), &["json"]).unwrap_err();
        assert!(err.to_string().contains("b.json"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
