//! ROS map, PNG and .npy exports read back to the same cells.

use mapper::export::{
    PngRows, Trinary, TrinaryThresholds, occupancy_pixel, read_npy, read_ros_map,
    write_distance_png, write_npy, write_occupancy_png, write_ros_map,
};
use mapper::synthetic::{Lidar, Scene, Solid, car_sensor_mount};
use mapper::{Levels, MapConfig, MultiHeightMap};
use nalgebra::{Isometry2, Point2, Vector2};

fn mapped() -> MultiHeightMap {
    let scene = Scene {
        solids: vec![
            Solid::standing_box(6.0, 2.0, 2.0, 1.0, 1.1),
            Solid::post(-4.0, -3.0, 0.2, 0.45),
        ],
        ground_intensity: 0.3,
        solid_intensity: 0.8,
    };
    let config = MapConfig {
        block_cells: 100,
        ..Default::default()
    };
    let mut map = MultiHeightMap::new(
        config,
        Levels::cumulative(vec![0.0, 0.7]).unwrap(),
        Point2::new(1.0, 1.0),
    )
    .unwrap();
    let scan = Lidar::hdl32e()
        .scan(
            &scene,
            &Isometry2::new(Vector2::new(1.0, 1.0), 0.0),
            &car_sensor_mount(),
            |_, _| 0.0,
        )
        .unwrap();
    map.insert_scan(&scan, None).unwrap();
    map.update_distance_maps();
    map
}

/// The PNG image (the mapping drive's) reads back to exactly what the PGM does, and is smaller.
#[test]
fn a_ros_map_with_a_png_image_reads_back_like_the_pgm() {
    let map = mapped();
    let dir = tempfile::tempdir().unwrap();
    let thresholds = TrinaryThresholds::default();
    let probabilities = map.probability_grid(0).unwrap();
    let (pgm_yaml, png_yaml) = (dir.path().join("a.yaml"), dir.path().join("b.yaml"));
    let pgm = write_ros_map(&probabilities, &pgm_yaml, thresholds).unwrap();
    let png = mapper::export::write_ros_map_as(
        &probabilities,
        &png_yaml,
        thresholds,
        mapper::export::RosImage::Png,
    )
    .unwrap();
    assert_eq!(png.file_name().unwrap(), "b.ros.png");
    assert!(
        std::fs::read_to_string(&png_yaml)
            .unwrap()
            .contains("image: b.ros.png")
    );
    let (a, b) = (
        read_ros_map(&pgm_yaml).unwrap(),
        read_ros_map(&png_yaml).unwrap(),
    );
    assert_eq!(a.geometry(), b.geometry());
    assert_eq!(a.data(), b.data());
    let size = |p: &std::path::Path| std::fs::metadata(p).unwrap().len();
    assert!(
        size(&png) * 3 < size(&pgm),
        "{} vs {}",
        size(&png),
        size(&pgm)
    );
}

#[test]
fn ros_map_reads_back_to_the_same_cells_and_origin() {
    let map = mapped();
    let dir = tempfile::tempdir().unwrap();
    let thresholds = TrinaryThresholds::default();
    for k in 0..2 {
        let probabilities = map.probability_grid(k).unwrap();
        let yaml = dir.path().join(format!("level{k}.yaml"));
        let pgm = write_ros_map(&probabilities, &yaml, thresholds).unwrap();
        assert!(
            std::fs::read(&pgm).unwrap().starts_with(b"P5"),
            "binary PGM"
        );
        let text = std::fs::read_to_string(&yaml).unwrap();
        assert!(
            text.contains(&format!("image: level{k}.pgm")) && text.contains("mode: trinary"),
            "{text}"
        );
        let back = read_ros_map(&yaml).unwrap();
        assert_eq!(
            back.geometry(),
            probabilities.geometry(),
            "origin = lower-left pixel, same resolution and size"
        );
        let expected: Vec<Trinary> = probabilities
            .data()
            .iter()
            .map(|p| thresholds.classify(*p))
            .collect();
        assert_eq!(back.data(), &expected[..], "level {k}");
        assert!(
            expected.contains(&Trinary::Occupied)
                && expected.contains(&Trinary::Free)
                && expected.contains(&Trinary::Unknown)
        );
    }
}

