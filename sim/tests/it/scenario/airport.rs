//! Airport scenarios (`[airport]`, `route.taxi`): the world taken from an apt.dat - its ground
//! areas, painted lines, furniture and parked aircraft - and the taxi route planned on its
//! network; every mistake located in the scenario file (and, for the apt.dat, in that file).

use sim::world::ObjectKind;

use super::{assert_error, error, read, repo};

/// An airport scenario on the shipped fictional airport (paths relative to the fixtures
/// directory the test scenarios are labelled with).
fn xtsm(extra: &str) -> String {
    let file = repo().join("scenarios/airports/xtsm/apt.dat");
    format!(
        "name = \"x\"\n[airport]\nfile = \"{}\"\n{extra}[vehicle]\ndescription = \"praetor600\"\n[route]\ntaxi = {{ from = \"S3\", to = \"runway 27\", via = [\"B\", \"A\"] }}\nspeed_m_s = 6.0\n",
        file.display()
    )
}

#[test]
fn an_airport_scenario_takes_its_world_from_the_file() {
    let s = read(&xtsm(
        "parked = [{ stand = \"S2\", vehicle = \"a320\" }]\nground_equipment = true\n",
    ))
    .expect("reads");
    // The airport's extent (x -800..800 with the runway, y 0..340 less the runway's half width)
    // and 100 m of grass round it.
    assert!(
        (s.world.min_m[0] + 900.0).abs() < 0.1 && (s.world.max_m[1] - 440.0).abs() < 0.1,
        "{:?} {:?}",
        s.world.min_m,
        s.world.max_m
    );
    assert_eq!(s.world.ground_remission, 0.12);
    assert_eq!(s.world.areas.len(), 8, "7 pavements and the runway");
    let count = |kind| s.objects.iter().filter(|o| o.kind == kind).count();
    let a320 = aircraft::Vehicle::shipped("a320")
        .expect("shipped")
        .parts
        .len();
    assert_eq!(
        (
            count(ObjectKind::Sign),
            count(ObjectKind::LightUnit),
            count(ObjectKind::Windsock)
        ),
        (4, 1, 1)
    );
    // B's two 70 m edge-light lines: a light at 0, 30 and 60 m of each.
    assert_eq!(count(ObjectKind::EdgeLight), 6);
    assert_eq!(count(ObjectKind::ParkedAircraft), a320);
    assert_eq!(
        (count(ObjectKind::Tug), count(ObjectKind::BaggageCart)),
        (1, 1)
    );
    assert!(s.objects.iter().any(|o| o.id == "stand_S2/wing_left#3"));
    // Painted lines: one patch per segment.
    assert!(s.patches.len() > 1000 && s.patches.iter().all(|p| p.id.starts_with("line_")));
    // The route: from where the tug lets go, 9.6 m east of abeam S3 (its push-back's turn and
    // 5 m on), to runway 27's hold point, turns braked into; the vehicle starts on S3.
    let route = &s.route;
    // 1,015 m on the network and the 9.6 m, 8 m less round its three right-angle turns (radius
    // 6.04 m).
    assert!(
        (route.length_m() - 1016.8).abs() < 0.5,
        "{}",
        route.length_m()
    );
    let s3 = s.route.pushback.as_ref().expect("S3 is a gate").poses[0].0;
    assert_eq!(s.vehicle.world_from_start.translation.vector, s3);
    let limits = route.speed_limits_m_s.as_ref().expect("speed limits");
    assert_eq!(limits.len(), route.waypoints_m.len());
    assert!(limits.contains(&6.0) && limits.iter().any(|&v| v < 2.5));
}

#[test]
fn a_world_given_crops_the_airport() {
    let world = "[world]\nmin_m = [-100.0, 100.0]\nmax_m = [800.0, 300.0]\n";
    let text = format!("{}{world}", xtsm(""));
    let s = read(&text);
    // The route ends at 27's hold point (750, 60), outside this world.
    let message = s.expect_err("the route leaves the world").to_string();
    assert!(
        message.contains("`route.taxi`") && message.contains("outside the world"),
        "{message}"
    );
    let world = "[world]\nmin_m = [-100.0, 0.0]\nmax_m = [800.0, 300.0]\n";
    let s = read(&format!("{}{world}", xtsm(""))).expect("reads");
    // The signs at x = -765 and the windsock at y = -80 are left out; the rest stays.
    assert_eq!(
        s.objects
            .iter()
            .filter(|o| o.kind == ObjectKind::Sign)
            .count(),
        3
    );
    assert_eq!(
        s.objects
            .iter()
            .filter(|o| o.kind == ObjectKind::Windsock)
            .count(),
        0
    );
}

