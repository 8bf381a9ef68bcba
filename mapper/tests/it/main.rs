//! The mapper's integration tests, one binary: collision checks, exports, the map (by subject)
//! open tops and overhead structures.

mod collision;
mod export;
mod map;
mod open_top;
mod overhead;
mod representations;
