//! The window and its block files: the offline map under the live one, re-centring with blocks
//! saved and read back, bad block files named, and the margin the window moves past.

use super::{insert, map_with, p, scene};
use mapper::synthetic::Solid;
use mapper::{Levels, MapConfig, MergeMode, MultiHeightMap};
use nalgebra::Point2;

/// The highest known probability of a level within `r` metres of (x, y): obstacles are mapped
/// on their faces, so presence is tested around an object, not at its centre.
fn max_p_near(map: &MultiHeightMap, k: usize, x: f64, y: f64, r: f64) -> Option<f32> {
    let steps = (r / 0.1).ceil() as i64;
    let mut best: Option<f32> = None;
    for i in -steps..=steps {
        for j in -steps..=steps {
            let (dx, dy) = (i as f64 * 0.1, j as f64 * 0.1);
            if dx * dx + dy * dy <= r * r
                && let Some(v) = p(map, k, x + dx, y + dy)
            {
                best = Some(best.map_or(v, |b: f32| b.max(v)));
            }
        }
    }
    best
}

#[test]
fn the_online_map_takes_unknown_cells_from_the_offline_map() {
    let dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    // Mapping drive: a parked box at (10, 0) and a pillar at (0, 10).
    let offline_scene = scene(vec![
        Solid::standing_box(10.0, 0.0, 1.0, 1.0, 1.5),
        Solid::post(0.0, 10.0, 0.3, 3.0),
    ]);
    let mut mapping = map_with(levels.clone());
    insert(&mut mapping, &offline_scene, 2);
    let store = mapper::BlockStore::open(dir.path(), mapping.block_spec().clone()).unwrap();
    assert!(mapping.save_live(&store).unwrap() > 0);

    // Online: the parked box left, a cone appeared at (5, 0); the pillar is hidden behind a wall.
    let online_scene = scene(vec![
        Solid::post(5.0, -3.0, 0.2, 0.45),
        Solid::Box {
            min: [-3.0, 5.0, 0.0].into(),
            max: [3.0, 5.2, 3.0].into(),
        },
    ]);
    let mut online = MultiHeightMap::with_stores(
        MapConfig::default(),
        levels,
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap();
    assert!(
        max_p_near(&online, 0, 10.0, 0.0, 0.7).unwrap() > 0.9,
        "before any scan the prior shows the parked box"
    );
    insert(&mut online, &online_scene, 2);
    assert!(
        max_p_near(&online, 0, 5.0, -3.0, 0.4).unwrap() > 0.9,
        "the new cone is in the online map"
    );
    assert!(
        max_p_near(&online, 0, 10.0, 0.0, 0.7).unwrap() < 0.5,
        "the box that left is seen free again"
    );
    assert!(
        max_p_near(&online, 0, 0.0, 10.0, 0.5).unwrap() > 0.9,
        "the hidden pillar comes from the offline map"
    );
    assert!(
        online
            .live_log_odds(0)
            .unwrap()
            .at(&Point2::new(0.0, 9.75))
            .unwrap()
            .is_nan(),
        "the live map never saw the pillar"
    );

    // Decay blend: a cell both know mixes 10:1 in probability.
    let mut decay = MultiHeightMap::with_stores(
        MapConfig {
            merge: MergeMode::Decay,
            ..Default::default()
        },
        Levels::cumulative(vec![0.0, 0.7]).unwrap(),
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap();
    insert(&mut decay, &online_scene, 2);
    let pb = max_p_near(&decay, 0, 10.0, 0.0, 0.7).unwrap();
    assert!(
        pb > 0.05 && pb < 0.5,
        "decay keeps a trace of the prior: {pb}"
    );
}

#[test]
fn recentring_saves_and_reloads_blocks_with_their_cells() {
    let live_dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let mut map = MultiHeightMap::with_stores(
        MapConfig::default(),
        levels,
        Point2::origin(),
        None,
        Some(live_dir.path()),
    )
    .unwrap();
    insert(
        &mut map,
        &scene(vec![Solid::standing_box(8.0, 3.0, 1.0, 1.0, 1.2)]),
        2,
    );
    let before = map.probability_grid(0).unwrap();
    let at = Point2::new(7.5, 3.0); // on the box's near face
    let p_before = map.probability_at(0, &at).unwrap();

    // One block east (past the re-centring margin): the window moves by 70 m, cells move with
    // their world positions.
    assert!(map.recenter(Point2::new(80.0, 0.0)).unwrap());
    assert_eq!(map.probability_at(0, &at), Some(p_before));
    // Far away: the whole window goes to disk.
    assert!(map.recenter(Point2::new(1000.0, 1000.0)).unwrap());
    assert_eq!(map.probability_at(0, &at), None);
    assert!(
        !map.recenter(Point2::new(1001.0, 1001.0)).unwrap(),
        "same middle block: no move"
    );
    // Back: every cell as it was.
    assert!(map.recenter(Point2::origin()).unwrap());
    assert_eq!(map.probability_grid(0).unwrap().data(), before.data());
}

#[test]
fn bad_block_files_are_errors_that_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let mut map = map_with(levels.clone());
    insert(&mut map, &scene(vec![Solid::post(4.0, 4.0, 0.3, 1.0)]), 1);
    let store = mapper::BlockStore::open(dir.path(), map.block_spec().clone()).unwrap();
    map.save_live(&store).unwrap();
    let index = mapper::BlockIndex { x: 0, y: 0 };
    let path = store.path(index);
    let good = std::fs::read(&path).unwrap();
    let loaded = store.load(index).unwrap().unwrap();
    let original = map
        .live_blocks()
        .into_iter()
        .find(|b| b.index == index)
        .unwrap();
    let bits = |b: &mapper::Block| {
        b.levels
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert!(
        bits(&loaded) == bits(&original),
        "block round trip changed log-odds"
    );
    // The remission comes back quantized: the count exact, mean and spread within half a step.
    let sampled = original.remission.iter().filter(|r| r.count > 0).count();
    assert!(sampled > 100, "{sampled} cells with samples");
    for (a, b) in original.remission.iter().zip(&loaded.remission) {
        assert_eq!(a.count, b.count);
        if a.count > 0 {
            let (ma, mb) = (a.mean().unwrap(), b.mean().unwrap());
            let (sa, sb) = (a.variance().unwrap().sqrt(), b.variance().unwrap().sqrt());
            assert!((ma - mb).abs() as f64 <= mapper::remission::MEAN_STEP / 2.0 + 1e-6);
            assert!((sa - sb).abs() as f64 <= mapper::remission::SPREAD_STEP / 2.0 + 1e-4);
        }
    }

    let open = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        let err = MultiHeightMap::with_stores(
            MapConfig::default(),
            levels.clone(),
            Point2::origin(),
            Some(dir.path()),
            None,
        )
        .unwrap_err();
        err.to_string()
    };
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 0x40;
    let e = open(&flipped);
    assert!(
        e.contains("block_0_0.tsmb") && e.contains("checksum"),
        "{e}"
    );
    let e = open(&good[..good.len() - 100]);
    assert!(
        e.contains("block_0_0.tsmb") && e.contains("truncated"),
        "{e}"
    );
    let e = open(&good[..20]);
    assert!(e.contains("block_0_0.tsmb"), "{e}");
    let e = open(b"");
    assert!(e.contains("block_0_0.tsmb") && e.contains("magic"), "{e}");
    // Blocks of the uncompressed format 1 and of format 2 (float remission sums) are refused
    // with the remedy.
    for old in [1u32, 2] {
        let mut bytes = good.clone();
        bytes[8..12].copy_from_slice(&old.to_le_bytes());
        let e = open(&bytes);
        assert!(
            e.contains("block_0_0.tsmb")
                && e.contains(&format!("format version {old} ("))
                && e.contains("taxi-sim map"),
            "{e}"
        );
    }
    // The compressed body is smaller than the block it holds.
    let side = map.block_spec().side;
    let raw = (4 * 2 + 6) * side * side;
    assert!(
        good.len() * 4 < raw,
        "{} bytes on disk for {raw}",
        good.len()
    );
    // A block of a map with other levels is refused by field name.
    std::fs::write(&path, &good).unwrap();
    let other = Levels::cumulative(vec![0.0, 0.5]).unwrap();
    let err = MultiHeightMap::with_stores(
        MapConfig::default(),
        other,
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("heights[1]"), "{err}");
}

/// A block whose checksum is valid but which holds a value no map writes (an infinite log-odds,
/// one beyond the clamp, a non-finite remission sum...) is refused, naming the file, the field,
/// the level and the cell; NaN log-odds (unknown) and values at the clamp still load.
#[test]
fn block_with_valid_checksum_and_non_finite_value_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let levels = Levels::cumulative(vec![0.0, 0.7]).unwrap();
    let mut map = map_with(levels.clone());
    insert(&mut map, &scene(vec![Solid::post(4.0, 4.0, 0.3, 1.0)]), 1);
    let spec = map.block_spec().clone();
    let store = mapper::BlockStore::open(dir.path(), spec.clone()).unwrap();
    map.save_live(&store).unwrap();
    let index = mapper::BlockIndex { x: 0, y: 0 };
    let path = store.path(index);
    // A cell with remission samples (a ground return), so a zeroed count contradicts its sums.
    let original = map
        .live_blocks()
        .into_iter()
        .find(|b| b.index == index)
        .unwrap();
    let cell = original
        .remission
        .iter()
        .position(|r| r.count > 0 && r.sum != 0.0)
        .unwrap();
    let (row, column) = (cell / spec.side, cell % spec.side);
    // Writes the block with one value edited (and so a valid checksum) and loads it.
    let load = |edit: &dyn Fn(&mut mapper::Block)| {
        let mut block = original.clone();
        edit(&mut block);
        let bytes = mapper::blocks::encode_block(&spec, &block).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        store.load(index).map(|_| ()).map_err(|e| e.to_string())
    };
    let names = |e: &str, field: &str| {
        e.contains(&path.display().to_string())
            && e.contains(field)
            && e.contains(&format!("cell {cell} (row {row}, column {column})"))
    };
    let e = load(&|b| b.levels[1][cell] = f32::INFINITY).unwrap_err();
    assert!(
        names(&e, "`log_odds` of level 1") && e.contains("inf is infinite"),
        "{e}"
    );
    let e = load(&|b| b.levels[0][cell] = f32::NEG_INFINITY).unwrap_err();
    assert!(names(&e, "`log_odds` of level 0"), "{e}");
    let e = load(&|b| b.levels[0][cell] = 40.0).unwrap_err();
    assert!(
        names(&e, "`log_odds` of level 0") && e.contains("clamp") && e.contains("37"),
        "{e}"
    );
    // A remission cell that is not intensities' statistics is not written at all ...
    for (edit, why) in [
        (
            &|b: &mut mapper::Block| b.remission[cell].sum = f32::NAN,
            "not finite",
        ),
        (
            &|b: &mut mapper::Block| b.remission[cell].sum_sq = -1.0,
            "not a sum of squares",
        ),
        (
            &|b: &mut mapper::Block| b.remission[cell].sum = 3.0 * b.remission[cell].count as f32,
            "outside 0..1",
        ),
        (
            &|b: &mut mapper::Block| b.remission[cell].count = 0,
            "0 samples",
        ),
    ] as [(&dyn Fn(&mut mapper::Block), &str); 4]
    {
        let mut block = original.clone();
        edit(&mut block);
        let e = mapper::blocks::encode_block(&spec, &block)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(why) && e.contains(&format!("cell {cell} (row {row}, column {column})")),
            "{e}"
        );
    }
    // ... and one read with a mean but no samples is refused, naming the cell.
    let mut body = mapper::blocks::encode_body(&spec, &original).unwrap();
    let counts = body.len() - 4 * spec.side * spec.side;
    body[counts + 4 * cell..][..4].copy_from_slice(&0u32.to_le_bytes());
    std::fs::write(
        &path,
        mapper::blocks::frame_body(&spec, index, &body).unwrap(),
    )
    .unwrap();
    let e = store.load(index).map(|_| ()).unwrap_err().to_string();
    assert!(
        names(&e, "`remission.count`") && e.contains("0 samples"),
        "{e}"
    );
    // The map refuses to open over such a prior, naming the file too.
    load(&|b| b.levels[1][cell] = f32::INFINITY).unwrap_err();
    let err = MultiHeightMap::with_stores(
        MapConfig::default(),
        levels.clone(),
        Point2::origin(),
        Some(dir.path()),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(names(&err, "`log_odds` of level 1"), "{err}");
    // What a map can write still loads: unknown (NaN, any payload) and the clamp itself.
    load(&|b| b.levels[1][cell] = f32::from_bits(0x7fc0_1234)).unwrap();
    load(&|b| b.levels[1][cell] = -37.0).unwrap();
    load(&|b| b.levels[0][cell] = 37.0).unwrap();
}

