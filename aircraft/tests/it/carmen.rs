//! CARMEN collision files: reading the published car, round trips, and errors naming file and line.

use aircraft::Vehicle;
use aircraft::carmen::{from_carmen_file, from_carmen_str, to_carmen_string, write_carmen_file};

/// CARMEN's `bin/ford_escape/ford_escape_col.txt` (as FACTS.md gives it).
const FORD_ESCAPE_COL: &str =
    "5\n0\n-0.76 0.0 1.0 0\n0.207 0.0 1.0 0\n1.174 0.0 1.0 0\n2.141 0.0 1.0 0\n3.108 0.0 1.0 0\n";

#[test]
fn reads_carmens_car() {
    let model = from_carmen_str(FORD_ESCAPE_COL, "ford_escape_col.txt", &[0.0]).expect("reads");
    let xs: Vec<f64> = model.circles().iter().map(|c| c.x_m).collect();
    assert_eq!(xs, vec![-0.76, 0.207, 1.174, 2.141, 3.108]);
    for c in model.circles() {
        assert_eq!((c.y_m, c.radius_m, c.level), (0.0, 1.0, 0));
    }
    assert_eq!(model.level_heights_m(), &[0.0]);
}

#[test]
fn reads_the_multi_height_car_with_given_heights() {
    let mut text = String::from("10\n1\n");
    for x in [-0.76, 0.207, 1.174, 2.141, 3.108] {
        text.push_str(&format!("{x} 0.0 1.0 0\n"));
    }
    for y in [-1.53, -1.4, -1.27, -1.13, -1.0] {
        text.push_str(&format!("3.4 {y} 0.08 1\n"));
    }
    let model = from_carmen_str(&text, "col.txt", &[0.0, 0.7]).expect("reads");
    assert_eq!(model.circles().iter().filter(|c| c.level == 1).count(), 5);
    assert_eq!(model.level_heights_m(), &[0.0, 0.7]);
}

#[test]
fn fitted_models_round_trip() {
    for name in aircraft::SHIPPED_VEHICLES {
        let v = Vehicle::shipped(name).expect("vehicle");
        let fit = v.fit().expect("fit");
        let text = to_carmen_string(&fit.model);
        let back = from_carmen_str(&text, name, fit.model.level_heights_m()).expect("reads back");
        assert_eq!(back, fit.model, "{name}");
    }
}

#[test]
fn file_round_trip_is_written_atomically() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("col.txt");
    let model = from_carmen_str(FORD_ESCAPE_COL, "in", &[0.0]).expect("reads");
    std::fs::write(&path, "old contents").expect("seed");
    write_carmen_file(&path, &model).expect("writes");
    assert_eq!(from_carmen_file(&path, &[0.0]).expect("reads"), model);
    // Only the target is left in the directory: no temporary file lingers.
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1);
}

fn error_of(text: &str, heights: &[f64]) -> String {
    from_carmen_str(text, "bad_col.txt", heights)
        .expect_err("must fail")
        .to_string()
}

#[test]
fn bad_lines_name_file_and_line() {
    let cases: [(&str, &[f64], &str); 8] = [
        ("x\n0\n", &[0.0], "bad_col.txt:1:"),
        ("1\n0\n0 0 1\n", &[0.0], "bad_col.txt:3:"),
        ("1\n0\n0 0 abc 0\n", &[0.0], "bad_col.txt:3:"),
        ("1\n0\n0 0 -1 0\n", &[0.0], "bad_col.txt:3:"),
        ("1\n0\n0 0 1 2\n", &[0.0], "bad_col.txt:3:"),
        ("2\n0\n0 0 1 0\n", &[0.0], "bad_col.txt:1:"),
        ("1\n1\n0 0 1 0\n", &[0.0], "bad_col.txt:2:"),
        ("1\n0\n0 0 1 0\n\n0 nan 1 0\n", &[0.0], "bad_col.txt:5:"),
    ];
    for (text, heights, expected) in cases {
        let e = error_of(text, heights);
        assert!(e.starts_with(expected), "{text:?}: {e}");
    }
    assert!(error_of("", &[0.0]).contains("missing circle count"));
}
