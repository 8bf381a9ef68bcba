//! `taxi-sim tune` end to end on the tuning smoke sweep (`scenarios/campaigns/tune_smoke.toml`:
//! the fake-wing car over a cone under its wing, six settings of levels and circle model): the
//! command runs the campaign, compares the settings and writes the tables, the pictures and the
//! recommended model; what it says about the settings is what the levels make true.

use std::path::Path;
use std::process::Command;

fn column<'a>(header: &[&str], row: &'a [String], name: &str) -> &'a str {
    let i = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    &row[i]
}

/// Splits one CSV line whose quoted fields may hold commas and doubled quotes.
fn split_csv(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

#[test]
fn the_tuning_smoke_sweep_finds_one_level_too_few_and_writes_its_recommendation() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("tune");
    let status = Command::new(env!("CARGO_BIN_EXE_taxi-sim"))
        .current_dir(&root)
        .args(["tune", "scenarios/campaigns/tune_smoke.toml", "--out"])
        .arg(&dir)
        .args(["--poses", "100", "--jobs", "2"])
        .status()
        .unwrap();
    assert_eq!(
        status.code(),
        Some(0),
        "a setting without unsafe runs: exit 0"
    );

    let csv = std::fs::read_to_string(dir.join("settings.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<String>> = lines.map(split_csv).collect();
    assert_eq!(rows.len(), 6, "{csv}");
    for row in &rows {
        assert_eq!(row.len(), header.len(), "{row:?}");
        let get = |name: &str| column(&header, row, name);
        let levels: usize = get("levels").parse().unwrap();
        let conservative: usize = get("false_stops").parse::<usize>().unwrap()
            + get("needless_deviations").parse::<usize>().unwrap();
        // One level: the wing's circles see the cone, so the car goes round it (or stops);
        // with a level under the wing it passes over it, as the scenario expects.
        if levels == 1 {
            assert!(conservative >= 1, "{row:?}");
        } else {
            assert_eq!(conservative, 0, "{row:?}");
        }
        assert_eq!(get("contacts"), "0", "{row:?}");
        assert_eq!(get("poses"), "400", "4 places x 100 poses: {row:?}");
        // Every model is a fit: it covers every part, so it misses nothing beyond the lookup.
        assert_eq!(get("misses_beyond_lookup"), "0", "{row:?}");
        assert!(get("circle_ns_per_check").parse::<f64>().unwrap() > 0.0);
        let ratio: f64 = get("exact_ns_per_check").parse::<f64>().unwrap()
            / get("circle_ns_per_check").parse::<f64>().unwrap();
        assert!(ratio > 10.0, "the exact reference is the slow one: {row:?}");
    }
    let front = std::fs::read_to_string(dir.join("pareto.csv")).unwrap();
    let front_rows: Vec<&str> = front.lines().skip(1).collect();
    assert!(!front_rows.is_empty());
    for line in &front_rows {
        assert!(csv.contains(line), "{line} is not a setting");
        assert!(line.ends_with(",true"), "{line}");
    }
    // The recommendation: a two-level setting, as a run configuration and a CARMEN file.
    let rec = dir.join("recommended");
    let config = sim::scenario::RunConfig::from_file(&rec.join("config.toml")).unwrap();
    let heights = config.mapping.heights_of_interest_m.clone().unwrap();
    assert_eq!(heights.len(), 2, "{heights:?}");
    let model = aircraft::carmen::from_carmen_file(&rec.join("model.carmen"), &heights).unwrap();
    let vehicle = aircraft::Vehicle::shipped("iara_car_fake_wing").unwrap();
    assert_eq!(model, config.collision_model(&vehicle).unwrap());
    for (stem, size) in [("pareto", (1200, 560)), ("recommended/model", (1040, 560))] {
        let png = image::open(dir.join(format!("{stem}.png"))).unwrap();
        assert_eq!((png.width(), png.height()), size, "{stem}");
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("</svg>"), "{stem}");
    }
    let md = std::fs::read_to_string(dir.join("tune.md")).unwrap();
    assert!(md.contains("Recommended: setting"), "{md}");
}