/// A route along a block edge (the aerodrome's taxiway at y = 0) crosses it back and forth:
/// the window moves only once the position is `recenter_margin_m` past the middle block, in
/// any direction, and then centres on the block the position is in.
#[test]
fn the_window_moves_past_a_margin_not_at_every_crossing_of_a_block_edge() {
    let mut map = map_with(Levels::cumulative(vec![0.0]).unwrap());
    let margin = map.config().recenter_margin_m;
    assert_eq!(margin, 8.0);
    let lo = map.window_origin_block();
    // Middle block: [0, 70) x [0, 70). Zig-zag across y = 0 and x = 70, within the margin.
    for k in 0..40 {
        let wiggle = if k % 2 == 0 { -1.0 } else { 1.0 } * (0.05 + 0.19 * k as f64);
        for at in [
            Point2::new(30.0, wiggle),
            Point2::new(70.0 + wiggle, 30.0),
            Point2::new(-margin + 0.01, 70.0 + margin - 0.01),
        ] {
            assert!(!map.recenter(at).unwrap(), "{at:?}");
            assert_eq!(map.window_origin_block(), lo);
        }
    }
    // Just past the margin to the south: the window centres on the block below.
    assert!(map.recenter(Point2::new(30.0, -margin - 0.01)).unwrap());
    assert_eq!(
        (map.window_origin_block().x, map.window_origin_block().y),
        (lo.x, lo.y - 1)
    );
    // Back north across the edge, within the margin of the new middle block: stays.
    assert!(!map.recenter(Point2::new(30.0, margin - 0.01)).unwrap());
    assert!(map.recenter(Point2::new(30.0, margin + 0.01)).unwrap());
    assert_eq!(map.window_origin_block(), lo);
    // A margin over half a block is refused, naming the field.
    let config = MapConfig {
        recenter_margin_m: 36.0,
        ..MapConfig::default()
    };
    let err = config.validate().unwrap_err().to_string();
    assert!(err.contains("recenter_margin_m"), "{err}");
}
