//! Overhead structures and the offline map: every vehicle's map has a ceiling (its top plus its
//! sidecar's `overhead_clearance_m`); what is above it is no obstacle. The closed-loop runs under
//! and short of them are the scenario files' (`scenarios/{canopy_car,footbridge_jet,low_bar_car,
//! low_bridge_jet,airliner_wing_over_parked_jet}.toml`, their expectations and golden numbers,
//! `taxi-sim regress`).

use sim::scenario::{RunConfig, Scenario};

use crate::common::scenario;

/// The footbridge 9 m up is in no level of the jet: as a static object, the offline map holds
/// exactly what it holds without it. (The jet passed under it before the ceiling too, only
/// because its nose sensor stops seeing the deck 40 m out.)
#[test]
fn a_footbridge_above_the_jets_ceiling_is_in_no_level_of_its_map() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(&scenario("footbridge_jet").path).unwrap();
    let (before, deck) = text.split_once("[[obstacles]]").unwrap();
    let deck = deck.replace("expect = \"pass_under\"\n", "");
    let occupied = |text: &str, name: &str| {
        let path = dir.path().join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let s = Scenario::from_file(&path).unwrap();
        sim::offline_map::map_drive(
            &s,
            &RunConfig::default(),
            &dir.path().join(name),
            &mut |_, _| {},
        )
        .unwrap()
        .occupied_cells
    };
    let with_deck = occupied(&format!("{before}[[objects]]{deck}"), "with");
    let without = occupied(before, "without");
    assert_eq!(with_deck, without);
}
