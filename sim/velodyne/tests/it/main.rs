//! The Velodyne decoder's integration tests, one binary: captures the tests build (a pcap written
//! here, packets encoded here), hostile captures, VeloView calibration files, and - ignored
//! unless asked, as CI asks - VeloView's real HDL-32E recording in `../shared/data/velodyne`.

mod calibration;
mod common;
mod hostile;
mod packets;
mod shared_data;
