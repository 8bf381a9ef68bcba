//! A taxi on an airport read from an apt.dat, in closed loop (issue 37): the shipped fictional
//! XTSM, its route planned by taxiway names, its furniture and parked aircraft in the world.

use sim::scenario::RunConfig;

use crate::common::{run_with, scenario};

#[test]
fn the_jet_taxis_from_a_stand_to_the_runway_by_b_and_a() {
    let s = scenario("xtsm_stand_to_runway");
    let r = run_with(&s, RunConfig::for_scenario(&s, None).unwrap());
    assert!(r.expectations_met && r.contacts.is_empty(), "{r:#?}");
    let outcome = |id: &str| {
        r.obstacles
            .iter()
            .find(|o| o.id == id)
            .map(|o| o.passes[0].outcome.as_str().to_string())
    };
    assert_eq!(outcome("cone_under_wing").as_deref(), Some("passed"));
    assert_eq!(outcome("cart_on_a").as_deref(), Some("stopped"));
    // One stop, short of the cart (x = 560 m, 714 m along the route), until it goes at 150 s;
    // then on to the hold point (1,007 m).
    assert_eq!(r.stops.len(), 1, "{:?}", r.stops);
    let stop = &r.stops[0];
    assert!((700.0..725.0).contains(&stop.route_s_m), "{stop:?}");
    assert!(
        stop.end_s.is_some_and(|t| (150.0..155.0).contains(&t)),
        "{stop:?}"
    );
    assert!(
        r.lap_times_s[0] > 150.0 && r.lap_times_s[0] < 260.0,
        "{:?}",
        r.lap_times_s
    );
    // How close the route came to the airport's furniture (ground truth): B's edge lights, 10 m
    // either side of its centreline, pass 1.4 m under the wings; nothing nearer.
    let nearest = &r.closest_static;
    assert!(
        nearest.len() >= 6 && nearest[..6].iter().all(|c| c.id.starts_with("edge_light_")),
        "{nearest:?}"
    );
    assert!(
        (1.2..1.6).contains(&nearest[0].min_clearance_m),
        "{nearest:?}"
    );
}