#[test]
fn airport_mistakes_are_located() {
    let text = xtsm("parked = [{ stand = \"S9\", vehicle = \"a320\" }]\n");
    assert_error(
        &text,
        "\"S9\"",
        "airport.parked[0].stand",
        "no stand `S9` at XTSM",
    );
    let text = xtsm("parked = [{ stand = \"S2\", vehicle = \"b747\" }]\n");
    assert_error(
        &text,
        "\"b747\"",
        "airport.parked[0].vehicle",
        "cannot load the vehicle",
    );
    let text = xtsm("").replace("praetor600", "a320");
    assert_error(
        &text,
        "{ from",
        "route.taxi",
        "no path along B, A admitting code C",
    );
    let text = xtsm("").replace("via = [\"B\", \"A\"]", "via = [\"Q\"]");
    assert_error(
        &text,
        "{ from",
        "route.taxi",
        "no taxiway `Q` on the network",
    );
    let text = xtsm("").replace(
        "speed_m_s = 6.0",
        "speed_m_s = 6.0\nwaypoints_m = [[0.0, 0.0], [1.0, 0.0]]",
    );
    assert_error(
        &text,
        "[[0.0, 0.0]",
        "route.taxi",
        "give one of waypoints_m, pose_file and taxi",
    );
    // A broken apt.dat: located in the scenario, and the message says where in the apt.dat.
    let dir = tempfile::tempdir().expect("tempdir");
    let broken = dir.path().join("broken.dat");
    let fixture =
        std::fs::read_to_string(repo().join("scenarios/airports/xtsm/apt.dat")).expect("fixture");
    std::fs::write(
        &broken,
        fixture.replacen(
            "1202 4 11 twoway taxiway_B B",
            "1202 4 11 twoway taxiway_B2 B",
            1,
        ),
    )
    .expect("write");
    let text = xtsm("").replace(
        &repo()
            .join("scenarios/airports/xtsm/apt.dat")
            .display()
            .to_string(),
        &broken.display().to_string(),
    );
    let message = error(&text);
    assert!(
        message.contains("`airport.file`")
            && message.contains("broken.dat:")
            && message.contains("row 1202, field 4 (type): `taxiway_B2`"),
        "{message}"
    );
    // Without an airport: a world is needed, and a taxi route has no network.
    let bare = "name = \"x\"\n[vehicle]\ndescription = \"praetor600\"\n[route]\nwaypoints_m = [[0.0, 0.0], [10.0, 0.0]]\nspeed_m_s = 3.0\n";
    assert!(
        error(bare).contains("missing [world] (min_m, max_m), or an [airport] to take it from"),
        "{}",
        error(bare)
    );
    let no_airport = "name = \"x\"\n[world]\nmin_m = [-10.0, -10.0]\nmax_m = [10.0, 10.0]\n[vehicle]\ndescription = \"praetor600\"\n[route]\ntaxi = { from = \"S3\", to = \"runway 27\" }\nspeed_m_s = 3.0\n";
    assert_error(
        no_airport,
        "{ from",
        "route.taxi",
        "a taxi route needs an [airport]",
    );
    let stray_radius = format!(
        "{}turn_radius_m = 20.0\n",
        bare.replace(
            "name = \"x\"\n",
            "name = \"x\"\n[world]\nmin_m = [-10.0, -10.0]\nmax_m = [20.0, 10.0]\n"
        )
    );
    assert!(
        error(&stray_radius).contains("turn_radius_m goes with taxi"),
        "{}",
        error(&stray_radius)
    );
}

/// XTSM with S1's stated aircraft, S2 drawn by `occupancy` (the route's S3 and the code A S4 are
/// never filled), ground equipment, and the map surveyed as `stands` says.
fn surveyed(stands: &str, seed: u64, speed_m_s: f64, occupancy: f64) -> sim::scenario::Scenario {
    let extra = format!(
        "parked = [{{ stand = \"S1\", vehicle = \"praetor600\" }}]\noccupancy = {occupancy}\n\
         ground_equipment = true\nsurveyed_stands = \"{stands}\"\n"
    );
    let text = xtsm(&extra)
        .replace("speed_m_s = 6.0", &format!("speed_m_s = {speed_m_s}"))
        .replacen('\n', &format!("\nseed = {seed}\n"), 1);
    read(&text).expect("reads")
}

