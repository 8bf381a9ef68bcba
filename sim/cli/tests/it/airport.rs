//! `taxi-sim airport show` end to end on the shipped fictional airport: the summary, a route and
//! its picture; a malformed file and an impossible route exit 2 with a located message.

fn taxi_sim(args: &[&str]) -> (i32, String, String) {
    crate::taxi_sim_in(std::path::Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

const XTSM: &str = "../../scenarios/airports/xtsm/apt.dat";

#[test]
fn show_summarises_routes_and_draws_the_fictional_airport() {
    let dir = tempfile::tempdir().expect("tempdir");
    let picture = dir.path().join("xtsm.png");
    let (code, out, err) = taxi_sim(&[
        "airport",
        "show",
        XTSM,
        "--from",
        "S3",
        "--to",
        "runway 27",
        "--via",
        "B,A",
        "--picture",
        picture.to_str().expect("utf-8"),
    ]);
    assert_eq!(code, 0, "{err}");
    for line in [
        "runway 09/27: 1600.0 m x 30.0 m, asphalt",
        "taxi network: 15 nodes, 17 edges (1 code B, 14 code C, 2 runway, 2 one-way), 4.2 km, 1 component(s)",
        "stands (4): 1 gate code B, 2 gate code C, 1 tie_down code A",
        "route stand S3 -> runway 27 via B, A (praetor600, code B)",
        // From the tug's release point, 9.6 m east of where S3's axis meets the taxilane.
        "1025 m along the taxiways, 1017 m driven",
        "pushed back 58 m tail first from the stand (the tug's tightest turn 4.6 m)",
        "tightest turn 6.0 m; speed 6.0 m/s on straights, down to 2.5 in turns",
    ] {
        assert!(out.contains(line), "{line}\n{out}");
    }
    let image = image::open(&picture).expect("a PNG");
    assert_eq!(image.width(), 2000);
    // The route's start marker (green), end marker (red) and the push-back (orange) are drawn.
    let rgb = image.to_rgb8();
    assert!(rgb.pixels().any(|p| p.0 == [0, 170, 0]) && rgb.pixels().any(|p| p.0 == [255, 0, 0]));
    assert!(rgb.pixels().any(|p| p.0 == [230, 120, 0]));
}

#[test]
fn an_airliner_is_refused_taxiway_b_and_a_broken_file_is_located() {
    let (code, _, err) = taxi_sim(&[
        "airport",
        "show",
        XTSM,
        "--from",
        "S2",
        "--to",
        "runway 27",
        "--via",
        "B,A",
        "--vehicle",
        "a320",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("taxi route stand S2 -> runway 27: no path along B, A admitting code C"),
        "{err}"
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.dat");
    let text = std::fs::read_to_string(XTSM)
        .expect("fixture")
        .replacen(
            "1202 4 11 twoway taxiway_B B",
            "1202 4 11 twoway taxiway_B",
            1,
        )
        .replacen("1202 3 10 oneway", "1202 3 10 one_way", 1);
    std::fs::write(&bad, text).expect("write");
    let (code, _, err) = taxi_sim(&["airport", "show", bad.to_str().expect("utf-8")]);
    assert_eq!(code, 2);
    assert!(
        err.contains("bad.dat:")
            && err.contains("row 1202, field 3 (direction): `one_way` is not one of"),
        "{err}"
    );
}