#[test]
fn the_top_row_of_the_pgm_is_the_highest_y() {
    let map = mapped();
    let dir = tempfile::tempdir().unwrap();
    let yaml = dir.path().join("m.yaml");
    let grid = map.probability_grid(0).unwrap();
    let pgm = write_ros_map(&grid, &yaml, TrinaryThresholds::default()).unwrap();
    let bytes = std::fs::read(pgm).unwrap();
    let (w, h) = (grid.geometry().width(), grid.geometry().height());
    let pixels = &bytes[bytes.len() - w * h..];
    // The box's near face at x = 5, y in [1.5, 2.5]: find it in the top-first image rows.
    let cell = grid.geometry().cell_of(&Point2::new(5.05, 2.0)).unwrap();
    assert_eq!(
        pixels[(h - 1 - cell.y) * w + cell.x],
        0,
        "occupied pixel where the world says"
    );
}

#[test]
fn npy_holds_probabilities_and_distances_with_row_0_lowest_y() {
    let map = mapped();
    let dir = tempfile::tempdir().unwrap();
    let grid = map.probability_grid(1).unwrap();
    let path = dir.path().join("p.npy");
    write_npy(&grid, &path).unwrap();
    let (rows, cols, data) = read_npy(&path).unwrap();
    assert_eq!(
        (rows, cols),
        (grid.geometry().height(), grid.geometry().width())
    );
    assert_eq!(data, grid.data());
    let bytes = std::fs::read(&path).unwrap();
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!(
        (10 + header_len) % 64,
        0,
        "header aligned as NumPy requires"
    );

    let odm = map.distance_maps().level(0).unwrap();
    let path = dir.path().join("d.npy");
    write_npy(odm.grid(), &path).unwrap();
    let (_, _, d) = read_npy(&path).unwrap();
    let i = odm
        .grid()
        .geometry()
        .index_of(&Point2::new(5.05, 2.0))
        .unwrap();
    assert_eq!(d[i], 0.0, "an obstacle cell is at distance 0");
    assert!(d.iter().all(|v| (0.0..=odm.max_distance_m()).contains(v)));

    std::fs::write(&path, &std::fs::read(&path).unwrap()[..200]).unwrap();
    let err = read_npy(&path).unwrap_err().to_string();
    assert!(err.contains("d.npy") && err.contains("truncated"), "{err}");
}

#[test]
fn pngs_are_written() {
    let map = mapped();
    let dir = tempfile::tempdir().unwrap();
    write_occupancy_png(&map.probability_grid(0).unwrap(), &dir.path().join("o.png")).unwrap();
    write_distance_png(
        map.distance_maps().level(0).unwrap(),
        &dir.path().join("d.png"),
    )
    .unwrap();
    for f in ["o.png", "d.png"] {
        let img = image::open(dir.path().join(f)).unwrap();
        assert_eq!((img.width(), img.height()), (300, 300));
    }
}

#[test]
fn a_bad_ros_yaml_names_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let yaml = dir.path().join("bad.yaml");
    std::fs::write(&yaml, "image: x.pgm\nresolution: fast\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n").unwrap();
    let err = read_ros_map(&yaml).unwrap_err().to_string();
    assert!(
        err.contains("bad.yaml") && err.contains("resolution"),
        "{err}"
    );
}

/// A picture written row by row is the picture written whole, pixel for pixel, and appears at
/// its path only when finished; a row of the wrong width or a row missing is an error naming it.
#[test]
fn a_picture_streamed_by_rows_is_the_picture_written_whole() {
    let grid = mapped().probability_grid(0).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole.png");
    write_occupancy_png(&grid, &whole).unwrap();
    let (w, h) = (grid.geometry().width(), grid.geometry().height());
    let streamed = dir.path().join("streamed.png");
    let mut rows = PngRows::create(&streamed, w, h).unwrap();
    for y in (0..h).rev() {
        let row: Vec<u8> = grid.data()[y * w..(y + 1) * w]
            .iter()
            .map(|p| occupancy_pixel(*p))
            .collect();
        rows.write_row(&row).unwrap();
        assert!(!streamed.exists(), "a picture appears only when finished");
    }
    rows.finish().unwrap();
    let (a, b) = (
        image::open(&whole).unwrap().to_luma8(),
        image::open(&streamed).unwrap().to_luma8(),
    );
    assert_eq!(a.dimensions(), b.dimensions());
    assert!(a.as_raw() == b.as_raw(), "the pixels differ");
    assert!(a.as_raw().iter().any(|&p| p < 100) && a.as_raw().iter().any(|&p| p > 250));

    let mut rows = PngRows::create(&dir.path().join("bad.png"), 4, 2).unwrap();
    let e = rows.write_row(&[0; 3]).unwrap_err().to_string();
    assert!(e.contains("bad.png") && e.contains("3 pixels"), "{e}");
    rows.write_row(&[0; 4]).unwrap();
    let e = rows.finish().unwrap_err().to_string();
    assert!(
        e.contains("bad.png") && e.contains("1 rows never written"),
        "{e}"
    );
    assert!(!dir.path().join("bad.png").exists());
}
