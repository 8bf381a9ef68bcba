//! The mapper's integration tests, one binary: collision checks, exports, the map (by subject)
//! and overhead structures.

mod collision;
mod export;
mod map;
mod overhead;
mod representations;
