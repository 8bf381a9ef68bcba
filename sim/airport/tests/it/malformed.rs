//! Malformed airport files: each refused with an error naming the file, the line and the field.

use std::path::Path;

use airport::apt_dat;

fn fixture_text() -> String {
    std::fs::read_to_string(super::fixture::xtsm_path()).expect("fixture")
}

/// The fixture with line `line` (1-based) replaced.
fn with_line(line: usize, text: &str) -> String {
    let mut lines: Vec<String> = fixture_text().lines().map(str::to_string).collect();
    lines[line - 1] = text.to_string();
    lines.join("\n")
}

fn line_of(prefix: &str) -> usize {
    fixture_text()
        .lines()
        .position(|l| l.starts_with(prefix))
        .expect("row in fixture")
        + 1
}

fn error(text: &str) -> String {
    apt_dat::parse(Path::new("bad.dat"), text)
        .expect_err("refused")
        .to_string()
}

#[test]
fn a_bad_field_names_the_file_the_line_and_the_field() {
    let runway = line_of("100 ");
    let cases = [
        (
            runway,
            "100 30.00 1 0 0.25 1 2 0 09 44.0 9.99 0 0 3 0 0 0 27 44.0 x 0 0 3 0 0 0",
            "field 19 (longitude): `x` is not a finite number",
        ),
        (
            runway,
            "100 -3 1 0 0.25 1 2 0 09 44.0 9.99 0 0 3 0 0 0 27 44.0 10.0 0 0 3 0 0 0",
            "field 1 (width): -3 is not > 0",
        ),
        (
            runway,
            "100 30.00 1 0 0.25 1 2 0 09 94.0 9.99 0 0 3 0 0 0 27 44.0 10.0 0 0 3 0 0 0",
            "field 9 (latitude): 94 is outside -90..=90 degrees",
        ),
        (
            runway,
            "100 30.00 1 0 0.25 1 2 0 09 44.0 9.99",
            "field 11 (displaced threshold): missing",
        ),
        (
            runway,
            "100 30.00 24 0 0.25 1 2 0 09 44.0 9.99 0 0 3 0 0 0 27 44.0 10.0 0 0 3 0 0 0",
            "field 2 (surface type): 24: the asphalt and concrete shades are version 1200 and later; the file says 1100",
        ),
        (
            line_of("1202 4 11"),
            "1202 4 11 twoway taxiway_G B",
            "field 4 (type): `taxiway_G` is not",
        ),
        (
            line_of("1202 4 11"),
            "1202 4 99 twoway taxiway_B B",
            "field 2 (end node): no taxi node (1201) has id 99",
        ),
        (
            line_of("1202 4 11"),
            "1202 4 11 sideways taxiway_B B",
            "field 3 (direction): `sideways` is not one of",
        ),
        (
            line_of("1301 A"),
            "1301 H general_aviation",
            "field 1 (size class): `H` is not an ICAO size class A..F",
        ),
        (
            line_of("20 "),
            "20 44.0 10.0 0.00 0 7 {@L}B",
            "field 5 (size): 7 is not a sign size 1-5",
        ),
        (
            line_of("1204 "),
            "1204 takeoff 09,27",
            "field 1 (active zone): `takeoff` is not one of",
        ),
        (
            line_of("1201 ") + 4,
            "1201 44.0 10.0 both 3",
            "field 4 (node id): 3 is already the id of the node on line",
        ),
        (
            line_of("111 "),
            "111 44.0 10.0 4 3",
            "field 4 (style): 3 is not a painted line type (1-99) or lighting type (101-199), or repeats its kind",
        ),
    ];
    for (line, row, expected) in cases {
        let text = with_line(line, row);
        let message = match apt_dat::parse(Path::new("bad.dat"), &text) {
            Err(e) => e.to_string(),
            // Network references are checked when the airport is built.
            Ok(_) => {
                std::fs::write(std::env::temp_dir().join("taxi_sim_bad_network.dat"), &text)
                    .expect("write");
                airport::Airport::read(&std::env::temp_dir().join("taxi_sim_bad_network.dat"), None)
                    .expect_err("refused")
                    .to_string()
            }
        };
        assert!(message.contains(&format!(":{line}: ")), "{row}: {message}");
        assert!(message.contains(expected), "{row}: {message}");
    }
}

#[test]
fn headers_versions_and_structure_are_checked() {
    assert!(
        error("X\n1100 x\n").contains("bad.dat:1: the first line is `X`"),
        "{}",
        error("X\n1100 x\n")
    );
    assert!(error("I\n850 old\n").contains("bad.dat:2: apt.dat version 850 is not read here"));
    assert!(error("I\n1100 x\n").contains("no airport"));
    let old = fixture_text().replacen("1100 taxi-sim", "1000 taxi-sim", 1);
    assert!(
        error(&old).contains("row 1301 is version 1050 and later")
            || error(&old).contains("row 1302 is version 1050 and later"),
        "{}",
        error(&old)
    );
    // An unfinished ring: its feature's header line is named.
    let pavement = line_of("110 1 0.25 0.00 Taxiway B");
    let unfinished = with_line(pavement + 4, "111 44.0 10.0");
    let message = error(&unfinished);
    assert!(message.contains(&format!("bad.dat:{}: the feature begun on line {pavement} ends without a closing (113/114) or end (115/116) node", pavement + 4)), "{message}");
    let stray = format!(
        "{}\n111 44.0 10.0\n",
        fixture_text().trim_end().trim_end_matches("99")
    );
    assert!(
        error(&stray).contains("a node outside a pavement"),
        "{}",
        error(&stray)
    );
}

#[test]
fn unknown_row_codes_are_skipped_and_newer_versions_read() {
    let text = fixture_text().replacen(
        "1302 city Nowhere",
        "1302 city Nowhere\n1400 44.0 10.0 0.0 baggage_train 3 Truck\n1206 0 9 twoway Service",
        1,
    );
    assert!(apt_dat::parse(Path::new("ok.dat"), &text).is_ok());
    let v1200 = fixture_text()
        .replacen("1100 taxi-sim", "1200 taxi-sim", 1)
        .replacen("110 2 0.25", "110 55 0.25", 1);
    let dat = apt_dat::parse(Path::new("ok.dat"), &v1200).expect("1200 with a concrete shade");
    let apron = dat.airports[0]
        .pavements
        .iter()
        .find(|p| p.name == "Apron")
        .expect("apron");
    assert_eq!(
        airport::Surface::of(apron.surface),
        airport::Surface::Concrete
    );
}
