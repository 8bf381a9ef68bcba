//! The judge's traffic measures in a closed-loop run: a van driving across the front of a
//! standing car strikes it; the contact is reported struck (the car stood), not at fault, the
//! van's time to collision falls to 0 with a conflict event on the way, and its PET is 0 (they
//! were in the conflict area together).

use std::sync::atomic::{AtomicBool, Ordering};

use sim::engine::{Event, Observer, RunHandles, RunSetup, run_with};
use sim::scenario::{RunConfig, Scenario};

/// The IARA car creeps east at 0.02 m/s (standing, by the judge's 0.05 m/s); a van crosses
/// northwards 4 m ahead of its rear axle, through its front.
const STRUCK: &str = r#"
name = "van strikes a standing car"
seed = 5

[world]
min_m = [-20.0, -30.0]
max_m = [60.0, 30.0]

[vehicle]
description = "iara_car"

[route]
waypoints_m = [[0.0, 0.0], [40.0, 0.0]]
speed_m_s = 0.02

[expectations]
end = "any"
no_contact_at_fault = true

[[obstacles]]
id = "van"
kind = "vehicle"
path_m = [[3.5, -15.0], [3.5, 25.0]]
speed_m_s = 3.0
expect = "no_contact"
"#;

/// Records the run's events.
struct Events(Vec<Event>);

impl Observer for Events {
    fn event(&mut self, _t_s: f64, event: &Event) -> sim::Result<()> {
        self.0.push(event.clone());
        Ok(())
    }
}

#[test]
fn a_van_striking_a_standing_car_is_struck_not_at_fault() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("struck.toml");
    std::fs::write(&path, STRUCK).unwrap();
    let s = Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let map_dir = dir.path().join("map");
    sim::offline_map::map_drive(&s, &RunConfig::default(), &map_dir, &mut |_, _| {}).unwrap();
    let stop = AtomicBool::new(false);
    let mut events = Events(Vec::new());
    let r = run_with(
        &s,
        &RunSetup::new(map_dir),
        RunHandles {
            stop: Some(&stop),
            progress: &mut |p| {
                if p.sim_time_s >= 12.0 {
                    stop.store(true, Ordering::Relaxed);
                }
            },
            observer: &mut events,
        },
    )
    .unwrap();
    assert!(!r.contacts.is_empty(), "the van must reach the car: {r:#?}");
    assert_eq!(r.contacts_judged.len(), r.contacts.len());
    assert_eq!(
        (r.contacts_at_fault, r.contacts_struck),
        (0, r.contacts.len())
    );
    for c in &r.contacts_judged {
        assert_eq!(c.contact.object, "van");
        assert!(!c.at_fault && c.vehicle_speed_m_s.abs() <= 0.05, "{c:?}");
    }
    let contact_events: Vec<_> = events
        .0
        .iter()
        .filter_map(|e| match e {
            Event::Contact(c) => Some(c),
            _ => None,
        })
        .collect();
    assert_eq!(contact_events.len(), r.contacts.len());
    assert!(contact_events.iter().all(|c| !c.at_fault));
    // The car feels the strike, stands and calls a pilot: the run ends on the van's first
    // contact - a collision: time to collision and post-encroachment time 0.
    assert_eq!(r.end, sim::engine::EndReason::Struck);
    assert_eq!(r.contacts.len(), 1, "{:?}", r.contacts);
    let van = &r.obstacles[0];
    assert_eq!(van.min_ttc_s, Some(0.0), "{van:?}");
    assert_eq!(van.pet_s, Some(0.0), "{van:?}");
    let conflicts: Vec<f64> = events
        .0
        .iter()
        .filter_map(|e| match e {
            Event::Conflict { id, ttc_s } if id == "van" => Some(*ttc_s),
            _ => None,
        })
        .collect();
    assert_eq!(
        conflicts.len(),
        1,
        "one encounter, one event: {conflicts:?}"
    );
    assert!(conflicts[0] < 3.0 && conflicts[0] > 2.5, "{conflicts:?}");
}

/// The shipped crossing: the jet stops for the car, which crosses first, then drives on; with
/// `expect = "yield"` the pass meets it (the mover went first, PET > 0).
#[test]
fn the_jet_yields_to_the_crossing_car() {
    let shipped = std::fs::read_to_string(
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../scenarios/crossing_vehicle.toml"),
    )
    .unwrap();
    let yielding = shipped.replace("expect = \"stop\"", "expect = \"yield\"");
    assert_ne!(yielding, shipped);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("yielding.toml");
    std::fs::write(&path, &yielding).unwrap();
    let s = Scenario::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let map_dir = dir.path().join("map");
    sim::offline_map::map_drive(&s, &RunConfig::default(), &map_dir, &mut |_, _| {}).unwrap();
    let r = sim::engine::run(&s, &RunSetup::new(map_dir)).unwrap();
    let car = &r.obstacles[0];
    assert!(r.expectations_met, "{r:#?}");
    assert!(
        !car.passes.is_empty() && car.passes.iter().all(|p| p.met),
        "{car:?}"
    );
    assert_eq!(car.pet_mover_first, Some(true), "{car:?}");
    assert!(car.pet_s.is_some_and(|p| p > 0.0), "{car:?}");
    assert!(car.min_ttc_s.is_some_and(|t| t > 0.0), "{car:?}");
}
