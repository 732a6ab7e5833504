//! Helpers shared by the scene-loader tests: scratch folders, scene text, error text.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use mltbench::Error;
use mltbench::scene::SceneDescription;
use mltbench::scene::mitsuba::{load_file, load_str};

#[path = "../scratch_support/mod.rs"]
mod scratch_support;
pub use scratch_support::ScratchDir;

/// A fresh, empty folder for one test (unique per process and test name), removed when the
/// test is done with it.
pub fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new(&format!("loader-{test}"))
}

/// Writes `text` to `dir/name` (creating sub-folders) and returns the path.
pub fn write(dir: &Path, name: &str, text: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).expect("create folder");
    }
    std::fs::write(&path, text).expect("write fixture");
    path
}

/// `<scene version="3.0.0">` around `body`.
pub fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>\n")
}

/// A scene with one default sphere (so it is not empty) plus `body`.
pub fn with_sphere(body: &str) -> String {
    scene(&format!("<shape type=\"sphere\"/>\n{body}"))
}

/// Loads `text` as if it were the file `dir/scene.xml`.
pub fn load_in(dir: &Path, text: &str) -> Result<SceneDescription, Error> {
    load_str(text, &dir.join("scene.xml"))
}

/// Writes `text` to `dir/scene.xml` and loads that file.
pub fn load_written(dir: &Path, text: &str) -> Result<SceneDescription, Error> {
    let path = write(dir, "scene.xml", text);
    load_file(&path)
}

/// Loads a scene that must load.
pub fn load_ok(test: &str, text: &str) -> SceneDescription {
    let dir = scratch(test);
    match load_written(&dir, text) {
        Ok(desc) => desc,
        Err(e) => panic!("scene should load, got: {e}\n{text}"),
    }
}

/// Loads a scene that must fail and returns (message, path of the scene file).
pub fn load_err(test: &str, text: &str) -> (String, PathBuf) {
    let dir = scratch(test);
    let path = dir.join("scene.xml");
    match load_written(&dir, text) {
        Ok(_) => panic!("scene should not load:\n{text}"),
        Err(e) => (e.to_string(), path),
    }
}

/// Loads a scene that must fail, asserts the message names the scene file at `line`, and
/// returns the message.
pub fn load_err_at(test: &str, text: &str, line: usize) -> String {
    let (message, file) = load_err(test, text);
    assert_names(&message, &file, line);
    message
}

/// The 1-based line of the first line of `text` containing `needle`.
pub fn line_of(text: &str, needle: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.contains(needle))
        .expect("needle in text")
}

/// Asserts that `message` names `file` and `file:line`.
pub fn assert_names(message: &str, file: &Path, line: usize) {
    let at = format!("{}:{line}", file.display());
    assert!(message.contains(&at), "message should name {at}: {message}");
}

pub fn approx(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

pub fn approx_v(a: glam::Vec3, b: glam::Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * (1.0 + b.abs().max_element())
}
