//! Small airports written for one case each: two stands on one taxilane edge, a route returning
//! to a taxiway it left, an edge of no length, a split Bezier node - where a route search or a
//! line drawing goes wrong quietly if it goes wrong at all.

use airport::{Airport, Place, RouteRequest, SizeClass};

/// `body` (rows after the header and datum) read as an airport from a file of its own.
fn airport(name: &str, body: &str) -> Airport {
    let text = format!(
        "I\n1100 test\n\n1 500 0 0 TEST Test\n1302 datum_lat 43.0\n1302 datum_lon -76.0\n{body}99\n"
    );
    let path =
        std::env::temp_dir().join(format!("taxi_sim_small_{name}_{}.dat", std::process::id()));
    std::fs::write(&path, text).expect("write");
    let a = Airport::read(&path, None).expect("reads");
    std::fs::remove_file(&path).ok();
    a
}

fn route(a: &Airport, from: &str, to: &str, via: &[&str]) -> Result<airport::NetworkRoute, String> {
    let request = RouteRequest {
        from: Place::parse(from),
        to: Place::parse(to),
        via: via.iter().map(|v| (*v).to_string()).collect(),
        code: SizeClass::C,
    };
    airport::find(a, &request).map_err(|e| e.to_string())
}

/// Three nodes in a row 0.01 degrees of longitude apart (813 m at 43 N), joined by `names`.
fn line_of_three(names: [&str; 3]) -> String {
    let mut body = String::new();
    for i in 0..4 {
        body += &format!(
            "1201 43.0 {:.2} both {i} n{i}\n",
            -76.0 + 0.01 * f64::from(i)
        );
    }
    for (i, name) in names.iter().enumerate() {
        body += &format!("1202 {i} {} twoway taxiway_E {name}\n", i + 1);
    }
    body
}

/// Two gates abeam one edge: from abeam the first along that edge and into the second (about
/// 326 m + 33 m), not round the network - before, the search joined a start and an end on one edge only
/// through the edge's end nodes, and with no turning back found no path.
#[test]
fn two_stands_on_one_taxilane_edge_are_joined_along_it() {
    let a = airport(
        "stands",
        &(line_of_three(["A", "A", "A"])
            + "1300 43.0003 -75.997 180.0 gate jets G1\n1300 43.0003 -75.993 180.0 gate jets G2\n"),
    );
    let lead_m = (a.stand("G1").expect("G1").at.y).abs();
    let r = route(&a, "G1", "G2", &[]).expect("a route");
    let along_m = (a.stand("G2").expect("G2").at.x - a.stand("G1").expect("G1").at.x).abs();
    assert!(
        (r.length_m - (along_m + lead_m)).abs() < 0.05,
        "{} {along_m} {lead_m}",
        r.length_m
    );
    assert_eq!(r.taxiways, ["A"]);
    // Back the other way too (the edge is two-way).
    assert!((route(&a, "G2", "G1", &[]).expect("back").length_m - r.length_m).abs() < 0.01);
}

/// A line A - B - A: the route may name A twice, and after its list any taxiway leads on.
#[test]
fn via_may_return_to_a_taxiway_it_left() {
    let a = airport("via", &line_of_three(["A", "B", "A"]));
    for via in [&["A", "B", "A"][..], &["A", "B"], &["B"]] {
        let r = route(&a, "node 0", "node 3", via).unwrap_or_else(|e| panic!("{via:?}: {e}"));
        assert_eq!(r.taxiways, ["A", "B", "A"], "{via:?}");
    }
    // Out of order is still refused.
    assert!(route(&a, "node 0", "node 3", &["B", "A", "B"]).is_err());
}

/// Two nodes at one place joined by an edge of no length: a stand abeam the next edge is
/// reached along the taxiway (before, the empty edge's NaN projection won and the route went
/// across the grass, or found no path).
#[test]
fn an_edge_of_no_length_is_passed_over() {
    let body = "1201 43.0 -76.0 both 0 n0\n1201 43.0 -76.0 both 1 n1\n\
                1201 43.0 -75.99 both 2 n2\n1201 43.0 -75.98 both 3 n3\n\
                1202 0 1 twoway taxiway_E X\n1202 1 2 twoway taxiway_E A\n\
                1202 2 3 twoway taxiway_E A\n1300 43.0003 -75.995 180.0 gate jets G1\n";
    let a = airport("zero", body);
    let g1 = a.stand("G1").expect("G1").at;
    let n0 = a.network.nodes[0].at;
    let r = route(&a, "node 0", "G1", &[]).expect("to the stand");
    let expected = (g1.x - n0.x).abs() + g1.y.abs();
    assert!(
        (r.length_m - expected).abs() < 0.05,
        "{} {expected}",
        r.length_m
    );
    assert!(route(&a, "G1", "node 3", &[]).is_ok());
}

/// WorldEditor writes a split node as nodes at one place, the first with a handle: a painted
/// line through one is as long as the same line drawn with a plain corner (before, each split
/// drew a needle out along its handle and back).
#[test]
fn a_split_bezier_node_draws_no_needle() {
    let plain = airport(
        "plain",
        "120 line\n111 43.0 -76.0 1\n111 43.01 -76.0 1\n115 43.01 -75.99\n",
    );
    let split = airport(
        "split",
        "120 line\n111 43.0 -76.0 1\n112 43.01 -76.0 43.012 -76.0 1\n111 43.01 -76.0 1\n\
         112 43.01 -76.0 43.01 -75.9975 1\n115 43.01 -75.99\n",
    );
    let length = |a: &Airport| -> f64 {
        a.painted
            .iter()
            .flat_map(|run| run.points.windows(2).map(|w| (w[1] - w[0]).norm()))
            .sum()
    };
    assert!(length(&plain) > 1900.0, "{}", length(&plain));
    assert!(
        (length(&split) - length(&plain)).abs() < 1.0,
        "{} {}",
        length(&split),
        length(&plain)
    );
}

/// Two stands named alike ("Cargo 1", as a real file has them): a route from either name alone
/// is refused, the error listing both with their lines and places and how to pick one; `#k`
/// picks the k-th in file order, and a number past them is refused the same way.
#[test]
fn an_ambiguous_stand_name_is_an_error_listing_each_and_k_picks_one() {
    let a = airport(
        "cargo",
        &(line_of_three(["A", "A", "A"])
            + "1300 43.0003 -75.997 180.0 gate jets Cargo 1\n1300 43.0003 -75.993 180.0 gate jets Cargo 1\n"),
    );
    let e = route(&a, "Cargo 1", "node 3", &[]).unwrap_err().to_string();
    assert!(e.contains("ambiguous") && e.contains("2 stands"), "{e}");
    assert!(
        e.contains("`Cargo 1#1` (line 14") && e.contains("`Cargo 1#2` (line 15"),
        "{e}"
    );
    assert!(a.stand("Cargo 1").is_none());
    let first = a.find_stand("Cargo 1#1").unwrap();
    let second = a.find_stand("Cargo 1#2").unwrap();
    assert_eq!((first.line, second.line), (14, 15));
    assert!(second.at.x > first.at.x + 300.0);
    let r = route(&a, "Cargo 1#2", "node 0", &[]).expect("a route from the second");
    assert!(r.length_m > 0.0);
    let e = a.find_stand("Cargo 1#3").unwrap_err();
    assert!(e.contains("2 stand(s) named `Cargo 1`"), "{e}");
    let e = a.find_stand("Cargo 9").unwrap_err();
    assert!(e.contains("no stand `Cargo 9`"), "{e}");
}
