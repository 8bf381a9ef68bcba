//! The representation comparison (`taxi-sim bench representations`): the properties each
//! representation must have, on a shipped scene with an overhang, measured pose by pose.

use std::path::{Path, PathBuf};

use sim::scenario::{RunConfig, Scenario};
use sim::studies::representations::drive::Stretch;
use sim::studies::representations::truth::{Near, PoseDraw};
use sim::studies::representations::{Options, SceneResult, compare_scene, spans};

fn scenario(name: &str) -> Scenario {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(name);
    Scenario::from_file(&path).expect("a shipped scenario")
}

fn compare(name: &str, poses: usize) -> SceneResult {
    let s = scenario(name);
    let config = RunConfig::for_scenario(&s, None).expect("its configuration");
    let options = Options {
        stretch: Stretch {
            at_m: None,
            length_m: 200.0,
            spacing_m: Some(8.0),
        },
        draw: PoseDraw {
            count: poses,
            seed: 3,
            near_m: 2.0,
            seen_m: 40.0,
        },
        octomap: None,
    };
    compare_scene(&s, &config, &options, &mut |_, _, _| {}).expect("the comparison")
}

fn row<'a>(r: &'a SceneResult, name: &str) -> &'a sim::studies::representations::Row {
    r.rows
        .iter()
        .find(|x| x.name.starts_with(name))
        .expect("the row")
}

/// Per pose: `a` says colliding wherever `b` does.
fn covers(a: &[bool], b: &[bool]) -> bool {
    a.iter().zip(b).all(|(a, b)| *a || !*b)
}

#[test]
fn under_a_bridge_each_representation_keeps_its_property_pose_by_pose() {
    let r = compare("low_bridge_jet.toml", 800);
    assert_eq!(r.poses.0, 800, "every pose drawn");
    assert!(r.poses.1 > 100, "poses that truly collide: {}", r.poses.1);
    let cumulative = &row(&r, "multi-height, cumulative").judged;
    let banded = &row(&r, "multi-height, banded").judged;
    let voxels = &row(&r, "3D voxels").judged;
    let elevation = &row(&r, "2.5D").judged;
    // A level holds everything above its height: the thesis' grids never miss what the 3D grid
    // holds at a part's height.
    assert!(covers(&cumulative.answers, &voxels.answers));
    // An interval map keeps every hit and clears none: it never misses what the 3D grid holds.
    assert!(covers(&elevation.answers, &voxels.answers));
    // A band is part of its cumulative level: banded never says colliding where cumulative
    // does not (for this two-level jet they are the same grids).
    assert!(covers(&cumulative.answers, &banded.answers));
    // The price of the cumulative grids: the deck 6 m up stops the wings' circles, which 3D
    // lets pass - more false alarms near the overhang than the 3D grid.
    let over = |j: &sim::studies::representations::answers::Judged| {
        j.by_near.get(&Near::Overhang).copied().unwrap_or_default()
    };
    assert!(
        over(cumulative).false_alarms > over(voxels).false_alarms,
        "overhang false alarms: cumulative {:?}, voxels {:?}",
        over(cumulative),
        over(voxels)
    );
    // Costs: the dense 3D grid holds more than ten times the 2D levels' bytes.
    assert!(
        row(&r, "3D voxels").memory_window_bytes > 10 * row(&r, "multi-height").memory_window_bytes
    );
}

#[test]
fn a_circles_span_is_the_parts_it_covers_within_the_vehicle() {
    for name in ["low_bridge_jet.toml", "airliner_wing_over_parked_jet.toml"] {
        let s = scenario(name);
        let vehicle = &s.vehicle.vehicle;
        let config = RunConfig::for_scenario(&s, None).expect("its configuration");
        let model = config.collision_model(vehicle).expect("its model");
        let heights = model.level_heights_m().to_vec();
        let circles = spans::span_circles(&model, vehicle);
        assert_eq!(circles.len(), model.circles().len());
        for c in &circles {
            assert!(c.z_lo_m <= c.z_hi_m, "{name}: {c:?}");
            assert!(c.z_hi_m <= vehicle.top_m() + 1e-9, "{name}: {c:?}");
            // A circle covers parts of its level or above: their undersides are at or above
            // the level's height.
            assert!(c.z_lo_m >= heights[c.level] - 1e-6, "{name}: {c:?}");
        }
        // The wings' circles (level 1 and up) stop well under the vehicle's top: the tail is
        // not above them.
        let upper: Vec<_> = circles.iter().filter(|c| c.level > 0).collect();
        assert!(
            upper.iter().any(|c| c.z_hi_m < vehicle.top_m() - 1.0),
            "{name}: some raised part's circle spans less than the whole height"
        );
    }
}
