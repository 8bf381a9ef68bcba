//! Scenario files, one module per stage of the library's `sim::scenario` pipeline: reading a
//! file and locating its mistakes (`reading`), routes and vehicles (`routes`), static objects
//! and rows of them (`objects`), run-time obstacles, the start-overlap rule and the run's
//! expectations (`obstacles`), and the shipped scenarios, the thesis' experiments among them
//! (`shipped`). Every mistake is an error naming the file, the line, the column and the field;
//! this module holds the valid scenario the error cases edit and the assertions on the errors.

mod airport;
mod objects;
mod obstacles;
mod reading;
mod routes;
mod shipped;

use std::path::{Path, PathBuf};

use sim::scenario::Scenario;
use sim::toml_file::LocatedError;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// A valid scenario the error cases edit.
const BASE: &str = r#"name = "base"
[world]
min_m = [-10.0, -10.0]
max_m = [100.0, 10.0]
[vehicle]
description = "iara_car_fake_wing"
[route]
waypoints_m = [[0.0, 0.0], [50.0, 0.0]]
speed_m_s = 3.0
[[objects]]
id = "lamp"
kind = "lamp_post"
x_m = 20.0
y_m = 5.0
"#;

/// The path errors are labelled with (in the fixtures directory, so relative files resolve there).
fn bad_path() -> PathBuf {
    fixtures().join("bad.toml")
}

fn read(text: &str) -> Result<Scenario, LocatedError> {
    Scenario::from_str(text, &bad_path())
}

/// The error message of a text that must be rejected.
fn error(text: &str) -> String {
    match read(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// `file:line:column` of the first occurrence of `needle` in `text`; with a `|` in the needle,
/// of the character after it (`"laps = |0"`: the value).
fn at(text: &str, needle: &str) -> String {
    let (before, after) = needle.split_once('|').unwrap_or(("", needle));
    let offset = text
        .find(&format!("{before}{after}"))
        .unwrap_or_else(|| panic!("`{needle}` not in the text"))
        + before.len();
    let line = text[..offset].matches('\n').count() + 1;
    let column = offset - text[..offset].rfind('\n').map_or(0, |i| i + 1) + 1;
    format!("{}:{line}:{column}:", bad_path().display())
}

/// Asserts the message starts with the location of `needle`, names `field` and says `says`.
fn assert_error(text: &str, needle: &str, field: &str, says: &str) {
    let message = error(text);
    let location = at(text, needle);
    assert!(
        message.starts_with(&location),
        "expected location {location}\n got: {message}"
    );
    assert!(
        message.contains(&format!("`{field}`")),
        "expected field `{field}`\n got: {message}"
    );
    assert!(message.contains(says), "expected `{says}`\n got: {message}");
}

fn shipped(name: &str) -> Scenario {
    Scenario::from_file(&repo().join("scenarios").join(name)).unwrap_or_else(|e| panic!("{e}"))
}
