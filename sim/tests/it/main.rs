//! The `sim` library's integration tests, one test binary (`cargo test -p sim --test it`): scenario
//! files, the world and the LiDAR, map files, campaigns, the replay, property-based fuzzing of
//! the parsers, who was at fault by the judge alone, the small-obstacle studies, taxi routes planned on drawn airports, the traffic of movers and the judge's traffic
//! measures. Tests that run the `taxi-sim` binary live in its package (`sim/cli/tests/it`).
//! Paths are from this package (`sim`): the shipped scenarios are `../scenarios`, the fixtures
//! `tests/fixtures`.

mod campaign;
mod capture_out;
mod external_stack;
mod fuzz;
mod judge_fault;
mod map_files;
mod pcap;
mod replay;
mod representations;
mod rosbag;
mod scenario;
mod short_obstacles;
mod small_obstacles;
mod smoke_campaign;
mod stands;
mod taxi_plan;
mod traffic;
mod traffic_judge;
mod two_lidars;
mod world_lidar;