#[test]
fn a_surveyed_map_holds_the_stands_as_surveyed_and_one_serves_every_seed_speed_and_occupancy() {
    use sim::campaign::static_world_key;
    let config = sim::scenario::RunConfig::default();
    let key = |s: &sim::scenario::Scenario| static_world_key(s, &config).expect("key");
    let parked_at = |solids: &[sim::world::Solid], stand: &str| {
        solids
            .iter()
            .filter(|o| o.id.starts_with(&format!("stand_{stand}/")))
            .count()
    };
    // A seed whose draw fills S2 and one whose draw leaves it empty (occupancy 0.5).
    let fills = |seed| parked_at(&surveyed("empty", seed, 6.0, 0.5).objects, "S2") > 0;
    let full = (1..40).find(|&s| fills(s)).expect("a seed filling S2");
    let empty = (1..40)
        .find(|&s| !fills(s))
        .expect("a seed leaving S2 empty");
    let (a, b) = (
        surveyed("empty", full, 6.0, 0.5),
        surveyed("empty", empty, 4.0, 0.5),
    );
    let solids = |s: &sim::scenario::Scenario| s.survey_scene().solids;
    let kinds =
        |solids: &[sim::world::Solid], kind| solids.iter().filter(|o| o.kind == kind).count();
    // The run's world has its aircraft, equipment and furniture; the survey only the furniture.
    assert!(parked_at(&a.objects, "S1") > 0 && parked_at(&a.objects, "S2") > 0);
    assert_eq!(kinds(&a.objects, ObjectKind::Tug), 2);
    for k in [
        ObjectKind::ParkedAircraft,
        ObjectKind::Tug,
        ObjectKind::BaggageCart,
    ] {
        assert_eq!(kinds(&solids(&a), k), 0, "{k:?} in the survey");
    }
    for k in [
        ObjectKind::Sign,
        ObjectKind::EdgeLight,
        ObjectKind::Windsock,
    ] {
        assert_eq!(kinds(&solids(&a), k), kinds(&a.objects, k));
    }
    assert_eq!(a.static_scene().solids, a.objects);
    // One survey for both runs, whatever their seeds, speeds and occupancy: every edge of the
    // network (all inside the world) and a leg from each of the four stands to it.
    assert_eq!(solids(&a), solids(&b));
    assert_eq!(key(&a), key(&b));
    let survey = a.survey.as_ref().expect("surveyed");
    let apt = airport::Airport::read(&repo().join("scenarios/airports/xtsm/apt.dat"), None)
        .expect("reads");
    assert_eq!(survey.legs.len(), apt.network.edges.len() + 4);
    assert!(survey.length_m() > 1000.0, "{}", survey.length_m());
    for (leg, stand) in survey.legs[apt.network.edges.len()..]
        .iter()
        .zip(&apt.stands)
    {
        assert_eq!(leg[0].coords, stand.at);
        assert!((leg[1] - leg[0]).norm() < 120.0, "{leg:?}");
    }
    // ... and whatever their route: a survey is the airport's, not the route's.
    let other_route = read(
        &xtsm("surveyed_stands = \"empty\"\noccupancy = 0.5\n").replace(
            "to = \"runway 27\", via = [\"B\", \"A\"]",
            "to = \"runway 09\"",
        ),
    )
    .expect("reads");
    assert_ne!(other_route.route.waypoints_m, a.route.waypoints_m);
    assert_eq!(
        other_route.survey.as_ref().expect("surveyed").legs,
        survey.legs
    );
    assert_eq!(key(&other_route), key(&a));
    // `parked`: S1's stated aircraft and its equipment surveyed, S2's drawn one not.
    let p = surveyed("parked", full, 6.0, 0.5);
    assert_eq!(parked_at(&solids(&p), "S1"), parked_at(&p.objects, "S1"));
    assert_eq!(parked_at(&solids(&p), "S2"), 0);
    assert_eq!(kinds(&solids(&p), ObjectKind::Tug), 1);
    assert_ne!(key(&p), key(&a));
    assert_eq!(key(&p), key(&surveyed("parked", empty, 4.0, 0.5)));
    // `as_run` (the default): the map is the run's own world, its key the run's seed and speed.
    let (c, d) = (
        surveyed("as_run", full, 6.0, 0.5),
        surveyed("as_run", full, 4.0, 0.5),
    );
    assert!(c.survey.is_none());
    assert_eq!(c.survey_scene(), c.static_scene());
    assert_ne!(key(&c), key(&d));
    assert_ne!(key(&c), key(&surveyed("as_run", empty, 6.0, 0.5)));
    assert_ne!(key(&c), key(&a));
    // A survey that is not one of the three.
    let text = xtsm("surveyed_stands = \"full\"\n");
    assert_error(
        &text,
        "\"full\"",
        "airport.surveyed_stands",
        "unknown variant `full`",
    );
}
